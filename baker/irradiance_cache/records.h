/*
 * Irradiance-cache records (DESIGN.md section 7) and the queries on them: which records may
 * be used at a point, the interpolated irradiance there, and the clamps and gradients that
 * make interpolation safe.
 *
 * A record holds a gather's result at one texel's gather point: position, normal, RGB
 * irradiance E, its translation and rotation gradients and its radius of influence r. Records
 * are found by world position and normal only, whatever chart, atlas or instance they came
 * from (light does not stop at a UV seam). The weight of record i at (p, n) is Tabellion and
 * Lamorlette's (2004, eq. 2), 1 - max(eps_p, eps_n), with
 *     eps_p = sqrt(|p - p_i|^2 + 3 ((p - p_i).n_i)^2) / r_i     (an offset off the record's
 *              plane counts double: a shelf's records do not serve the floor under it)
 *     eps_n = sqrt(1 - n.n_i) / normal_limit
 * so weights fall smoothly to 0 at the edge of a record's reach (no blotch outlines, which
 * Ward's 1 / eps weight with a cut-off leaves). A record whose normal faces away (n.n_i <= 0,
 * the other wall of a corner) or that lies in front of p (Ward 1988: (p - p_i).(n + n_i)/2 <
 * 0, the record sees what p does not) is never used.
 * The interpolated value is sum_i w_i (E_i + g_t,i . (p - p_i) + g_r,i . (n_i x n)) / sum_i w_i
 * (Ward and Heckbert 1992, first-order gradients), each term kept >= 0.
 *
 * Records live in a k-d tree over their positions whose nodes also keep the largest radius
 * below them, so "records whose reach covers p" and "records within d of p" are the same
 * pruned walk. The walk visits records in an order fixed by the record set alone: results do
 * not depend on thread counts or on when records were inserted.
 */
#ifndef LMBAKE_IC_RECORDS_H
#define LMBAKE_IC_RECORDS_H

#include <lmbake/lmbake.h>

typedef struct lmb_ic_record {
    double p[3], n[3];     /* gather point and shading normal (unit) */
    /* The rest in single precision (168 bytes a record instead of 272; a quarter of a million
     * records on a level of 1,900 props): values and lengths need no more than a float's 7
     * digits, and every sum over records is taken in double. */
    float e[3];            /* irradiance, RGB */
    float grad_t[3][3];    /* per channel: dE/dp, world, in the record's tangent plane */
    float grad_r[3][3];    /* per channel: dE/d(rotation vector) of the normal */
    float harmonic;        /* harmonic mean distance of its gather rays (neighbour-clamped) */
    float r_min, r_max;    /* the reach's clamps in world units (spacing x the texel's size) */
    float r;               /* reach: clamp(error x harmonic, r_min, r_max) */
    float var;             /* variance of lum(e) as an estimate (0: unknown): post/denoise.h's noise level */
    float side[2][4];      /* the planes of the nearest two faces (distinct orientations) its 8 tangent rays
                              met within LMB_IC_CLEAR_REACH x r_max, turned to face it: (m, m . q); m = 0:
                              none. A point behind one may lie across a wall (across_geometry) */
    float lift;            /* world: how far a sight test lifts it off its surface (raytrace/rt_sight.h) */
    uint32_t atlas, texel; /* where it was gathered: atlas and listed-texel index */
    uint32_t group;        /* placement order: the level (of all rounds) that placed it */
} lmb_ic_record;

typedef struct lmb_ic_records {
    lmb_ic_record *rec;
    uint32_t count, cap;
    double error;          /* Ward's a: reach = a x harmonic mean distance */
    double normal_limit;   /* eps_n's scale, sqrt(1 - cos(largest normal difference)) */
    /* k-d tree (lmb_ic_records_index): node k covers order[lo, hi), children 2k and 2k + 1 */
    uint32_t *order;
    uint32_t nodes;
    float (*box)[6];       /* per node: min xyz, max xyz of its records' positions */
    float *reach;          /* per node: the largest r below it */
    /* per record, the texels it serves within [1, ray_scale] (ic_pass.c, count_served): set by
     * the first pass that gathers at the records again, dropped when records are added or clamped */
    uint32_t *serves;
    const struct lmb_rt *rt; /* borrowed, may be NULL: the scene that sight tests trace (lmb_ic_weight) */
} lmb_ic_records;

