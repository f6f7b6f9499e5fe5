/* The far-shadow atlas (core/shadow_atlas.h): the tile dictionary + LZMA
 * file round trip (lossless, any size, with nodata, 2- and 4-byte
 * indices), damaged files, and a day's far-shadow atlas of jacksboro. The
 * far field it is made of: check_far_horizon.c. */
#include <check.h>
#include <lzma.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "shadow_atlas.h"
#include "test_expect.h"
#include "test_grid.h"
#include "test_run.h"

/* The noise of the random maps and windows; each test runs in its own
 * process, so each starts from this state. */
static uint32_t rng_state = 12345;
static uint32_t rnd(void) { return tdem_xorshift32(&rng_state); }

/* ----------------------------------------------------------- the file */

/* Write `steps` planes, read them back whole and by windows. */
static void round_trip(int W, int H, int steps, int nodata, int noise, size_t *file_size,
                       int *index_bytes)
{
    ts_error err;
    size_t n = (size_t)W * H;
    uint8_t *planes = malloc(n * steps), *back = malloc(n);
    for (int s = 0; s < steps; s++)
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                uint8_t v;
                if (nodata && (x * 7 + y * 3) % 11 == 0)
                    v = TS_ATLAS_NODATA;
                else if (noise)
                    v = rnd() & 1;
                else /* a shadow front moving with the step */
                    v = x + y / 2 < (W * (s + 1)) / (steps + 1) ? 1 : 0;
                planes[s * n + (size_t)y * W + x] = v;
            }
    ts_atlas_writer *w;
    ck_assert(ts_atlas_writer_new(W, H, &w, &err) == TS_OK);
    for (int s = 0; s < steps; s++) {
        ts_atlas_step rec = {1.75e9 + 600.0 * s, 90.0 + s, 92.5 + s, 5.0 + s, -300};
        ck_assert_msg(ts_atlas_writer_add(w, planes + s * n, W, &rec, &err) == TS_OK, "%s",
                      err.message);
    }
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    info.threshold_cells = 512;
    info.threshold_m = 512 * 30.0;
    info.has_geotransform = 1;
    double gt[6] = {500000, 30, 0, 4100000, 0, -30};
    memcpy(info.geotransform, gt, sizeof gt);
    info.metadata = "PRODUCT=farshadow\nDATE=2026-06-21\n";
    uint8_t *file;
    size_t size;
    ck_assert(ts_atlas_writer_finish(w, &info, &file, &size, &err) == TS_OK);
    ts_atlas_writer_free(w);
    ck_assert(ts_atlas_identify(file, size));
    ts_atlas *a;
    ck_assert_msg(ts_atlas_open(file, size, &a, &err) == TS_OK, "%s", err.message);
    free(file);
    const ts_atlas_info *ai = ts_atlas_get_info(a);
    ck_assert(ai->width == W && ai->height == H && ai->steps == steps);
    ck_assert(ai->threshold_cells == 512 && ai->threshold_m == 512 * 30.0);
    ck_assert(ai->has_geotransform && memcmp(ai->geotransform, gt, sizeof gt) == 0);
    ck_assert(ai->has_nodata == nodata);
    ck_assert_str_eq(ai->metadata, "PRODUCT=farshadow\nDATE=2026-06-21\n");
    for (int s = 0; s < steps; s++) {
        const ts_atlas_step *r = ts_atlas_get_step(a, s);
        ck_assert(r->unix_time == 1.75e9 + 600.0 * s && r->azimuth == 90.0 + s &&
                  r->grid_azimuth == 92.5 + s && r->elevation == 5.0 + s &&
                  r->utc_offset_minutes == -300);
        memset(back, 7, n);
        ck_assert(ts_atlas_read(a, s, 0, 0, W, H, back, W, &err) == TS_OK);
        ck_assert_msg(memcmp(back, planes + s * n, n) == 0, "map %d differs", s);
        /* odd windows */
        for (int k = 0; k < 5; k++) {
            int x0 = rnd() % W, y0 = rnd() % H;
            int ww = 1 + rnd() % (W - x0), hh = 1 + rnd() % (H - y0);
            uint8_t *win = malloc((size_t)ww * hh);
            ck_assert(ts_atlas_read(a, s, x0, y0, ww, hh, win, ww, &err) == TS_OK);
            for (int y = 0; y < hh; y++)
                ck_assert(memcmp(win + (size_t)y * ww,
                                 planes + s * n + (size_t)(y0 + y) * W + x0, ww) == 0);
            free(win);
        }
    }
    ck_assert(ts_atlas_get_step(a, steps) == NULL);
    EXPECT_ARG(ts_atlas_read(a, steps, 0, 0, 1, 1, back, 1, &err), &err);
    EXPECT_ARG(ts_atlas_read(a, 0, W - 1, 0, 2, 1, back, 2, &err), &err);
    *file_size = ai->file_bytes;
    *index_bytes = ai->index_bytes;
    ts_atlas_free(a);
    free(planes);
    free(back);
}

