/*
 * BC6H_UFLOAT encoder (see bc6h.h). Per 4 x 4 block:
 *   1. each texel's channels as half-float bit patterns h (round to nearest even), and their
 *      targets in the decoder's interpolation domain x = h x 64 / 31 (the decoder's last step
 *      for unsigned blocks is h = (x x 31) >> 6);
 *   2. one region: a line through the texels' x (their weighted mean and principal axis by
 *      power iteration on the covariance), endpoints at the extreme projections; two regions:
 *      the partitions ranked by how far their two regions' texels lie from their own lines
 *      (the covariance's two smaller eigenvalues), the best LMB_BC6H_TRY_PARTITIONS kept;
 *   3. for each mode (four one-region, ten two-region) and line: endpoints quantized to the
 *      mode's bits (the nearest value the decoder's unquantization gives; a difference beyond
 *      its bits is clamped), each texel's index the weight whose decoded half lies nearest its
 *      h; then twice, each region's endpoints refitted by least squares to those weights and
 *      the indices chosen again;
 *   4. each region's anchor texel must have an index whose top bit is 0: that region's
 *      endpoints swap when it does not (a transformed mode whose differences then overflow
 *      drops the candidate);
 *   5. the candidate with the smallest weighted squared error in h (a relative error: h steps
 *      are 2^-10 of the value's power of two) is written (bc6h_modes.c packs it).
 */
#include "bc6h.h"

#include "bc6h_modes.h"
#include "ktx2.h"

#include <math.h>
#include <omp.h>
#include <string.h>

/* Sweeps of coordinate descent on the kept candidate's endpoints (polish). */
#define LMB_BC6H_POLISH_SWEEPS 4

/* Two-region partitions fully tried per block, best first by the line residual. */
#define LMB_BC6H_TRY_PARTITIONS 2

/* One block's texels: halves h, targets x, weights wt. */
typedef struct block_in {
    int h[16][3];
    double x[16][3], wt[16];
} block_in;

/* A candidate: mode (index into lmb_bc6h_modes), partition, quantized endpoints, indices, error. */
typedef struct fit {
    int mode, partition;
    int q[4][3];
    int idx[16];
    double error;
} fit;

static int region_of(int regions, int p, int i)
{
    return regions == 2 ? (lmb_bc6h_partitions[p] >> i) & 1 : 0;
}

/* The quantized endpoint whose unquantized value is nearest x (0..65535). */
static int quantize(double x, int bits)
{
    int top = (1 << bits) - 1;
    int q = (int)floor(x / (double)(1 << (16 - bits)));
    int best = 0;
    double best_d = 1e30;
    for (int k = q - 1; k <= q + 1; k++) {
        int c = k < 0 ? 0 : k > top ? top : k;
        double d = fabs((double)lmb_bc6h_unquantize(c, bits) - x);
        if (d < best_d) {
            best_d = d;
            best = c;
        }
    }
    return best;
}

/* Whether every difference of a transformed mode's endpoints to w fits its bits. */
static int deltas_fit(const lmb_bc6h_mode *md, int q[4][3])
{
    for (int e = 1; e < 2 * md->regions; e++)
        for (int c = 0; c < 3; c++)
            if (md->delta[c]) {
                int d = q[e][c] - q[0][c], half = 1 << (md->delta[c] - 1);
                if (d < -half || d > half - 1)
                    return 0;
            }
    return 1;
}

/* The halves each region's indices decode to (endpoints f->q): pal[region][index][channel]. */
static void palettes(const fit *f, int pal[2][16][3])
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    int n = md->regions == 1 ? 16 : 8;
    const int *w = md->regions == 1 ? lmb_bc6h_weights4 : lmb_bc6h_weights3;
    for (int r = 0; r < md->regions; r++) {
        int e0[3], e1[3];
        for (int c = 0; c < 3; c++) {
            e0[c] = lmb_bc6h_unquantize(f->q[2 * r][c], md->bits);
            e1[c] = lmb_bc6h_unquantize(f->q[2 * r + 1][c], md->bits);
        }
        for (int k = 0; k < n; k++)
            for (int c = 0; c < 3; c++)
                pal[r][k][c] = (((64 - w[k]) * e0[c] + w[k] * e1[c] + 32) >> 6) * 31 >> 6;
    }
}

/* Each texel's nearest entry of its region's palette (endpoints f->q); returns the weighted
 * squared error in h. */
