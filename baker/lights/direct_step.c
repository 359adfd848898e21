/* An atlas's gather points and direct light as a step of bands (direct_step.h). */
#include "direct_step.h"

#include <omp.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


typedef struct band_ctx {
    const lmb_direct_options *opt;
    const lmb_direct *direct;
    const lmb_scene *scene;
    const lmb_layout *layout;
    uint32_t atlas, width, height, rows; /* rows per band */
    lmb_progress_fn progress;
    void *progress_user;
    lmb_instance_rows instance_rows;     /* which instances a band visits */
} band_ctx;

uint32_t lmb_direct_group_bands(const lmb_direct_options *opt)
{
    int threads = opt->threads ? (int)opt->threads : omp_get_max_threads();
    return 4 * (uint32_t)(threads > 0 ? threads : 1);
}

lmb_status lmb_direct_build_bands(const lmb_direct_options *opt, const lmb_scene *scene, const lmb_layout *layout,
                                  uint32_t atlas, uint32_t rows, uint64_t first, uint64_t last,
                                  const lmb_instance_rows *instance_rows, const uint8_t *skip, lmb_texels *out,
                                  lmb_error *err)
{
    uint32_t height = layout->height[atlas];
    int64_t n = (int64_t)(last - first), failed_at = n;
    lmb_error *errs = calloc((size_t)n + 1, sizeof *errs);
    if (!errs)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", atlas);
    memset(out, 0, (size_t)n * sizeof *out);
    int threads = opt->threads ? (int)opt->threads : omp_get_max_threads();
    /* one band per thread at a time: a band's texels are built on one thread, the bands at once */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int64_t k = 0; k < n; k++) {
        if (skip && skip[k])
            continue;
        uint32_t y0 = (uint32_t)(first + (uint64_t)k) * rows, y1 = y0 + rows < height ? y0 + rows : height;
        if (lmb_texels_build_rows(scene, layout, atlas, opt->texel_samples, y0, y1, instance_rows, &out[k],
                                  &errs[k]) != LMB_OK) {
            memset(&out[k], 0, sizeof out[k]);
#pragma omp critical(lmb_build_bands_failed)
            failed_at = k < failed_at ? k : failed_at;
        }
    }
    lmb_status st = LMB_OK;
    if (failed_at < n) { /* the first band's error, whatever the threads did */
        *err = errs[failed_at];
        st = err->status;
        for (int64_t k = 0; k < n; k++)
            lmb_texels_free(&out[k]);
    }
    free(errs);
    return st;
}

/* The bands' output arrays (one allocation per array and band). */
typedef struct band_light {
    float *e, *variance, *dir, *deferred, *mask;
} band_light;

static void band_light_free(band_light *l)
{
    free(l->e);
    free(l->variance);
    free(l->dir);
    free(l->deferred);
    free(l->mask);
}

/* A band's bytes: u32 count; per texel u32 texel, f32 size, lmb_point_ref, u8 valid, u8 partly;
 * then 3 f32 direct light per texel, 3 f32 direction sum per texel when directional, 3 f32
 * deferred light (mixed lighting) and 4 f32 shadowmask visibilities when those are on; 1 f32
 * round variance per texel (lmb_direct_job). band_bytes is their size, put_band writes them
 * at dst (any band on any thread: each owns its range of the step's bytes). */
static size_t band_floats(int directional, int has_deferred, int has_mask);
static size_t band_texel_bytes(size_t floats);

static size_t band_bytes(const lmb_texels *t, const band_light *l)
{
    return 4 + band_texel_bytes(band_floats(l->dir != NULL, l->deferred != NULL, l->mask != NULL)) * t->count;
}

