/*
 * make_atlas_seeds: writes the valid atlases of the fuzz_atlas seed corpus
 * through the real writer (core/shadow_atlas.c). Run by hand when the format
 * changes (see docs/testing.md):
 *
 *   cc -std=c11 -D_GNU_SOURCE -Icore tests/fuzz/make_atlas_seeds.c core/shadow_atlas*.c \
 *      core/status.c core/datetime.c -llzma -lm -o /tmp/mas &&
 *      /tmp/mas tests/fuzz/corpus/fuzz_atlas
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shadow_atlas.h"

/* One atlas of w x h cells and `steps` maps: a shadow edge that moves with
 * the step, nodata in the first row's first cells when `nodata`. */
static int write_seed(const char *dir, const char *name, int w, int h, int steps,
                      int nodata, int georef, const char *metadata)
{
    ts_error err;
    ts_atlas_writer *wr = NULL;
    uint8_t *plane = malloc((size_t)w * h), *bytes = NULL;
    size_t size = 0;
    if (!plane || ts_atlas_writer_new(w, h, &wr, &err) != TS_OK)
        return fprintf(stderr, "%s: %s\n", name, err.message), 1;
    for (int s = 0; s < steps; s++) {
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                plane[(size_t)y * w + x] = (uint8_t)((x + y + s) % (3 + s) == 0);
        if (nodata)
            for (int x = 0; x < w && x < 3; x++)
                plane[x] = TS_ATLAS_NODATA;
        ts_atlas_step rec = {1782000000.0 + 1800.0 * s, 60.0 + 20.0 * s,
                             61.0 + 20.0 * s, 5.0 + 10.0 * s, 120};
        if (ts_atlas_writer_add(wr, plane, w, &rec, &err) != TS_OK)
            return fprintf(stderr, "%s: %s\n", name, err.message), 1;
    }
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    info.threshold_cells = 16;
    info.threshold_m = 480.0;
    info.has_geotransform = georef;
    double gt[6] = {2600000.0, 30.0, 0.0, 1200000.0, 0.0, -30.0};
    memcpy(info.geotransform, gt, sizeof gt);
    info.metadata = metadata;
    if (ts_atlas_writer_finish(wr, &info, &bytes, &size, &err) != TS_OK)
        return fprintf(stderr, "%s: %s\n", name, err.message), 1;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(bytes, 1, size, f) != size || fclose(f) != 0)
        return fprintf(stderr, "cannot write %s\n", path), 1;
    ts_atlas_writer_free(wr);
    free(bytes);
    free(plane);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2)
        return fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]), 2;
    const char *d = argv[1];
    return write_seed(d, "valid_1x1_1map.tsa", 1, 1, 1, 0, 0, NULL) |
           write_seed(d, "valid_8x8_2maps.tsa", 8, 8, 2, 0, 1, "DATE=2026-06-21\n") |
           write_seed(d, "valid_9x17_3maps_nodata.tsa", 9, 17, 3, 1, 1,
                      "DATE=2026-06-21\nTIMEZONE=+02:00\nZ_FACTOR=1\nBAND=1\n") |
           write_seed(d, "valid_33x5_4maps.tsa", 33, 5, 4, 0, 0,
                      "SOURCE_DEM=dem.tif\nCURVATURE=YES\n");
}
