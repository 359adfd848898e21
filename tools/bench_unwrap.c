/*
 * Unwrap benchmark (not a test: it measures time). For each reference mesh (Cornell box,
 * 128x80 UV sphere, 125x80 torus, and a 100k-triangle bumpy sphere): unwrap, pack into
 * one ~1024x1024 atlas with padding 2 at the highest density that fits, and print one CSV
 * row with the metrics of docs/unwrap.md and the charting/packing times, next to xatlas's figures
 * measured on this kind of machine (../shared/NOTES.md).
 * usage: bench_unwrap [SIZE] > unwrap.csv
 */
#include "meshgen.h"
#include "unwrap_fit.h"

#include <stdio.h>
#include <stdlib.h>

typedef struct ref {
    const char *name;
    double xatlas_coverage, xatlas_l2, xatlas_chart_s; /* < 0: not measured */
} ref;

int main(int argc, char **argv)
{
    uint32_t size = argc > 1 ? (uint32_t)atoi(argv[1]) : 1024;
    const ref refs[] = {{"cornell", 0.894, 1.000, -1},
                        {"sphere_128x80", 0.662, 1.0045, 2.5},
                        {"torus_125x80", 0.553, 1.0019, 2.4},
                        {"bumpy_sphere_100k", -1, -1, 35}};
    printf("mesh,triangles,charts,atlas_w,atlas_h,texels_per_unit,coverage,l2_stretch,density_p1,density_p50,"
           "density_p99,overlapping_texels,charting_s,packing_s,xatlas_coverage,xatlas_l2,xatlas_charting_s\n");
    for (int i = 0; i < 4; i++) {
        gen_mesh g;
        int rc = i == 0 ? gen_cornell_box(&g)
                 : i == 1 ? gen_uv_sphere(&g, 128, 80, 1.0f)
                 : i == 2 ? gen_torus(&g, 125, 80, 1.0f, 0.3f)
                          : gen_bumpy_sphere(&g, 400, 126, 1.0f, 0.04f);
        fit_result r;
        if (rc || fit_mesh(&g, size, 2, &r)) {
            fprintf(stderr, "bench_unwrap: %s failed\n", refs[i].name);
            return 1;
        }
        printf("%s,%u,%u,%u,%u,%.3f,%.4f,%.5f,%.3f,%.3f,%.3f,%llu,%.3f,%.3f,%g,%g,%g\n", refs[i].name, g.triangle_count,
               r.charts, r.width, r.height, r.density, r.coverage, r.l2_stretch, r.density_p1, r.density_p50,
               r.density_p99, (unsigned long long)r.overlapping_texels, r.chart_seconds, r.pack_seconds,
               refs[i].xatlas_coverage, refs[i].xatlas_l2, refs[i].xatlas_chart_s);
        fflush(stdout);
        gen_mesh_free(&g);
    }
    return 0;
}