static void put_band(const lmb_texels *t, const band_light *l, uint8_t *dst)
{
    memcpy(dst, &t->count, 4);
    dst += 4;
    for (uint32_t i = 0; i < t->count; i++) {
        uint8_t flags[2] = {t->valid[i], t->edge[i]};
        memcpy(dst, &t->texel[i], 4);
        memcpy(dst + 4, &t->texel_size[i], 4);
        memcpy(dst + 8, &t->refs[(size_t)i * t->samples + t->gather_at[i]], sizeof(lmb_point_ref));
        memcpy(dst + 8 + sizeof(lmb_point_ref), flags, 2);
        dst += 10 + sizeof(lmb_point_ref);
    }
    size_t n = t->count;
    memcpy(dst, l->e, 3 * sizeof(float) * n);
    dst += 3 * sizeof(float) * n;
    if (l->dir) {
        memcpy(dst, l->dir, 3 * sizeof(float) * n);
        dst += 3 * sizeof(float) * n;
    }
    if (l->deferred) {
        memcpy(dst, l->deferred, 3 * sizeof(float) * n);
        dst += 3 * sizeof(float) * n;
    }
    if (l->mask) {
        memcpy(dst, l->mask, LMB_SHADOWMASK_CHANNELS * sizeof(float) * n);
        dst += LMB_SHADOWMASK_CHANNELS * sizeof(float) * n;
    }
    memcpy(dst, l->variance, sizeof(float) * n);
}

/* Bands [first, last) in groups of lmb_direct_group_bands: a group's bands are built at once
 * (a band per thread) and lit in one parallel loop over all their texels, then written in order. */
static lmb_status compute_bands(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    band_ctx *c = user;
    lmb_status st = LMB_OK;
    uint32_t group = lmb_direct_group_bands(c->opt);
    lmb_texels *bands = calloc(group, sizeof *bands);
    band_light *light = calloc(group, sizeof *light);
    lmb_direct_job *jobs = calloc(group, sizeof *jobs);
    float **irradiance = calloc(group, sizeof *irradiance);
    if (!bands || !light || !jobs || !irradiance)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", c->atlas);
    int has_deferred = lmb_direct_has_deferred(c->direct), has_mask = lmb_direct_shadowmask_channels(c->direct) > 0;
    for (uint64_t g = first; g < last && st == LMB_OK; g += group) {
        uint32_t n = (uint32_t)(last - g < group ? last - g : group);
        st = lmb_direct_build_bands(c->opt, c->scene, c->layout, c->atlas, c->rows, g, g + n, &c->instance_rows, NULL,
                                    bands, err);
        if (st != LMB_OK)
            break;
        for (uint32_t k = 0; k < n && st == LMB_OK; k++) {
            size_t count = bands[k].count;
            band_light *l = &light[k];
            memset(l, 0, sizeof *l);
            l->e = calloc(3 * count + 1, sizeof *l->e);
            l->variance = calloc(count + 1, sizeof *l->variance);
            l->dir = c->opt->directional ? calloc(3 * count + 1, sizeof *l->dir) : NULL;
            l->deferred = has_deferred ? calloc(3 * count + 1, sizeof *l->deferred) : NULL;
            l->mask = has_mask ? calloc(LMB_SHADOWMASK_CHANNELS * count + 1, sizeof *l->mask) : NULL;
            if (!l->e || !l->variance || (c->opt->directional && !l->dir) || (has_deferred && !l->deferred) ||
                (has_mask && !l->mask))
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", c->atlas);
            jobs[k] = (lmb_direct_job){c->direct, c->atlas, l->dir, l->deferred, l->mask, l->variance, NULL};
            irradiance[k] = l->e;
        }
        if (st == LMB_OK)
            st = lmb_direct_compute_bands(jobs, bands, irradiance, n, &counters[0], &counters[1], err);
        size_t at = out->size, total = 0;
        for (uint32_t k = 0; k < n && st == LMB_OK; k++)
            total += band_bytes(&bands[k], &light[k]);
        uint8_t *bytes = st == LMB_OK ? lmb_buf_extend(out, total, err) : NULL;
        if (st == LMB_OK && !bytes)
            st = err->status;
        if (bytes) {
            size_t *offset = calloc((size_t)n + 1, sizeof *offset);
            for (uint32_t k = 0; offset && k + 1 < n; k++)
                offset[k + 1] = offset[k] + band_bytes(&bands[k], &light[k]);
            if (!offset)
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", c->atlas);
            int threads = c->opt->threads ? (int)c->opt->threads : omp_get_max_threads();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
            for (uint32_t k = 0; k < (offset ? n : 0); k++)
                put_band(&bands[k], &light[k], out->data + at + offset[k]);
            free(offset);
        }
        for (uint32_t k = 0; k < n; k++) {
            band_light_free(&light[k]);
            memset(&light[k], 0, sizeof light[k]);
            lmb_texels_free(&bands[k]);
        }
        uint64_t rows_done = (g + n) * c->rows < c->height ? (g + n) * c->rows : c->height;
        if (st == LMB_OK && c->progress)
            c->progress(c->progress_user, "direct", rows_done * c->width, (uint64_t)c->height * c->width);
    }
    free(bands);
    free(light);
    free(jobs);
    free(irradiance);
    return st;
}

