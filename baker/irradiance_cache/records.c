/* Irradiance-cache records: weights, the k-d tree, interpolation, clamps, gradients (records.h). */
#include "records.h"

#include "raytrace/rt_sight.h"

#include "util/frame.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define LEAF 8
/* The largest normal difference a record serves: 30 degrees, sqrt(1 - cos 30) = 0.366, or
 * less for small errors (Ward's criterion: eps_n = sqrt(1 - n.n_i) against a). */
#define NORMAL_LIMIT_MAX 0.366

void lmb_ic_records_init(lmb_ic_records *s, double error)
{
    memset(s, 0, sizeof *s);
    s->error = error;
    s->normal_limit = error < NORMAL_LIMIT_MAX ? error : NORMAL_LIMIT_MAX;
}

void lmb_ic_records_free(lmb_ic_records *s)
{
    free(s->rec);
    free(s->order);
    free(s->box);
    free(s->reach);
    free(s->serves);
    memset(s, 0, sizeof *s);
}

lmb_status lmb_ic_records_append(lmb_ic_records *s, const lmb_ic_record *r, uint32_t n, lmb_error *err)
{
    if ((uint64_t)s->count + n > UINT32_MAX - 1)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: more than 4 billion records");
    free(s->serves);
    s->serves = NULL;
    if (s->count + n > s->cap) {
        uint32_t cap = s->cap ? s->cap : 1024;
        while (cap < s->count + n)
            cap = cap > UINT32_MAX / 2 ? UINT32_MAX - 1 : cap * 2;
        lmb_ic_record *p = realloc(s->rec, (size_t)cap * sizeof *p);
        if (!p)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records", cap);
        s->rec = p;
        s->cap = cap;
    }
    if (n)
        memcpy(s->rec + s->count, r, (size_t)n * sizeof *r);
    s->count += n;
    return LMB_OK;
}

/* ---- k-d tree ----------------------------------------------------------------------------- */

/* Orders records by one coordinate, ties by index: a total order, so the tree depends on the
 * record set alone. */
static int before(const lmb_ic_records *s, int axis, uint32_t a, uint32_t b)
{
    double x = s->rec[a].p[axis], y = s->rec[b].p[axis];
    return x < y || (x == y && a < b);
}

/* Quickselect: order[lo, hi) partitioned so that order[k] is in place (Lomuto, median of 3). */
static void select_kth(const lmb_ic_records *s, int axis, uint32_t *o, uint32_t lo, uint32_t hi, uint32_t k)
{
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2, a = o[lo], b = o[mid], c = o[hi - 1], pivot;
        if (before(s, axis, a, b))
            pivot = before(s, axis, b, c) ? mid : before(s, axis, a, c) ? hi - 1 : lo;
        else
            pivot = before(s, axis, a, c) ? lo : before(s, axis, b, c) ? hi - 1 : mid;
        uint32_t t = o[pivot], store = lo;
        o[pivot] = o[hi - 1];
        o[hi - 1] = t;
        for (uint32_t i = lo; i + 1 < hi; i++)
            if (before(s, axis, o[i], o[hi - 1])) {
                t = o[i];
                o[i] = o[store];
                o[store++] = t;
            }
        t = o[store];
        o[store] = o[hi - 1];
        o[hi - 1] = t;
        if (k == store)
            return;
        if (k < store)
            hi = store;
        else
            lo = store + 1;
    }
}

/* Subtrees of more records than this are built as tasks of their own. */
#define BUILD_TASK_RECORDS 8192

/* point[i]: record i's position as a float box, rounded outward so that it holds the double
 * position (computed once per index, not at every level of the tree). */
static void build(lmb_ic_records *s, const float (*point)[6], uint32_t node, uint32_t lo, uint32_t hi)
{
    float *b = s->box[node];
    b[0] = b[1] = b[2] = FLT_MAX;
    b[3] = b[4] = b[5] = -FLT_MAX;
    for (uint32_t k = lo; k < hi; k++) {
        const float *q = point[s->order[k]];
        for (int a = 0; a < 3; a++) {
            b[a] = q[a] < b[a] ? q[a] : b[a];
            b[3 + a] = q[3 + a] > b[3 + a] ? q[3 + a] : b[3 + a];
        }
    }
    if (hi - lo <= LEAF)
        return;
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (b[3 + a] - b[a] > b[3 + axis] - b[axis])
            axis = a;
    uint32_t mid = lo + (hi - lo) / 2;
    select_kth(s, axis, s->order, lo, hi, mid);
    /* the halves own disjoint ranges of order[] and disjoint nodes: large ones are tasks (the
     * tree is the same whichever thread builds a part) */
    if (hi - lo > BUILD_TASK_RECORDS) {
#pragma omp task default(none) firstprivate(s, point, node, lo, mid)
        build(s, point, 2 * node, lo, mid);
        build(s, point, 2 * node + 1, mid, hi);
#pragma omp taskwait
    } else {
        build(s, point, 2 * node, lo, mid);
        build(s, point, 2 * node + 1, mid, hi);
    }
}

