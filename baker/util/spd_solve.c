/* Sparse SPD solves through CHOLMOD (see spd_solve.h). */
#include "spd_solve.h"

#include <string.h>

int lmb_spd_begin(lmb_spd *s, size_t n, size_t entries, size_t columns)
{
    memset(s, 0, sizeof *s);
    cholmod_start(&s->cm);
    s->cm.print = 0;
    s->cm.supernodal = CHOLMOD_SIMPLICIAL; /* deterministic, no threaded BLAS */
    s->cm.nmethods = 1;
    s->cm.method[0].ordering = CHOLMOD_AMD;
    s->cm.postorder = 1;
    s->a = cholmod_allocate_triplet(n, n, entries, 1, CHOLMOD_REAL, &s->cm);
    s->b = cholmod_zeros(n, columns, CHOLMOD_REAL, &s->cm);
    return s->a && s->b;
}

int lmb_spd_solve(lmb_spd *s, double *out)
{
    cholmod_sparse *a = cholmod_triplet_to_sparse(s->a, s->a->nnz, &s->cm);
    cholmod_factor *l = a ? cholmod_analyze(a, &s->cm) : NULL;
    cholmod_dense *x = NULL;
    if (l && cholmod_factorize(a, l, &s->cm) && s->cm.status == CHOLMOD_OK)
        x = cholmod_solve(CHOLMOD_A, l, s->b, &s->cm);
    int ok = x != NULL;
    if (ok)
        memcpy(out, x->x, x->nrow * x->ncol * sizeof *out);
    cholmod_free_dense(&x, &s->cm);
    cholmod_free_factor(&l, &s->cm);
    cholmod_free_sparse(&a, &s->cm);
    return ok;
}

void lmb_spd_end(lmb_spd *s)
{
    cholmod_free_dense(&s->b, &s->cm);
    cholmod_free_triplet(&s->a, &s->cm);
    cholmod_finish(&s->cm);
}