START_TEST(test_round_trip)
{
    size_t size;
    int ib;
    const int sizes[][2] = {{1, 1}, {8, 8}, {9, 7}, {37, 29}, {130, 70}, {256, 3}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        for (int nd = 0; nd < 2; nd++)
            for (int noise = 0; noise < 2; noise++) {
                round_trip(sizes[i][0], sizes[i][1], 5, nd, noise, &size, &ib);
                ck_assert_int_eq(ib, 2);
            }
    round_trip(200, 160, 40, 0, 0, &size, &ib);
    printf("moving front, 200 x 160, 40 maps: %zu bytes = %.3f bits per cell\n", size,
           size * 8.0 / (200 * 160));
    /* noise: more than 65536 distinct tiles, so 4-byte indices */
    round_trip(1024, 1024, 5, 1, 1, &size, &ib);
    ck_assert_int_eq(ib, 4);
    printf("noise, 1024 x 1024, 5 maps: %d-byte indices, %zu bytes\n", ib, size);
}
END_TEST

START_TEST(test_bad_maps_and_files)
{
    ts_error err;
    ts_atlas_writer *w;
    uint8_t plane[16 * 16], other[16 * 16];
    memset(plane, 0, sizeof plane);
    ck_assert(ts_atlas_writer_new(16, 16, &w, &err) == TS_OK);
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    uint8_t *file;
    size_t size;
    EXPECT_ARG(ts_atlas_writer_finish(w, &info, &file, &size, &err), &err); /* no map */
    plane[17] = 2;
    EXPECT_ARG(ts_atlas_writer_add(w, plane, 16, NULL, &err), &err);
    ck_assert(strstr(err.message, "binary"));
    plane[17] = TS_ATLAS_NODATA;
    ck_assert(ts_atlas_writer_add(w, plane, 16, NULL, &err) == TS_OK);
    memcpy(other, plane, sizeof other);
    other[17] = 1;
    EXPECT_ARG(ts_atlas_writer_add(w, other, 16, NULL, &err), &err);
    ck_assert(strstr(err.message, "nodata"));
    ck_assert(ts_atlas_writer_finish(w, &info, &file, &size, &err) == TS_OK);
    ts_atlas_writer_free(w);
    EXPECT_ARG(ts_atlas_writer_new(0, 5, &w, &err), &err);

    ts_atlas *a;
    /* truncated anywhere */
    for (size_t cut = 0; cut < size; cut += 1 + cut / 3) {
        ts_status st = ts_atlas_open(file, cut, &a, &err);
        ck_assert_msg(st == TS_ERR_ARG, "truncated at %zu: status %d", cut, (int)st);
    }
    /* one flipped bit anywhere */
    int caught = 0, total = 0;
    for (size_t i = 0; i < size; i++) {
        uint8_t *copy = malloc(size);
        memcpy(copy, file, size);
        copy[i] ^= 0x10;
        ts_status st = ts_atlas_open(copy, size, &a, &err);
        if (st == TS_OK)
            ts_atlas_free(a);
        else
            caught += st == TS_ERR_ARG;
        total++;
        free(copy);
    }
    /* version 2: the step records and the metadata text are under a CRC too */
    printf("damaged atlas (%zu bytes): %d of %d single-bit flips refused\n", size, caught,
           total);
    ck_assert_int_eq(caught, total);
    /* the header alone against the file's size (what the driver reads
     * first): this file's size passes, a longer or shorter file does not */
    ck_assert_msg(ts_atlas_check_header(file, TS_ATLAS_HEADER_SIZE, size, &err) == TS_OK,
                  "%s", err.message);
    EXPECT_ARG(ts_atlas_check_header(file, TS_ATLAS_HEADER_SIZE, (uint64_t)3 << 30, &err),
               &err);
    ck_assert(strstr(err.message, "bytes follow its last section"));
    EXPECT_ARG(ts_atlas_check_header(file, TS_ATLAS_HEADER_SIZE, size - 1, &err), &err);
    ck_assert(strstr(err.message, "truncated"));
    EXPECT_ARG(ts_atlas_check_header(file, 100, size, &err), &err); /* too few bytes */
    /* not an atlas */
    EXPECT_ARG(ts_atlas_open((const uint8_t *)"GIF89a..........", 16, &a, &err), &err);
    ck_assert(!ts_atlas_identify((const uint8_t *)"\x89PNG", 4));
    /* a future version */
    file[8] = 3;
    EXPECT_ARG(ts_atlas_open(file, size, &a, &err), &err);
    ck_assert(strstr(err.message, "version 3"));
    /* version 1 (no checksum over the steps and the text): recreate it */
    file[8] = 1;
    uint32_t crc = lzma_crc32(file, 160, 0);
    for (int i = 0; i < 4; i++)
        file[160 + i] = (uint8_t)(crc >> (8 * i));
    EXPECT_ARG(ts_atlas_open(file, size, &a, &err), &err);
    ck_assert(strstr(err.message, "version 1") && strstr(err.message, "recreate"));
    free(file);
}
END_TEST

/* A valid 3-map atlas of 16 x 16 cells, its steps 10 minutes apart. */
static uint8_t *small_atlas(size_t *size)
{
    ts_error err;
    ts_atlas_writer *w;
    uint8_t plane[16 * 16];
    memset(plane, 0, sizeof plane);
    ck_assert(ts_atlas_writer_new(16, 16, &w, &err) == TS_OK);
    for (int s = 0; s < 3; s++) {
        ts_atlas_step rec = {1.75e9 + 600.0 * s, 100.0 + s, 101.0 + s, 10.0 + s, 120};
        ck_assert(ts_atlas_writer_add(w, plane, 16, &rec, &err) == TS_OK);
    }
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    info.metadata = "PRODUCT=farshadow\nBAND=1\n";
    uint8_t *file;
    ck_assert(ts_atlas_writer_finish(w, &info, &file, size, &err) == TS_OK);
    ts_atlas_writer_free(w);
    return file;
}

static void put_le(uint8_t *p, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* Forge field `at` (byte offset in the record) of map k's step record, and
 * the CRC that covers it, as a hostile writer would. */
static void forge_step(uint8_t *file, int k, int at, double value, int32_t offset)
{
    uint8_t *r = file + TS_ATLAS_HEADER_SIZE + (size_t)k * TS_ATLAS_STEP_SIZE;
    if (at == 32 || at == 36) { /* the offset, the reserved field */
        put_le(r + at, (uint32_t)offset, 4);
    } else {
        uint64_t u;
        memcpy(&u, &value, 8);
        put_le(r + at, u, 8);
    }
    uint64_t text_off = 0, text_n = 0;
    for (int i = 7; i >= 0; i--) {
        text_off = text_off << 8 | file[112 + i];
        text_n = text_n << 8 | file[120 + i];
    }
    uint32_t crc = lzma_crc32(file + TS_ATLAS_HEADER_SIZE, 3 * TS_ATLAS_STEP_SIZE, 0);
    put_le(file + 164, lzma_crc32(file + text_off, text_n, crc), 4);
}

/* A step table whose records hold garbage is refused with its cause, on
 * reading (a forged file with a valid CRC) and on writing. */
START_TEST(test_bad_step_tables)
{
    const struct {
        int map, at;
        double value;
        int32_t offset;
        const char *cause;
    } cases[] = {
        {1, 0, NAN, 0, "either every map has one or none has"},
        {2, 0, 1.75e9, 0, "is not after map 2's"},
        {0, 0, -9.2e18, 0, "between the years -2000 and 6000"},
        {0, 0, INFINITY, 0, "between the years -2000 and 6000"},
        {0, 0, 1.75e9 - 90000.0, 0, "more than the one day"},
        {1, 24, 95.0, 0, "elevation (95) lies outside -90 to 90"},
        {1, 24, NAN, 0, NULL}, /* an unknown elevation is allowed */
        {2, 8, 400.0, 0, "azimuth (400 true"},
        {2, 16, -1.0, 0, "-1 grid) lies outside 0 to 360"},
        {0, 32, 0, 5000, "offset from UTC (5000 minutes)"},
        {0, 32, 0, INT32_MIN, "lies outside -23:59 to +23:59"},
        {1, 36, 0, 9, "map 2's reserved field is 9, not 0"},
    };
    ts_error err;
    ts_atlas *a;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t size;
        uint8_t *file = small_atlas(&size);
        forge_step(file, cases[i].map, cases[i].at, cases[i].value, cases[i].offset);
        ts_status st = ts_atlas_open(file, size, &a, &err);
        if (!cases[i].cause) {
            ck_assert_msg(st == TS_OK, "%s", err.message);
            ts_atlas_free(a);
        } else {
            ck_assert_msg(st == TS_ERR_ARG && err.code == TS_ERR_ARG, "case %zu: status %d", i,
                          (int)st);
            printf("forged step table, case %zu -> %s\n", i, err.message);
            ck_assert_msg(
                strstr(err.message, "the atlas's step table is invalid: ") == err.message &&
                    strstr(err.message, cases[i].cause),
                "case %zu: %s", i, err.message);
        }
        free(file);
    }
    /* a flag bit version 2 does not define, under a valid header CRC */
    size_t size;
    uint8_t *file = small_atlas(&size);
    file[34] |= 0x10; /* bit 20 of the flags at byte 32 */
    put_le(file + 160, lzma_crc32(file, 160, 0), 4);
    EXPECT_ARG(ts_atlas_open(file, size, &a, &err), &err);
    ck_assert_msg(strstr(err.message, "sets flag bits 0x100000, which version 2 does not "
                                      "define"), "%s", err.message);
    free(file);
    /* the metadata text changed without its CRC */
    file = small_atlas(&size);
    uint8_t *text = memchr(file, '=', size);
    ck_assert(text != NULL);
    text[1] = 'x';
    EXPECT_ARG(ts_atlas_open(file, size, &a, &err), &err);
    ck_assert(strstr(err.message, "step table or metadata text is damaged"));
    free(file);
    /* the writer refuses what the reader would */
    ts_atlas_writer *w;
    uint8_t plane[4] = {0, 1, 0, 1};
    ck_assert(ts_atlas_writer_new(2, 2, &w, &err) == TS_OK);
    ts_atlas_step late = {2e9, 10, 10, 10, 0}, early = {1e9, 10, 10, 10, 0};
    ck_assert(ts_atlas_writer_add(w, plane, 2, &late, &err) == TS_OK);
    ck_assert(ts_atlas_writer_add(w, plane, 2, &early, &err) == TS_OK);
    uint8_t *bytes;
    EXPECT_ARG(ts_atlas_writer_finish(w, NULL, &bytes, &size, &err), &err);
    ck_assert(strstr(err.message, "cannot write the atlas: map 2's time"));
    ts_atlas_writer_free(w);
}
END_TEST

/* A day of far shadows over jacksboro: far threshold 24 cells so that
 * the small DEM has some; written, read back identical; bits per cell. */
START_TEST(test_jacksboro_day)
{
    ts_error err;
    ts_grid g;
    tdem_load(&g, "jacksboro");
    size_t n = (size_t)g.width * g.height;
    double lon = -84.245, lat = 36.589, north = 0;
    ts_sun_sites s = {1, 1, 0, 0, 0, 0, &lon, &lat, &north};
    ts_day_opts o;
    ts_day_opts_default(&o);
    double start = ts_local_midnight(2026, 12, 21, -300);
    enum { STEPS = 24 };
    double t[STEPS];
    int steps;
    ck_assert(ts_day_atlas_times(&s, &o, start, 86400, STEPS, t, &steps, &err) == TS_OK);
    ck_assert_int_eq(steps, STEPS);
    double T = 24 * 74.4;
    uint8_t *maps = malloc(n * STEPS), *back = malloc(n);
    ts_atlas_writer *w;
    ck_assert(ts_atlas_writer_new(g.width, g.height, &w, &err) == TS_OK);
    size_t shadowed = 0;
    for (int k = 0; k < STEPS; k++) {
        ts_sun_sample sun;
        ck_assert(ts_sun_at_site(&s, &o, t[k], &sun, &err) == TS_OK);
        ck_assert(ts_far_shadow(&g, sun.grid_azimuth, sun.elevation, T, &o.horizon,
                                maps + k * n, &err) == TS_OK);
        for (size_t i = 0; i < n; i++)
            shadowed += maps[k * n + i] == 1;
        ts_atlas_step rec = {t[k], sun.azimuth, sun.grid_azimuth, sun.elevation, -300};
        ck_assert(ts_atlas_writer_add(w, maps + k * n, g.width, &rec, &err) == TS_OK);
    }
    uint8_t *file;
    size_t size;
    ts_atlas_info info;
    memset(&info, 0, sizeof info);
    ck_assert(ts_atlas_writer_finish(w, &info, &file, &size, &err) == TS_OK);
    ts_atlas_writer_free(w);
    ts_atlas *a;
    ck_assert(ts_atlas_open(file, size, &a, &err) == TS_OK);
    for (int k = 0; k < STEPS; k++) {
        ck_assert(ts_atlas_read(a, k, 0, 0, g.width, g.height, back, g.width, &err) == TS_OK);
        ck_assert(memcmp(back, maps + k * n, n) == 0);
    }
    printf("jacksboro 2026-12-21, far threshold 24 cells, %d maps: %.1f%% of cell-maps in "
           "far shadow, %u distinct tiles, %zu bytes = %.4f bits per cell per day\n",
           STEPS, 100.0 * shadowed / (n * STEPS), ts_atlas_get_info(a)->dictionary_tiles,
           size, size * 8.0 / n);
    ck_assert(shadowed > 0);
    ck_assert(size * 8.0 / n < 3.0);
    ts_atlas_free(a);
    free(file);
    free(maps);
    free(back);
    ts_grid_free(&g);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("atlas");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_round_trip);
    tcase_add_test(tc, test_bad_maps_and_files);
    tcase_add_test(tc, test_bad_step_tables);
    tcase_add_test(tc, test_jacksboro_day);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    return test_run_suite(suite());
}
