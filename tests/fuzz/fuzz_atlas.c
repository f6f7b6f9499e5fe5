/*
 * fuzz_atlas: the far-shadow atlas reader (core/shadow_atlas.c) on
 * arbitrary bytes, as a .tsa file's contents. Each input is read twice:
 * as it is, and, when it starts with the magic, with its header CRC
 * recomputed, so that mutations of the header fields reach the size checks,
 * the LZMA sections and the index maps instead of stopping at the CRC.
 * An atlas that opens is then read back whole (or a large window of it) and
 * with windows that must be refused.
 */
#include <lzma.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "shadow_atlas.h"

/* Largest window decoded per map: keeps each input fast. */
#define MAX_WINDOW_CELLS (1 << 16)

static void read_back(const ts_atlas *a)
{
    const ts_atlas_info *info = ts_atlas_get_info(a);
    ts_error err;
    fuzz_require(info && info->width >= 1 && info->height >= 1 && info->steps >= 1,
                 "an open atlas has no cells or no maps");
    fuzz_require(info->metadata != NULL, "an open atlas has no metadata text");
    (void)strlen(info->metadata);
    int w = info->width, h = info->height;
    if ((long long)w * h > MAX_WINDOW_CELLS) {
        w = w < 256 ? w : 256;
        h = MAX_WINDOW_CELLS / w < info->height ? MAX_WINDOW_CELLS / w : info->height;
    }
    uint8_t *out = malloc((size_t)w * (size_t)h);
    if (!out)
        return;
    int steps = info->steps < 8 ? info->steps : 8;
    for (int s = 0; s < steps; s++) {
        fuzz_require(ts_atlas_get_step(a, s) != NULL, "a map has no record");
        fuzz_require(ts_atlas_read(a, s, 0, 0, w, h, out, w, &err) == TS_OK,
                     "a window inside the atlas cannot be read");
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            fuzz_require(out[i] == 0 || out[i] == 1 || out[i] == TS_ATLAS_NODATA,
                         "a decoded cell is not 0, 1 or nodata");
        /* the last cell alone: the edge tiles */
        fuzz_require(ts_atlas_read(a, s, info->width - 1, info->height - 1, 1, 1, out, 1,
                     &err) == TS_OK, "the last cell cannot be read");
    }
    fuzz_require(ts_atlas_get_step(a, info->steps) == NULL,
                 "a map past the end has a record");
    fuzz_require(ts_atlas_get_step(a, -1) == NULL, "map -1 has a record");
    fuzz_require(ts_atlas_read(a, info->steps, 0, 0, 1, 1, out, 1, &err) != TS_OK,
                 "a map past the end was read");
    fuzz_require(ts_atlas_read(a, 0, info->width, 0, 1, 1, out, 1, &err) != TS_OK,
                 "a window right of the atlas was read");
    fuzz_require(ts_atlas_read(a, 0, 0, info->height, 1, 1, out, 1, &err) != TS_OK,
                 "a window below the atlas was read");
    fuzz_require(ts_atlas_read(a, 0, -1, 0, 1, 1, out, 1, &err) != TS_OK,
                 "a window at x = -1 was read");
    free(out);
}

static void open_and_read(const uint8_t *data, size_t size)
{
    ts_atlas *a = NULL;
    ts_error err;
    memset(&err, 0, sizeof err);
    if (ts_atlas_open(data, size, &a, &err) == TS_OK) {
        read_back(a);
        ts_atlas_free(a);
    } else {
        fuzz_require(a == NULL, "a failed open returned an atlas");
        fuzz_require(err.message[0] != '\0', "a failed open says nothing");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)ts_atlas_identify(data, size);
    open_and_read(data, size);
    if (size >= TS_ATLAS_HEADER_SIZE && ts_atlas_identify(data, size)) {
        uint8_t *fixed = malloc(size);
        if (!fixed)
            return 0;
        memcpy(fixed, data, size);
        uint32_t crc = lzma_crc32(fixed, 160, 0);
        for (int i = 0; i < 4; i++) {
            fixed[160 + i] = (uint8_t)(crc >> (8 * i));
            fixed[164 + i] = 0;
        }
        open_and_read(fixed, size);
        free(fixed);
    }
    return 0;
}