/* Every node's largest reach below it (positions, hence the tree, unchanged). */
static float refresh_reach(lmb_ic_records *s, uint32_t node, uint32_t lo, uint32_t hi)
{
    float reach = 0;
    if (hi - lo <= LEAF) {
        for (uint32_t k = lo; k < hi; k++) {
            float rr = nextafterf((float)s->rec[s->order[k]].r, FLT_MAX); /* rounded up */
            reach = rr > reach ? rr : reach;
        }
    } else {
        uint32_t mid = lo + (hi - lo) / 2;
        float left = refresh_reach(s, 2 * node, lo, mid), right = refresh_reach(s, 2 * node + 1, mid, hi);
        reach = left > right ? left : right;
    }
    s->reach[node] = reach;
    return reach;
}

lmb_status lmb_ic_records_index(lmb_ic_records *s, int threads, lmb_error *err)
{
    threads = threads > 0 ? threads : omp_get_max_threads();
    uint32_t depth = 0;
    while (((uint64_t)s->count >> depth) > LEAF)
        depth++;
    uint32_t nodes = (2u << (depth + 1)) + 1;
    free(s->order);
    free(s->box);
    free(s->reach);
    s->order = malloc(((size_t)s->count + 1) * sizeof *s->order);
    s->box = malloc((size_t)nodes * sizeof *s->box);
    s->reach = malloc((size_t)nodes * sizeof *s->reach);
    s->nodes = nodes;
    if (!s->order || !s->box || !s->reach)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory indexing %u records", s->count);
    for (uint32_t k = 0; k < s->count; k++)
        s->order[k] = k;
    float (*point)[6] = malloc(((size_t)s->count + 1) * sizeof *point);
    if (!point)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory indexing %u records", s->count);
#pragma omp parallel for num_threads(threads) schedule(static) if (s->count > BUILD_TASK_RECORDS)
    for (uint32_t k = 0; k < s->count; k++)
        for (int a = 0; a < 3; a++) {
            point[k][a] = nextafterf((float)s->rec[k].p[a], -FLT_MAX);
            point[k][3 + a] = nextafterf((float)s->rec[k].p[a], FLT_MAX);
        }
    if (s->count) {
#pragma omp parallel num_threads(threads) if (s->count > BUILD_TASK_RECORDS)
#pragma omp single
        build(s, (const float (*)[6])point, 1, 0, s->count);
        refresh_reach(s, 1, 0, s->count);
    }
    free(point);
    return LMB_OK;
}

/* Squared distance from p to node's box. */
static double box_distance2(const float *b, const double p[3])
{
    double d2 = 0;
    for (int a = 0; a < 3; a++) {
        double d = p[a] < b[a] ? b[a] - p[a] : p[a] > b[3 + a] ? p[a] - b[3 + a] : 0;
        d2 += d * d;
    }
    return d2;
}

typedef void (*visit_fn)(void *user, uint32_t record);

/* Visits, in tree order, every record that may lie within `radius` of p (radius < 0: within
 * -radius times the record's own reach). */
static void walk(const lmb_ic_records *s, const double p[3], double radius, visit_fn visit, void *user)
{
    if (!s->count)
        return;
    uint32_t stack[3 * 64], top = 0;
    stack[top++] = 1;
    stack[top++] = 0;
    stack[top++] = s->count;
    while (top) {
        uint32_t hi = stack[--top], lo = stack[--top], node = stack[--top];
        double r = radius < 0 ? -radius * s->reach[node] : radius;
        if (box_distance2(s->box[node], p) >= r * r)
            continue;
        if (hi - lo <= LEAF) {
            for (uint32_t k = lo; k < hi; k++)
                visit(user, s->order[k]);
            continue;
        }
        uint32_t mid = lo + (hi - lo) / 2;
        /* right pushed first: the left child is visited first */
        stack[top++] = 2 * node + 1;
        stack[top++] = mid;
        stack[top++] = hi;
        stack[top++] = 2 * node;
        stack[top++] = lo;
        stack[top++] = mid;
    }
}