static double choose_indices(const block_in *b, fit *f)
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    int n = md->regions == 1 ? 16 : 8;
    int pal[2][16][3];
    palettes(f, pal);
    double total = 0;
    for (int i = 0; i < 16; i++) {
        int r = region_of(md->regions, f->partition, i), bk = 0;
        double best = 1e30;
        for (int k = 0; k < n; k++) {
            double d = 0;
            for (int c = 0; c < 3; c++) {
                double t = (double)(pal[r][k][c] - b->h[i][c]);
                d += t * t;
            }
            if (d < best) {
                best = d;
                bk = k;
            }
        }
        f->idx[i] = bk;
        total += b->wt[i] * best;
    }
    return total;
}

/* Candidate f's indices for its endpoints, anchors fixed; returns 0 when its differences do not
 * fit the mode (after an anchor's swap). */
static int evaluate(const block_in *b, fit *f)
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    f->error = choose_indices(b, f);
    int n = md->regions == 1 ? 16 : 8;
    for (int r = 0; r < md->regions; r++) {
        int anchor = r == 0 ? 0 : lmb_bc6h_anchor2[f->partition];
        if (f->idx[anchor] < n / 2)
            continue;
        for (int c = 0; c < 3; c++) {
            int t = f->q[2 * r][c];
            f->q[2 * r][c] = f->q[2 * r + 1][c];
            f->q[2 * r + 1][c] = t;
        }
        for (int i = 0; i < 16; i++)
            if (region_of(md->regions, f->partition, i) == r)
                f->idx[i] = n - 1 - f->idx[i];
    }
    return deltas_fit(md, f->q);
}

/* Candidate f (mode and partition set) from endpoint targets ex (interpolation domain):
 * quantized, indices chosen, anchors fixed. Returns 0 when the mode cannot hold them. */
static int fit_endpoints(const block_in *b, const double ex[4][3], fit *f)
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    for (int e = 0; e < 2 * md->regions; e++)
        for (int c = 0; c < 3; c++) {
            f->q[e][c] = quantize(ex[e][c], md->bits);
            if (e > 0 && md->delta[c]) { /* the endpoint moves toward w until the difference fits */
                int half = 1 << (md->delta[c] - 1), d = f->q[e][c] - f->q[0][c];
                f->q[e][c] = f->q[0][c] + (d < -half ? -half : d > half - 1 ? half - 1 : d);
            }
        }
    return evaluate(b, f);
}

/* Coordinate descent on the quantized endpoints of f: each channel of each endpoint one step
 * up or down while that lowers the error (least squares on real numbers is not least squares
 * on the quantized grid and the chosen indices). */
static void polish(const block_in *b, fit *f)
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    int top = (1 << md->bits) - 1;
    for (int sweep = 0; sweep < LMB_BC6H_POLISH_SWEEPS && f->error > 0; sweep++) {
        int improved = 0;
        for (int e = 0; e < 2 * md->regions; e++)
            for (int c = 0; c < 3; c++)
                for (int step = -1; step <= 1; step += 2) {
                    fit g = *f;
                    g.q[e][c] += step;
                    if (g.q[e][c] < 0 || g.q[e][c] > top || !evaluate(b, &g) || !(g.error < f->error))
                        continue;
                    *f = g;
                    improved = 1;
                }
        if (!improved)
            break;
    }
}

/* Least-squares endpoints of region r for f's indices: minimises the weighted
 * sum_i |(1 - t_i) x0 + t_i x1 - x_i|^2 over the region's texels. Returns 0 when singular. */
static int refit(const block_in *b, const fit *f, int r, double x0[3], double x1[3])
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[f->mode];
    const int *w = md->regions == 1 ? lmb_bc6h_weights4 : lmb_bc6h_weights3;
    double aa = 0, ab = 0, bb = 0, ax[3] = {0}, bx[3] = {0};
    for (int i = 0; i < 16; i++) {
        if (region_of(md->regions, f->partition, i) != r)
            continue;
        double t = w[f->idx[i]] / 64.0, a = 1 - t, k = b->wt[i];
        aa += k * a * a;
        ab += k * a * t;
        bb += k * t * t;
        for (int c = 0; c < 3; c++) {
            ax[c] += k * a * b->x[i][c];
            bx[c] += k * t * b->x[i][c];
        }
    }
    double det = aa * bb - ab * ab;
    if (!(fabs(det) > 1e-12 * (aa * bb + 1e-30)))
        return 0;
    for (int c = 0; c < 3; c++) {
        x0[c] = (bb * ax[c] - ab * bx[c]) / det;
        x1[c] = (aa * bx[c] - ab * ax[c]) / det;
        x0[c] = x0[c] < 0 ? 0 : x0[c] > 65535 ? 65535 : x0[c];
        x1[c] = x1[c] < 0 ? 0 : x1[c] > 65535 ? 65535 : x1[c];
    }
    return 1;
}