/* Grows *arr to hold `total` texels of `per` floats; 0 when out of memory. */
static int grow_floats(float **arr, size_t total, size_t per)
{
    float *p = realloc(*arr, (per * total + 1) * sizeof *p);
    if (p)
        *arr = p;
    return p != NULL;
}

/* Floats per texel a band's bytes hold after its texels: direct (3), direction (3), deferred (3),
 * shadowmask (4) when present, variance (1). */
static size_t band_floats(int directional, int has_deferred, int has_mask)
{
    return 3 + (directional ? 3 : 0) + (has_deferred ? 3 : 0) + (has_mask ? LMB_SHADOWMASK_CHANNELS : 0) + 1;
}

/* Bytes per texel of a band: its texel, size, point reference and flags, then its floats. */
static size_t band_texel_bytes(size_t floats)
{
    return 4 + 4 + sizeof(lmb_point_ref) + 2 + floats * sizeof(float);
}

/* Texels in the bands of `in` from its read position; UINT64_MAX when they do not parse whole. */
static uint64_t bands_texels(const lmb_buf *in, size_t floats)
{
    uint64_t total = 0;
    size_t at = in->read, per = band_texel_bytes(floats);
    while (at < in->size) {
        uint32_t n;
        if (in->size - at < 4)
            return UINT64_MAX;
        memcpy(&n, in->data + at, 4);
        if ((uint64_t)n * per > in->size - at - 4)
            return UINT64_MAX;
        at += 4 + (size_t)n * per;
        total += n;
    }
    return total;
}

/* Room in out's arrays for `more` texels beyond those it holds: the bands in one buffer are then
 * appended without moving anything (each array grown exactly once per buffer, not once per band:
 * grown band by band they were copied whole once they no longer fit in place). */
static lmb_status reserve_bands(lmb_direct_atlas *out, uint64_t more, int directional, int has_deferred, int has_mask,
                                uint32_t atlas, lmb_error *err)
{
    size_t total = (size_t)out->t.count + more;
    if (!more)
        return LMB_OK;
    if (total > UINT32_MAX)
        return lmb_error_set(err, LMB_ERR_INPUT, "direct light of atlas %u: more than 4 billion texels", atlas);
    float *d = realloc(out->direct, (3 * total + 1) * sizeof *d);
    if (d)
        out->direct = d;
    float *nz = realloc(out->variance, (total + 1) * sizeof *nz);
    if (nz)
        out->variance = nz;
    if (!d || !nz || (directional && !grow_floats(&out->direction, total, 3)) ||
        (has_deferred && !grow_floats(&out->deferred, total, 3)) ||
        (has_mask && !grow_floats(&out->shadowmask, total, LMB_SHADOWMASK_CHANNELS)))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", atlas);
    return lmb_texels_reserve(&out->t, (uint32_t)total, err);
}

/* Appends the next band of `in` to out, whose arrays reserve_bands made room in (the buffer's
 * bands were checked whole by bands_texels). */