typedef struct nearest_ctx {
    const lmb_ic_records *s;
    const double *p, *n;
    double min_cos, best_d2;
    const uint8_t *eligible;
    int64_t best;
} nearest_ctx;

static void nearest_visit(void *user, uint32_t k)
{
    nearest_ctx *c = user;
    const lmb_ic_record *r = &c->s->rec[k];
    if (!c->eligible[k] || lmb_dot3(r->n, c->n) < c->min_cos)
        return;
    double d[3] = {r->p[0] - c->p[0], r->p[1] - c->p[1], r->p[2] - c->p[2]}, d2 = lmb_dot3(d, d);
    if (d2 >= 4 * r->r * r->r)
        return;
    if (c->best < 0 || d2 < c->best_d2 || (d2 == c->best_d2 && k < c->best)) {
        c->best = k;
        c->best_d2 = d2;
    }
}

int64_t lmb_ic_records_nearest(const lmb_ic_records *s, const double p[3], const double n[3], double min_cos,
                               const uint8_t *eligible)
{
    nearest_ctx c = {s, p, n, min_cos, 0, eligible, -1};
    walk(s, p, -2, nearest_visit, &c);
    return c.best;
}

/* ---- weights and interpolation -------------------------------------------------------- */

/*
 * Whether record r may serve point p (normal n) across geometry (docs/leaks.md): a wall standing
 * between them on their surface (a floor chart running under a wall between two rooms). A wall
 * that crosses the segment from the record to p within its reach is met by one of the record's
 * tangent rays (the nearest of 8 to its normal within 1.0824 x its distance); the record keeps
 * the planes of the nearest two such faces, and only a point behind one of them traces a ray. A
 * point off the record's plane (a ceiling's texel under a roof's record 4 cm above it: Ward's
 * test lets a record serve what lies in front of it) always does: a slab may lie between.
 */
static int across_geometry(const lmb_ic_records *s, const lmb_ic_record *r, const double p[3], const double n[3])
{
    if (!s->rt)
        return 0;
    double d[3] = {p[0] - r->p[0], p[1] - r->p[1], p[2] - r->p[2]};
    if (fabs(lmb_dot3(d, r->n)) > 2.0 * r->lift) /* off its plane: a slab may lie between (a ceiling under a roof) */
        return !lmb_rt_in_sight(s->rt, r->p, r->n, p, n, r->lift);
    int behind = 0;
    for (int k = 0; k < 2 && !behind; k++) {
        const float *pl = r->side[k];
        behind = (pl[0] != 0 || pl[1] != 0 || pl[2] != 0) && pl[0] * p[0] + pl[1] * p[1] + pl[2] * p[2] < pl[3];
    }
    return behind && !lmb_rt_in_sight(s->rt, r->p, r->n, p, n, r->lift);
}

double lmb_ic_weight(const lmb_ic_records *s, const lmb_ic_record *r, const double p[3], const double n[3])
{
    double c = lmb_dot3(n, r->n);
    if (c <= 0)
        return 0;
    double d[3] = {p[0] - r->p[0], p[1] - r->p[1], p[2] - r->p[2]};
    double mean_n[3] = {0.5 * (n[0] + r->n[0]), 0.5 * (n[1] + r->n[1]), 0.5 * (n[2] + r->n[2])};
    if (lmb_dot3(d, mean_n) < -1e-3 * r->r) /* p behind the record's plane */
        return 0;
    double along = lmb_dot3(d, r->n);
    double eps_p = sqrt(lmb_dot3(d, d) + 3.0 * along * along) / r->r;
    double eps_n = sqrt(fmax(0.0, 1.0 - c)) / s->normal_limit;
    double eps = eps_p > eps_n ? eps_p : eps_n;
    return eps < 1 ? 1 - eps : 0;
}

typedef struct interp_ctx {
    const lmb_ic_records *s;
    const double *p, *n;
    double sum, e[3];
    int want_e;
} interp_ctx;