/* The line through region r's texels (weighted): endpoints at the extreme projections on the
 * principal axis of the texels that count into x0, x1; returns the weighted squared distance of the texels to the line. */
static double region_line(const block_in *b, int regions, int p, int r, double x0[3], double x1[3])
{
    double mean[3] = {0}, cov[6] = {0}, total = 0;
    for (int i = 0; i < 16; i++)
        if (region_of(regions, p, i) == r) {
            total += b->wt[i];
            for (int c = 0; c < 3; c++)
                mean[c] += b->wt[i] * b->x[i][c];
        }
    for (int c = 0; c < 3; c++)
        mean[c] /= total;
    for (int i = 0; i < 16; i++) {
        if (region_of(regions, p, i) != r)
            continue;
        double d[3] = {b->x[i][0] - mean[0], b->x[i][1] - mean[1], b->x[i][2] - mean[2]}, k = b->wt[i];
        cov[0] += k * d[0] * d[0];
        cov[1] += k * d[0] * d[1];
        cov[2] += k * d[0] * d[2];
        cov[3] += k * d[1] * d[1];
        cov[4] += k * d[1] * d[2];
        cov[5] += k * d[2] * d[2];
    }
    double axis[3] = {0.57735, 0.57735, 0.57735}, lambda = 0;
    for (int it = 0; it < 8; it++) {
        double v[3] = {cov[0] * axis[0] + cov[1] * axis[1] + cov[2] * axis[2],
                       cov[1] * axis[0] + cov[3] * axis[1] + cov[4] * axis[2],
                       cov[2] * axis[0] + cov[4] * axis[1] + cov[5] * axis[2]};
        double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(len > 1e-12))
            break;
        lambda = len;
        for (int c = 0; c < 3; c++)
            axis[c] = v[c] / len;
    }
    /* the extremes over the texels that count (a texel no lookup reads, weighted 1e-3, may hold
     * a neighbour chart's dilated light: spanning it would coarsen the steps of those that do) */
    double lo = 1e30, hi = -1e30, wmax = 0;
    for (int i = 0; i < 16; i++)
        if (region_of(regions, p, i) == r && b->wt[i] > wmax)
            wmax = b->wt[i];
    for (int i = 0; i < 16; i++) {
        if (region_of(regions, p, i) != r || !(b->wt[i] > 0) || b->wt[i] < 0.01 * wmax)
            continue;
        double t = 0;
        for (int c = 0; c < 3; c++)
            t += (b->x[i][c] - mean[c]) * axis[c];
        lo = t < lo ? t : lo;
        hi = t > hi ? t : hi;
    }
    if (lo > hi)
        lo = hi = 0;
    for (int c = 0; c < 3; c++) {
        x0[c] = mean[c] + lo * axis[c];
        x1[c] = mean[c] + hi * axis[c];
        x0[c] = x0[c] < 0 ? 0 : x0[c] > 65535 ? 65535 : x0[c];
        x1[c] = x1[c] < 0 ? 0 : x1[c] > 65535 ? 65535 : x1[c];
    }
    double trace = cov[0] + cov[3] + cov[5];
    return trace - lambda > 0 ? trace - lambda : 0;
}

/* The best fit of mode m with partition p from the regions' lines, refined; into *best when
 * better. */
static void try_mode(const block_in *b, int m, int p, const double lines[4][3], fit *best)
{
    const lmb_bc6h_mode *md = &lmb_bc6h_modes[m];
    double ex[4][3];
    memcpy(ex, lines, sizeof ex);
    for (int it = 0; it < 3; it++) {
        fit f = {.mode = m, .partition = p};
        if (!fit_endpoints(b, (const double(*)[3])ex, &f))
            return;
        if (f.error < best->error)
            *best = f;
        if (f.error == 0)
            return;
        for (int r = 0; r < md->regions; r++)
            if (!refit(b, &f, r, ex[2 * r], ex[2 * r + 1]))
                return;
    }
}

/* ---- blocks -------------------------------------------------------------------------- */

