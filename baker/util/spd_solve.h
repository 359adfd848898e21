/*
 * Sparse symmetric positive definite solves through CHOLMOD, as the unwrap (LSCM) and the seam
 * stitching need them: the caller fills the upper triangle as triplets and the right-hand sides,
 * then one simplicial Cholesky factorisation with AMD ordering (deterministic: no threaded
 * BLAS) solves for every column. Ownership: lmb_spd_end frees everything begin made.
 */
#ifndef LMBAKE_SPD_SOLVE_H
#define LMBAKE_SPD_SOLVE_H

#include <cholmod.h>

#include <stddef.h>

typedef struct lmb_spd {
    cholmod_common cm;
    cholmod_triplet *a; /* n x n, upper triangle (stype 1): append entries at a->nnz */
    cholmod_dense *b;   /* n x columns, zeros: fill column k at b->x + k * n */
} lmb_spd;

/* Room for n unknowns, at most `entries` triplets, `columns` right-hand sides. 0: out of memory
 * (call lmb_spd_end anyway). */
int lmb_spd_begin(lmb_spd *s, size_t n, size_t entries, size_t columns);

/* Solves; the solution (n x columns, column-major) into out. 0: not positive definite or out
 * of memory. */
int lmb_spd_solve(lmb_spd *s, double *out);

void lmb_spd_end(lmb_spd *s);

#endif