static void interp_visit(void *user, uint32_t k)
{
    interp_ctx *c = user;
    const lmb_ic_record *r = &c->s->rec[k];
    double w = lmb_ic_weight(c->s, r, c->p, c->n);
    if (!(w > 0) || across_geometry(c->s, r, c->p, c->n))
        return;
    c->sum += w;
    if (!c->want_e)
        return;
    double d[3] = {c->p[0] - r->p[0], c->p[1] - r->p[1], c->p[2] - r->p[2]}, rot[3];
    lmb_cross3(r->n, c->n, rot); /* the rotation taking n_i to n, for small angles */
    for (int ch = 0; ch < 3; ch++) {
        const float *gt = r->grad_t[ch], *gr = r->grad_r[ch];
        double v = r->e[ch] + (gt[0] * d[0] + gt[1] * d[1] + gt[2] * d[2]) +
                   (gr[0] * rot[0] + gr[1] * rot[1] + gr[2] * rot[2]);
        c->e[ch] += w * (v > 0 ? v : 0);
    }
}

double lmb_ic_interpolate(const lmb_ic_records *s, const double p[3], const double n[3], double e[3])
{
    interp_ctx c = {s, p, n, 0, {0, 0, 0}, e != NULL};
    walk(s, p, -1, interp_visit, &c);
    if (e)
        for (int ch = 0; ch < 3; ch++)
            e[ch] = c.sum > 0 ? c.e[ch] / c.sum : 0;
    return c.sum;
}

typedef struct share_ctx {
    const lmb_ic_records *s;
    const double *p, *n;
    double sum;
    uint64_t *share;
} share_ctx;

static void share_visit(void *user, uint32_t k)
{
    share_ctx *c = user;
    double w = lmb_ic_weight(c->s, &c->s->rec[k], c->p, c->n);
    if (!(w > 0) || across_geometry(c->s, &c->s->rec[k], c->p, c->n))
        return;
    uint64_t part = (uint64_t)llround(w / c->sum * LMB_IC_SHARE_ONE);
#pragma omp atomic
    c->share[k] += part;
}

void lmb_ic_add_shares(const lmb_ic_records *s, const double p[3], const double n[3], uint64_t *share)
{
    share_ctx c = {s, p, n, lmb_ic_interpolate(s, p, n, NULL), share};
    if (c.sum > 0)
        walk(s, p, -1, share_visit, &c);
}

/* ---- neighbour clamping ------------------------------------------------------------------ */

typedef struct clamp_ctx {
    const lmb_ic_records *s;
    const lmb_ic_record *self;
    double harmonic;
} clamp_ctx;

static void clamp_visit(void *user, uint32_t k)
{
    clamp_ctx *c = user;
    const lmb_ic_record *r = &c->s->rec[k];
    double d[3] = {r->p[0] - c->self->p[0], r->p[1] - c->self->p[1], r->p[2] - c->self->p[2]};
    double bound = r->harmonic + sqrt(lmb_dot3(d, d));
    if (bound < c->harmonic)
        c->harmonic = bound;
}

double lmb_ic_reach(const lmb_ic_records *s, const lmb_ic_record *r)
{
    double reach = s->error * r->harmonic;
    return reach < r->r_min ? r->r_min : reach > r->r_max ? r->r_max : reach;
}

lmb_status lmb_ic_records_clamp(lmb_ic_records *s, uint32_t threads, lmb_error *err)
{
    double *h = malloc(((size_t)s->count + 1) * sizeof *h);
    if (!h)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory clamping %u records", s->count);
    free(s->serves);
    s->serves = NULL;
    int nt = threads ? (int)threads : omp_get_max_threads();
#pragma omp parallel for num_threads(nt) schedule(dynamic, 256)
    for (uint32_t i = 0; i < s->count; i++) {
        clamp_ctx c = {s, &s->rec[i], s->rec[i].harmonic};
        walk(s, s->rec[i].p, s->rec[i].r, clamp_visit, &c);
        h[i] = c.harmonic;
    }
    for (uint32_t i = 0; i < s->count; i++) {
        s->rec[i].harmonic = (float)h[i];
        s->rec[i].r = (float)lmb_ic_reach(s, &s->rec[i]);
    }
    free(h);
    if (s->count)
        refresh_reach(s, 1, 0, s->count);
    return LMB_OK;
}

/* ---- gradients ----------------------------------------------------------------------------- */