/* How far a record's tangent rays look, over its largest reach: 1 / cos(22.5 degrees), the most
 * a ray of 8 around the circle is longer than the way to a straight wall nearest to it, with a
 * margin. */
#define LMB_IC_CLEAR_REACH 1.2

/* An empty set for error setting a (> 0). Free with lmb_ic_records_free. */
void lmb_ic_records_init(lmb_ic_records *s, double error);
void lmb_ic_records_free(lmb_ic_records *s);

/* Appends records (copied). LMB_ERR_INTERNAL when out of memory. */
lmb_status lmb_ic_records_append(lmb_ic_records *s, const lmb_ic_record *r, uint32_t n, lmb_error *err);

/* Rebuilds the k-d tree after records were added or their reach changed; large subtrees are
 * built in parallel on `threads` (0: all cores), the tree the same at any count. */
lmb_status lmb_ic_records_index(lmb_ic_records *s, int threads, lmb_error *err);

/* The reach of r from its harmonic distance and clamps: clamp(error x harmonic, r_min, r_max). */
double lmb_ic_reach(const lmb_ic_records *s, const lmb_ic_record *r);

/* Weight of record r at (p, n) (see above): in (0, 1], or 0 when it may not be used. */
double lmb_ic_weight(const lmb_ic_records *s, const lmb_ic_record *r, const double p[3], const double n[3]);

/* Sum of the weights at (p, n); with e != NULL also the interpolated irradiance (0 when the
 * sum is 0). Reads the index: call lmb_ic_records_index first. */
double lmb_ic_interpolate(const lmb_ic_records *s, const double p[3], const double n[3], double e[3]);

/* Fixed point of lmb_ic_add_shares: a whole texel. */
#define LMB_IC_SHARE_ONE 65536

/* Adds to share[k] record k's part of the interpolation at (p, n), w_k / sum of the weights, in
 * units of 1 / LMB_IC_SHARE_ONE (rounded): summed over every valid texel, how many texels a
 * record serves. The additions are atomic integers, so a parallel sweep gives the same sums
 * at any thread count. Reads the index. */
void lmb_ic_add_shares(const lmb_ic_records *s, const double p[3], const double n[3], uint64_t *share);

/* The nearest record k with eligible[k] set whose shading normal is within acos(min_cos) of n
 * and that lies within twice its reach of p; -1 when there is none. Reads the index. */
int64_t lmb_ic_records_nearest(const lmb_ic_records *s, const double p[3], const double n[3], double min_cos,
                               const uint8_t *eligible);

/* Neighbour clamping (Krivanek et al. 2006): no record's harmonic distance exceeds a
 * neighbour's plus the distance between them, R_i <= R_j + |p_i - p_j| over the records
 * within its reach; then every reach is recomputed (the index follows). One Jacobi sweep (each record reads the
 * others' values from before the sweep), so the result does not depend on the order. */
lmb_status lmb_ic_records_clamp(lmb_ic_records *s, uint32_t threads, lmb_error *err);

/* Translation gradients by a weighted least-squares fit over each record's neighbours (see
 * docs/irradiance-cache.md: why not Ward and Heckbert's stratified formula). Reads the index. */
lmb_status lmb_ic_records_fit_gradients(lmb_ic_records *s, uint32_t threads, lmb_error *err);

/* The gradients of records [first, last) only, into g[i - first] (the records unchanged): the
 * farm's step of the fit (irradiance_cache/ic_pass.c). */
void lmb_ic_records_fit_range(const lmb_ic_records *s, uint32_t first, uint32_t last, uint32_t threads,
                              double (*g)[3][3]);

#endif