static lmb_status take_band(lmb_buf *in, int directional, int has_deferred, int has_mask, lmb_direct_atlas *out,
                            const band_ctx *c, lmb_error *err)
{
    uint32_t n;
    if (!lmb_buf_take(in, &n, 4) || (size_t)out->t.count + n > out->t.capacity)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct light of atlas %u: a band beyond the room made", c->atlas);
    lmb_texels band;
    memset(&band, 0, sizeof band);
    band.width = c->width;
    band.height = c->height;
    band.samples = 1;
    band.scene = c->scene;
    band.layout = c->layout;
    band.count = n;
    band.texel = malloc(((size_t)n + 1) * sizeof *band.texel);
    band.texel_size = malloc(((size_t)n + 1) * sizeof *band.texel_size);
    band.refs = malloc(((size_t)n + 1) * sizeof *band.refs);
    band.valid = malloc((size_t)n + 1);
    band.edge = malloc((size_t)n + 1);
    band.gather_at = calloc((size_t)n + 1, 1);
    lmb_status st = LMB_OK;
    if (!band.texel || !band.texel_size || !band.refs || !band.valid || !band.edge || !band.gather_at)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", c->atlas);
    for (uint32_t i = 0; i < n && st == LMB_OK; i++) {
        uint8_t flags[2];
        lmb_buf_take(in, &band.texel[i], 4);
        lmb_buf_take(in, &band.texel_size[i], 4);
        lmb_buf_take(in, &band.refs[i], sizeof band.refs[i]);
        lmb_buf_take(in, flags, 2);
        band.valid[i] = flags[0];
        band.edge[i] = flags[1];
    }
    if (st == LMB_OK && n && (!lmb_buf_take(in, out->direct + 3 * (size_t)out->t.count, 3 * sizeof(float) * n) ||
                         (directional && !lmb_buf_take(in, out->direction + 3 * (size_t)out->t.count,
                                                       3 * sizeof(float) * n)) ||
                         (has_deferred && !lmb_buf_take(in, out->deferred + 3 * (size_t)out->t.count,
                                                        3 * sizeof(float) * n)) ||
                         (has_mask && !lmb_buf_take(in, out->shadowmask + LMB_SHADOWMASK_CHANNELS * (size_t)out->t.count,
                                                    LMB_SHADOWMASK_CHANNELS * sizeof(float) * n)) ||
                         !lmb_buf_take(in, out->variance + out->t.count, sizeof(float) * n)))
        st = lmb_error_set(err, LMB_ERR_INPUT, "direct light of atlas %u: truncated band", c->atlas);
    if (st == LMB_OK)
        st = lmb_texels_append(&out->t, &band, err);
    lmb_texels_free(&band);
    return st;
}

/* The step's bytes as they come (lmb_steps_run_streamed): every band in them appended to out. */
typedef struct bands_taken {
    lmb_direct_atlas *out;
    const band_ctx *c;
    uint64_t bands;
} bands_taken;

static lmb_status take_bands(void *user, lmb_buf *bytes, lmb_error *err)
{
    bands_taken *bt = user;
    const band_ctx *c = bt->c;
    int directional = c->opt->directional, has_deferred = lmb_direct_has_deferred(c->direct);
    int has_mask = lmb_direct_shadowmask_channels(c->direct) > 0;
    uint64_t more = bands_texels(bytes, band_floats(directional, has_deferred, has_mask));
    if (more == UINT64_MAX)
        return lmb_error_set(err, LMB_ERR_INPUT, "direct light of atlas %u: truncated band", c->atlas);
    lmb_status st = reserve_bands(bt->out, more, directional, has_deferred, has_mask, c->atlas, err);
    for (; bytes->read < bytes->size && st == LMB_OK; bt->bands++)
        st = take_band(bytes, directional, has_deferred, has_mask, bt->out, c, err);
    return st;
}

/* Each band's estimated cost: the atlas area its rows hold under the instances' triangles
 * (each triangle's area spread evenly over the rows it spans; covered texels cast the rays),
 * plus a little per texel (an empty texel is still visited). Packing leaves whole rows nearly
 * empty, so the band's area alone would give the farm's shards unequal work. */
static void band_costs(const lmb_layout *layout, uint32_t a, uint32_t width, uint32_t height, uint32_t rows,
                       uint64_t bands, double *cost)
{
    for (uint64_t b = 0; b < bands; b++) {
        uint64_t y0 = b * rows, y1 = y0 + rows < height ? y0 + rows : height;
        cost[b] = 0.05 * (double)((y1 - y0) * width);
    }
    for (uint32_t i = 0; i < layout->instance_count; i++) {
        const lmb_layout_instance *li = &layout->instances[i];
        if (!li->lightmapped || li->atlas != a)
            continue;
        for (size_t f = 0; f < li->triangle_count; f++) {
            double q[6];
            lmb_layout_uv(layout, i, f, q);
            double area = 0.5 * fabs((q[2] - q[0]) * (q[5] - q[1]) - (q[4] - q[0]) * (q[3] - q[1]));
            double lo = fmin(q[1], fmin(q[3], q[5])), hi = fmax(q[1], fmax(q[3], q[5]));
            if (!(area > 0) || hi < 0 || lo >= height)
                continue;
            lo = lo < 0 ? 0 : lo;
            hi = hi > height ? height : hi;
            uint64_t b0 = (uint64_t)lo / rows, b1 = (uint64_t)(hi > lo ? hi - 1e-9 : lo) / rows;
            b1 = b1 < bands ? b1 : bands - 1;
            for (uint64_t b = b0; b <= b1 && b < bands; b++) { /* the share of [lo, hi] in the band's rows */
                double r0 = (double)(b * rows), r1 = (double)((b + 1) * rows);
                double part = hi > lo ? (fmin(hi, r1) - fmax(lo, r0)) / (hi - lo) : 1.0;
                cost[b] += area * (part > 0 ? part : 0);
            }
        }
    }
}