typedef struct fit_ctx {
    const lmb_ic_records *s;
    const lmb_ic_record *self;
    double t[3], b[3];       /* tangent frame of self */
    double a[3];             /* normal matrix [a0 a1; a1 a2] */
    double rhs[3][2];        /* per channel */
    uint32_t used;
} fit_ctx;

/* Neighbours within twice the reach that could serve this record's points (weight test
 * from the record's side at a doubled reach), weighted by closeness. */
static void fit_visit(void *user, uint32_t k)
{
    fit_ctx *c = user;
    const lmb_ic_record *r = &c->s->rec[k], *self = c->self;
    if (r == self || lmb_dot3(r->n, self->n) < 1 - c->s->normal_limit * c->s->normal_limit)
        return;
    double d[3] = {r->p[0] - self->p[0], r->p[1] - self->p[1], r->p[2] - self->p[2]};
    double along = lmb_dot3(d, self->n), dist2 = lmb_dot3(d, d), reach = 2 * self->r;
    if (fabs(along) > 0.25 * sqrt(dist2) || dist2 >= reach * reach)
        return; /* off the record's plane: not the same surface */
    if (across_geometry(c->s, self, r->p, r->n))
        return; /* across a wall: another room's light says nothing of this one's slope */
    double u = lmb_dot3(d, c->t), v = lmb_dot3(d, c->b);
    double w = 1 - sqrt(dist2) / reach;
    c->a[0] += w * u * u;
    c->a[1] += w * u * v;
    c->a[2] += w * v * v;
    for (int ch = 0; ch < 3; ch++) {
        double de = r->e[ch] - self->e[ch];
        c->rhs[ch][0] += w * u * de;
        c->rhs[ch][1] += w * v * de;
    }
    c->used++;
}

/*
 * Per record and channel: g minimizing sum_j w_j (E_j - E_i - g.(p_j - p_i))^2 over the
 * neighbours j in its tangent plane (2 unknowns), with a small ridge so that neighbours on a
 * line give the gradient along it only. A gradient that would change E by more than E over
 * the reach is scaled down to that (noise, not light: irradiance does not go negative).
 */
void lmb_ic_records_fit_range(const lmb_ic_records *s, uint32_t first, uint32_t last, uint32_t threads,
                              double (*g)[3][3])
{
    int nt = threads ? (int)threads : omp_get_max_threads();
#pragma omp parallel for num_threads(nt) schedule(dynamic, 256)
    for (uint32_t i = first; i < last; i++) {
        const lmb_ic_record *r = &s->rec[i];
        double (*gi)[3] = g[i - first];
        fit_ctx c;
        memset(&c, 0, sizeof c);
        c.s = s;
        c.self = r;
        lmb_frame(r->n, c.t, c.b);
        walk(s, r->p, 2 * r->r, fit_visit, &c);
        memset(gi, 0, sizeof g[0]);
        double ridge = 1e-3 * (c.a[0] + c.a[2]) + 1e-30;
        double a0 = c.a[0] + ridge, a1 = c.a[1], a2 = c.a[2] + ridge, det = a0 * a2 - a1 * a1;
        if (c.used < 2 || !(det > 0))
            continue;
        for (int ch = 0; ch < 3; ch++) {
            double gu = (a2 * c.rhs[ch][0] - a1 * c.rhs[ch][1]) / det;
            double gv = (a0 * c.rhs[ch][1] - a1 * c.rhs[ch][0]) / det;
            double mag = sqrt(gu * gu + gv * gv) * r->r, scale = mag > r->e[ch] ? r->e[ch] / mag : 1;
            for (int k = 0; k < 3; k++)
                gi[ch][k] = scale * (gu * c.t[k] + gv * c.b[k]);
        }
    }
}

lmb_status lmb_ic_records_fit_gradients(lmb_ic_records *s, uint32_t threads, lmb_error *err)
{
    double (*g)[3][3] = malloc(((size_t)s->count + 1) * sizeof *g);
    if (!g)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u gradients", s->count);
    lmb_ic_records_fit_range(s, 0, s->count, threads, g);
    for (uint32_t i = 0; i < s->count; i++)
        for (int ch = 0; ch < 3; ch++)
            for (int k = 0; k < 3; k++)
                s->rec[i].grad_t[ch][k] = (float)g[i][ch][k];
    free(g);
    return LMB_OK;
}
