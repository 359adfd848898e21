/* The gather points' validity memo (point_validity.h): allocation. */
#include "point_validity.h"

#include <stdlib.h>
#include <string.h>

lmb_status lmb_point_validity_init(lmb_point_validity *v, const lmb_layout *layout, uint32_t samples, lmb_error *err)
{
    memset(v, 0, sizeof *v);
    v->atlas_count = layout->atlas_count;
    v->samples = samples;
    v->size = calloc((size_t)v->atlas_count + 1, sizeof *v->size);
    v->entry = calloc((size_t)v->atlas_count + 1, sizeof *v->entry);
    int ok = v->size && v->entry;
    for (uint32_t a = 0; ok && a < v->atlas_count; a++) {
        v->size[a] = (uint64_t)layout->width[a] * layout->height[a] * samples;
        v->entry[a] = calloc(v->size[a] + 1, 1);
        ok = v->entry[a] != NULL;
    }
    if (!ok) {
        lmb_point_validity_free(v);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "gather points' validity: out of memory");
    }
    return LMB_OK;
}

void lmb_point_validity_free(lmb_point_validity *v)
{
    for (uint32_t a = 0; v->entry && a < v->atlas_count; a++)
        free(v->entry[a]);
    free(v->entry);
    free(v->size);
    memset(v, 0, sizeof *v);
}

uint64_t lmb_point_validity_known(const lmb_point_validity *v)
{
    uint64_t n = 0;
    for (uint32_t a = 0; a < v->atlas_count; a++)
        for (uint64_t i = 0; i < v->size[a]; i++)
            n += v->entry[a][i] != LMB_VALIDITY_UNKNOWN;
    return n;
}