static uint16_t to_half(float v, int *clamped)
{
    if (!(v > 0))
        return 0;
    if (v > LMB_BC6H_MAX) {
        *clamped = 1;
        v = LMB_BC6H_MAX;
    }
    return lmb_float_to_half(v);
}

/* Encodes the block whose top-left texel is (bx, by); returns how many of its texels (inside the
 * image) were clamped. */
static int encode_block(uint32_t w, uint32_t h, const float *rgb, const uint8_t *care, uint32_t bx, uint32_t by,
                        uint8_t out[16])
{
    block_in b;
    int clamped = 0;
    for (int i = 0; i < 16; i++) {
        uint32_t px = bx + (uint32_t)(i & 3), py = by + (uint32_t)(i >> 2);
        px = px < w ? px : w - 1;
        py = py < h ? py : h - 1;
        const float *p = rgb + 3 * ((size_t)py * w + px);
        int over = 0, inside = px == bx + (uint32_t)(i & 3) && py == by + (uint32_t)(i >> 2);
        /* a texel past the edge or one no lookup reads counts little, not nothing: a block of
         * only such texels is still fitted */
        b.wt[i] = !inside ? 1e-3 : !care ? 1.0 : care[(size_t)py * w + px] ? (double)care[(size_t)py * w + px] : 1e-3;
        for (int c = 0; c < 3; c++) {
            b.h[i][c] = to_half(p[c], &over);
            b.x[i][c] = b.h[i][c] * 64.0 / 31.0;
        }
        clamped += inside && over;
    }
    fit best = {.error = 1e300};
    double lines[4][3];
    region_line(&b, 1, 0, 0, lines[0], lines[1]);
    for (int m = 0; m < LMB_BC6H_MODES; m++)
        if (lmb_bc6h_modes[m].regions == 1)
            try_mode(&b, m, 0, (const double(*)[3])lines, &best);
    /* two regions: the partitions whose regions lie nearest their own lines */
    int order[LMB_BC6H_TRY_PARTITIONS];
    double residual[LMB_BC6H_TRY_PARTITIONS];
    for (int k = 0; k < LMB_BC6H_TRY_PARTITIONS; k++) {
        order[k] = -1;
        residual[k] = 1e300;
    }
    for (int p = 0; p < 32 && best.error > 0; p++) {
        double l[4][3];
        double res = region_line(&b, 2, p, 0, l[0], l[1]) + region_line(&b, 2, p, 1, l[2], l[3]);
        for (int k = 0; k < LMB_BC6H_TRY_PARTITIONS; k++)
            if (res < residual[k]) {
                for (int j = LMB_BC6H_TRY_PARTITIONS - 1; j > k; j--) {
                    residual[j] = residual[j - 1];
                    order[j] = order[j - 1];
                }
                residual[k] = res;
                order[k] = p;
                break;
            }
    }
    for (int k = 0; k < LMB_BC6H_TRY_PARTITIONS && best.error > 0; k++) {
        if (order[k] < 0)
            continue;
        region_line(&b, 2, order[k], 0, lines[0], lines[1]);
        region_line(&b, 2, order[k], 1, lines[2], lines[3]);
        for (int m = 0; m < LMB_BC6H_MODES; m++)
            if (lmb_bc6h_modes[m].regions == 2)
                try_mode(&b, m, order[k], (const double(*)[3])lines, &best);
    }
    polish(&b, &best);
    lmb_bc6h_pack(best.mode, (const int(*)[3])best.q, best.partition, best.idx, out);
    return clamped;
}

size_t lmb_bc6h_size(uint32_t w, uint32_t h)
{
    return (size_t)((w + 3) / 4) * ((h + 3) / 4) * 16;
}

uint64_t lmb_bc6h_encode(uint32_t w, uint32_t h, const float *rgb, const uint8_t *care, int threads, uint8_t *blocks)
{
    uint32_t bw = (w + 3) / 4, bh = (h + 3) / 4;
    uint64_t clamped = 0;
#pragma omp parallel for num_threads(threads > 0 ? threads : omp_get_max_threads()) schedule(dynamic, 4) \
    reduction(+ : clamped)
    for (uint32_t j = 0; j < bh; j++)
        for (uint32_t i = 0; i < bw; i++)
            clamped += (uint64_t)encode_block(w, h, rgb, care, 4 * i, 4 * j, blocks + 16 * ((size_t)j * bw + i));
    return clamped;
}