lmb_status lmb_direct_atlas_step(lmb_steps *steps, const lmb_direct *direct,
                                 const lmb_scene *scene, const lmb_layout *layout, uint32_t a, lmb_progress_fn progress,
                                 void *progress_user, lmb_direct_atlas *out, uint64_t *rays, lmb_error *err)
{
    const lmb_direct_options *opt = lmb_direct_opts(direct);
    memset(out, 0, sizeof *out);
    band_ctx c = {opt, direct, scene, layout, a, layout->width[a], layout->height[a], 1, progress, progress_user,
                  {0}};
    c.rows = c.width ? (LMB_DIRECT_BAND_TEXELS + c.width - 1) / c.width : c.height;
    if (!c.rows)
        c.rows = 1;
    uint64_t bands = c.height ? (c.height + (uint64_t)c.rows - 1) / c.rows : 0;
    double *cost = malloc((bands + 1) * sizeof *cost);
    if (!cost)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
    lmb_status st = lmb_instance_rows_make(scene, layout, a, c.rows, &c.instance_rows, err);
    if (st != LMB_OK) {
        free(cost);
        return st;
    }
    band_costs(layout, a, c.width, c.height, c.rows, bands, cost);
    char name[64];
    snprintf(name, sizeof name, "direct, atlas %u", a);
    /* rays: sub-samples x shadow rays, over the atlas's area (an upper bound: not every texel is used) */
    lmb_step_desc d = {name, bands, cost, (double)c.width * c.height * opt->texel_samples * opt->samples,
                       compute_bands, &c};
    uint64_t counters[LMB_STEP_COUNTERS];
    bands_taken taken = {out, &c, 0};
    if (progress) /* the stage starts now, not when its first group is done */
        progress(progress_user, "direct", 0, (uint64_t)c.height * c.width);
    /* a group of bands at a time (compute_bands): the bytes of one group are held at once */
    st = lmb_steps_run_streamed(steps, &d, lmb_direct_group_bands(opt), take_bands, &taken, counters, err);
    *rays += counters[0];
    out->rays = counters[0];
    if (st == LMB_OK && taken.bands != bands)
        st = lmb_error_set(err, LMB_ERR_INPUT, "direct light of atlas %u: %llu of %llu bands", a,
                           (unsigned long long)taken.bands, (unsigned long long)bands);
    if (st == LMB_OK && !out->t.texel) { /* an atlas without texels: empty arrays, not NULL */
        lmb_texels empty;
        memset(&empty, 0, sizeof empty);
        empty.width = c.width;
        empty.height = c.height;
        empty.samples = 1;
        st = lmb_texels_append(&out->t, &empty, err);
    }
    if (st == LMB_OK && !out->direct)
        out->direct = calloc(1, sizeof *out->direct);
    if (st == LMB_OK && !out->variance)
        out->variance = calloc(1, sizeof *out->variance);
    if (st == LMB_OK && lmb_direct_has_deferred(direct) && !out->deferred)
        out->deferred = calloc(1, sizeof *out->deferred);
    if (st == LMB_OK && lmb_direct_shadowmask_channels(direct) && !out->shadowmask)
        out->shadowmask = calloc(1, sizeof *out->shadowmask);
    if (st == LMB_OK && opt->directional && !out->direction)
        out->direction = calloc(1, sizeof *out->direction);
    if (st == LMB_OK && (!out->direct || !out->variance || (opt->directional && !out->direction)))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
    free(cost);
    lmb_instance_rows_free(&c.instance_rows);
    return st;
}
