/* Environment-map files (core/env_map_exr.c): every variant OpenEXRCore
 * writes (pixel types, channel sets, compressions, scanline and tiled,
 * multi-part, from memory) reads back equal to the pixels written; every
 * bad input gives an error sentence naming the file. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "terrashade_env.h"
#include "test_env.h"
#include "test_exr_write.h"
#include "test_run.h"

enum { W = 64, H = 32 }; /* a 2:1 lat-long map */

static const char *const RGB[] = {"R", "G", "B"};

static unsigned char *read_all(const char *path, size_t *n);

/* Texel by texel: same geometry, radiance within tol (relative). */
static void expect_same(const ts_env *got, const ts_env *want, double tol, const char *what)
{
    ck_assert_msg(got->count == want->count, "%s: %zu texels, want %zu", what, got->count,
                  want->count);
    double worst = 0.0;
    for (size_t i = 0; i < got->count; i++) {
        const ts_env_texel *a = &got->texels[i], *b = &want->texels[i];
        ck_assert_msg(memcmp(a->dir, b->dir, sizeof a->dir) == 0 &&
                      a->solid_angle == b->solid_angle, "%s: texel %zu moved", what, i);
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(a->rgb[c] - b->rgb[c]) / fmax(fabs(b->rgb[c]), 1e-3));
    }
    printf("%-34s %zu texels, largest relative difference %.2e\n", what, got->count, worst);
    ck_assert_msg(worst <= tol, "%s: radiance differs by %g", what, worst);
}

/* Interleave rgb (3 floats a pixel) into the spec's channels: R, G, B and
 * Y take the grey/colour values, any other channel (A, Z) noise. */
static float *interleave(const float *rgb, size_t n, const texr_spec *s)
{
    float *out = malloc(n * (size_t)s->nchannels * sizeof *out);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < s->nchannels; c++) {
            const char *name = s->channels[c];
            int slot = !strcmp(name, "R") || !strcmp(name, "Y") ? 0
                       : !strcmp(name, "G")                     ? 1
                       : !strcmp(name, "B")                     ? 2
                                                                : -1;
            out[i * (size_t)s->nchannels + (size_t)c] =
                slot >= 0 ? rgb[3 * i + (size_t)slot] : (float)((i * 7919) % 13);
        }
    return out;
}

/* Write rgb in the spec's form and read it back through the file and
 * through memory; both must equal want. */
static void round_trip(const texr_spec *s, const float *rgb, const ts_env *want, double tol,
                       const char *what)
{
    const char *path = tenv_tmp("variant.exr");
    float *px = interleave(rgb, (size_t)s->width * s->height, s);
    ck_assert_msg(texr_write(path, s, px) == 0, "%s: cannot write", what);
    free(px);
    ts_env got;
    ts_error err;
    ck_assert_msg(ts_env_load_exr_file(path, 0.0, 0, &got, &err) == TS_OK, "%s: %s", what,
                  err.message);
    expect_same(&got, want, tol, what);
    ts_env_free(&got);

    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    static unsigned char buf[1 << 20];
    size_t size = fread(buf, 1, sizeof buf, f);
    fclose(f);
    ck_assert_msg(ts_env_load_exr_memory(buf, size, what, 0.0, 0, &got, &err) == TS_OK, "%s: %s",
                  what, err.message);
    expect_same(&got, want, tol, "  the same from memory");
    ts_env_free(&got);
}

START_TEST(test_variants_latlong)
{
    float *rgb = tenv_random_image(W, H, 5); /* multiples of 1/64 below 10: exact in half */
    ts_env want;
    ts_error err;
    ck_assert_int_eq(ts_env_from_latlong(rgb, W, H, 0.0, &want, &err), TS_OK);
    static const char *const RGBA[] = {"A", "B", "G", "R"}, *const RGBZ[] = {"Z", "R", "G", "B"};
    static const struct {
        const char *what;
        exr_pixel_type_t type;
        exr_compression_t comp;
        int tile, rgba, extra_part;
    } v[] = {
        {"half, no compression", EXR_PIXEL_HALF, EXR_COMPRESSION_NONE, 0, 0, 0},
        {"float, ZIP", EXR_PIXEL_FLOAT, EXR_COMPRESSION_ZIP, 0, 0, 0},
        {"float, ZIPS", EXR_PIXEL_FLOAT, EXR_COMPRESSION_ZIPS, 0, 0, 0},
        {"half, RLE", EXR_PIXEL_HALF, EXR_COMPRESSION_RLE, 0, 0, 0},
        {"half, PIZ", EXR_PIXEL_HALF, EXR_COMPRESSION_PIZ, 0, 0, 0},
        {"half, PXR24", EXR_PIXEL_HALF, EXR_COMPRESSION_PXR24, 0, 0, 0},
        {"half, tiled 16, ZIP", EXR_PIXEL_HALF, EXR_COMPRESSION_ZIP, 16, 0, 0},
        {"float, tiled 7 (partial), PIZ", EXR_PIXEL_FLOAT, EXR_COMPRESSION_PIZ, 7, 0, 0},
        {"half RGBA, ZIP", EXR_PIXEL_HALF, EXR_COMPRESSION_ZIP, 0, 1, 0},
        {"float RGB + Z, tiled 16, RLE", EXR_PIXEL_FLOAT, EXR_COMPRESSION_RLE, 16, 2, 0},
        {"half, two parts (reads the first)", EXR_PIXEL_HALF, EXR_COMPRESSION_ZIP, 0, 0, 1},
        {"float, two parts, tiled 8", EXR_PIXEL_FLOAT, EXR_COMPRESSION_PIZ, 8, 0, 1},
    };
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) {
        texr_spec s = {.width = W, .height = H, .channels = RGB, .nchannels = 3, .type = v[k].type,
                       .compression = v[k].comp, .tile_size = v[k].tile, .envmap = -1,
                       .extra_part = v[k].extra_part};
        if (v[k].rgba)
            s.channels = v[k].rgba == 1 ? RGBA : RGBZ, s.nchannels = 4;
        round_trip(&s, rgb, &want, 0, v[k].what);
    }
    /* a data window away from (0, 0): positions count from its corner */
    texr_spec moved = {.width = W, .height = H, .channels = RGB, .nchannels = 3,
                       .type = EXR_PIXEL_HALF, .compression = EXR_COMPRESSION_ZIP, .envmap = -1,
                       .origin_x = -5, .origin_y = 100};
    round_trip(&moved, rgb, &want, 0, "data window at (-5, 100)");
    moved.tile_size = 16;
    round_trip(&moved, rgb, &want, 0, "data window at (-5, 100), tiled");
    ts_env_free(&want);
    free(rgb);
}
END_TEST

/* The lossy compressions, on a smooth map: 24-bit floats (PXR24 on float
 * channels) and B44 / B44A (4 x 4 blocks of half). */
START_TEST(test_variants_lossy)
{
    float *rgb = tenv_constant((size_t)W * H, 0.0f);
    for (int j = 0; j < H; j++)
        for (int i = 0; i < W; i++)
            for (int c = 0; c < 3; c++)
                rgb[((size_t)j * W + i) * 3 + c] =
                    (float)(2.0 + c + sin(2 * M_PI * i / W) * cos(M_PI * j / H));
    ts_env want;
    ts_error err;
    ck_assert_int_eq(ts_env_from_latlong(rgb, W, H, 0.0, &want, &err), TS_OK);
    texr_spec s = {.width = W, .height = H, .channels = RGB, .nchannels = 3,
                   .type = EXR_PIXEL_FLOAT, .compression = EXR_COMPRESSION_PXR24, .envmap = -1};
    round_trip(&s, rgb, &want, 2e-5, "float, PXR24 (24-bit floats)");
    s.type = EXR_PIXEL_HALF, s.compression = EXR_COMPRESSION_B44;
    round_trip(&s, rgb, &want, 5e-3, "half, B44");
    s.compression = EXR_COMPRESSION_B44A, s.tile_size = 16;
    round_trip(&s, rgb, &want, 5e-3, "half, B44A, tiled 16");
    ts_env_free(&want);
    free(rgb);
}
END_TEST

/* Integer channels and luminance-only maps. */
START_TEST(test_variants_uint_and_grey)
{
    float *rgb = tenv_random_image(W, H, 9), *grey = tenv_constant((size_t)W * H, 0.0f);
    for (size_t i = 0; i < (size_t)W * H * 3; i++)
        rgb[i] = floorf(rgb[i] * 100.0f); /* integers for the uint file */
    for (size_t i = 0; i < (size_t)W * H; i++)
        grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = rgb[3 * i];
    ts_env want, want_grey;
    ts_error err;
    ck_assert_int_eq(ts_env_from_latlong(rgb, W, H, 0.0, &want, &err), TS_OK);
    ck_assert_int_eq(ts_env_from_latlong(grey, W, H, 0.0, &want_grey, &err), TS_OK);
    texr_spec s = {.width = W, .height = H, .channels = RGB, .nchannels = 3,
                   .type = EXR_PIXEL_UINT, .compression = EXR_COMPRESSION_ZIP, .envmap = -1};
    round_trip(&s, rgb, &want, 0, "uint, ZIP");
    static const char *const Y[] = {"Y"}, *const YA[] = {"A", "Y"};
    texr_spec y = {.width = W, .height = H, .channels = Y, .nchannels = 1, .type = EXR_PIXEL_HALF,
                   .compression = EXR_COMPRESSION_PIZ, .envmap = -1};
    round_trip(&y, rgb, &want_grey, 0, "Y only, half, PIZ");
    texr_spec ya = {.width = W, .height = H, .channels = YA, .nchannels = 2,
                    .type = EXR_PIXEL_FLOAT, .compression = EXR_COMPRESSION_NONE, .tile_size = 16,
                    .envmap = -1};
    round_trip(&ya, rgb, &want_grey, 0, "Y + A, float, tiled");
    ts_env_free(&want);
    ts_env_free(&want_grey);
    free(rgb);
    free(grey);
}
END_TEST

/* Cube maps: told by the attribute and by the 1:6 aspect alone. */
START_TEST(test_variants_cube)
{
    enum { F = 16 };
    float *rgb = tenv_random_image(F, 6 * F, 13);
    ts_env want;
    ts_error err;
    ck_assert_int_eq(ts_env_from_cube(rgb, F, 0.0, &want, &err), TS_OK);
    texr_spec s = {.width = F, .height = 6 * F, .channels = RGB, .nchannels = 3,
                   .type = EXR_PIXEL_HALF, .compression = EXR_COMPRESSION_ZIP,
                   .envmap = EXR_ENVMAP_CUBE};
    round_trip(&s, rgb, &want, 0, "cube, envmap attribute");
    s.envmap = -1;
    s.tile_size = 16;
    round_trip(&s, rgb, &want, 0, "cube by its 1:6 aspect, tiled");
    ts_env_free(&want);
    free(rgb);
}
END_TEST

/* The real DWAB map (decoded by OpenEXR's C++ library where OpenEXRCore
 * 3.1 cannot) reads the same from memory as from its file. */
START_TEST(test_dwa_from_memory)
{
    size_t n;
    unsigned char *b = read_all(TS_TEST_DATA "/envmaps/sunset.exr", &n);
    ts_env file, mem;
    ts_error err;
    ck_assert_msg(ts_env_load_exr_file(TS_TEST_DATA "/envmaps/sunset.exr", 30.0, 5000, &file,
                                       &err) == TS_OK, "%s", err.message);
    ck_assert_msg(ts_env_load_exr_memory(b, n, "sunset.exr", 30.0, 5000, &mem, &err) == TS_OK,
                  "%s", err.message);
    expect_same(&mem, &file, 0, "DWAB sunset.exr from memory");
    ts_env_free(&file);
    ts_env_free(&mem);
    free(b);
}
END_TEST

/* ---------------------------------------------------------------- bad input */

/* Expect an error whose sentence names the file. */
static void expect_error(ts_status st, const ts_error *err, const char *name, const char *word)
{
    printf("%-14s -> %s\n", word ? word : "", err->message);
    ck_assert_msg(st != TS_OK && err->code == st, "no error for %s", name);
    ck_assert_msg(strstr(err->message, name) != NULL, "'%s' does not name %s", err->message, name);
    if (word)
        ck_assert_msg(strstr(err->message, word) != NULL, "'%s' lacks '%s'", err->message, word);
}

static void expect_file_error(const char *path, const char *word)
{
    ts_env e;
    ts_error err;
    ts_status st = ts_env_load_exr_file(path, 0.0, 0, &e, &err);
    expect_error(st, &err, path, word);
    ck_assert_uint_eq(e.count, 0);
    ck_assert_ptr_null(e.texels);
}

static void write_bytes(const char *path, const void *bytes, size_t n)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(bytes, 1, n, f), n);
    fclose(f);
}

static unsigned char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*n);
    ck_assert_uint_eq(fread(b, 1, *n, f), *n);
    fclose(f);
    return b;
}

/* A small valid map of the given size, pixel values v. */
static const char *small_map(const char *name, int w, int h, int envmap,
                             const char *const *channels, int nch, float v)
{
    const char *path = tenv_tmp(name);
    float *px = malloc((size_t)w * h * (size_t)nch * sizeof *px);
    for (size_t i = 0; i < (size_t)w * h * (size_t)nch; i++)
        px[i] = v;
    texr_spec s = {.width = w, .height = h, .channels = channels, .nchannels = nch,
                   .type = EXR_PIXEL_FLOAT, .compression = EXR_COMPRESSION_ZIP, .envmap = envmap};
    ck_assert_int_eq(texr_write(path, &s, px), 0);
    free(px);
    return path;
}

/* Maps coarser than a degree a pixel keep their light: with max_texels the
 * pixels are cut into parts (a 4 x 2 map of radiance 1 lit a level plane
 * as 2 from its one zenith texel, a 1 x 6 cube as 0.67); without, one
 * texel per pixel as documented. */
START_TEST(test_coarse_maps_cut)
{
    static const struct {
        int w, h, envmap;
        size_t pixels;
    } maps[] = {{4, 2, EXR_ENVMAP_LATLONG, 8}, {2, 2, EXR_ENVMAP_LATLONG, 4},
                {6, 3, EXR_ENVMAP_LATLONG, 18}, {1, 6, EXR_ENVMAP_CUBE, 6},
                {2, 12, EXR_ENVMAP_CUBE, 24}, {3, 18, EXR_ENVMAP_CUBE, 54}};
    const double up[3] = {0, 0, 1}, tilt[3] = {0, sin(0.7), cos(0.7)};
    for (size_t k = 0; k < sizeof maps / sizeof maps[0]; k++) {
        const char *p = small_map("coarse.exr", maps[k].w, maps[k].h, maps[k].envmap, RGB, 3,
                                  1.0f);
        ts_env e;
        ts_error err;
        ck_assert_int_eq(ts_env_load_exr_file(p, 0.0, 0, &e, &err), TS_OK);
        ck_assert_uint_eq(e.count, maps[k].pixels);
        ts_env_free(&e);
        ck_assert_int_eq(ts_env_load_exr_file(p, 0.0, (size_t)1 << 21, &e, &err), TS_OK);
        double flat[3], slope[3];
        tenv_irradiance(&e, up, flat);
        tenv_irradiance(&e, tilt, slope);
        printf("%d x %d: %zu texels, level plane %.6f pi, slope %.6f pi\n", maps[k].w,
               maps[k].h, e.count, flat[0] / M_PI, slope[0] / M_PI);
        ck_assert_double_eq_tol(tenv_total_solid_angle(&e) / (4 * M_PI), 1.0, 1e-5);
        ck_assert_double_eq_tol(flat[0] / M_PI, 1.0, 1e-3);
        ck_assert_double_eq_tol(slope[0] / M_PI, 1.0, 1e-3); /* the whole sphere lit */
        ck_assert_uint_le(e.count, (size_t)1 << 21);
        ts_env_free(&e);
    }
}
END_TEST

/* ts_env_exr_info: the layout, channels and size from the header alone,
 * and the same refusals as the reader for what the header shows. */
START_TEST(test_header_info)
{
    static const struct {
        const char *file;
        int cube, width, height;
    } maps[] = {{"sunset.exr", 0, 1024, 512}, {"sunset_cube128.exr", 1, 128, 768}};
    ts_error err;
    ts_env_map_info info;
    for (size_t k = 0; k < sizeof maps / sizeof maps[0]; k++) {
        char path[512];
        size_t n;
        snprintf(path, sizeof path, "%s/envmaps/%s", TS_TEST_DATA, maps[k].file);
        unsigned char *b = read_all(path, &n);
        ck_assert_msg(ts_env_exr_info(b, n, maps[k].file, &info, &err) == TS_OK, "%s",
                      err.message);
        printf("%-20s cube %d grey %d, %d x %d\n", maps[k].file, info.cube, info.grey,
               info.width, info.height);
        ck_assert(info.cube == maps[k].cube && info.grey == 0);
        ck_assert(info.width == maps[k].width && info.height == maps[k].height);
        free(b);
    }
    static const char words[] = "not an OpenEXR file";
    expect_error(ts_env_exr_info(words, sizeof words, "words.exr", &info, &err), &err,
                 "words.exr", "not a readable OpenEXR file");
    ck_assert_int_eq(ts_env_exr_info(words, sizeof words, "x", NULL, &err), TS_ERR_ARG);
}
END_TEST

START_TEST(test_bad_files)
{
    expect_file_error("/nonexistent/envmaps/missing.exr", "No such file");

    const char *text = tenv_tmp("notes.exr");
    static const char words[] = "This is a text file, not an image.\n";
    write_bytes(text, words, sizeof words - 1);
    expect_file_error(text, "not a readable OpenEXR file");
    const char *empty = tenv_tmp("empty.exr");
    write_bytes(empty, "", 0);
    expect_file_error(empty, "not a readable OpenEXR file");

    /* truncated: the real DWA map and a ZIP map of ours, cut */
    size_t n;
    unsigned char *b = read_all(TS_TEST_DATA "/envmaps/sunset.exr", &n);
    const char *cut = tenv_tmp("sunset_cut.exr");
    write_bytes(cut, b, n * 2 / 5);
    expect_file_error(cut, NULL);
    write_bytes(cut, b, 300); /* in the header */
    expect_file_error(cut, NULL);
    free(b);
    const char *zip = small_map("zip.exr", 256, 128, -1, RGB, 3, 1.5f);
    b = read_all(zip, &n);
    write_bytes(zip, b, n - 40);
    expect_file_error(zip, NULL);
    ts_env e;
    ts_error err;
    expect_error(ts_env_load_exr_memory(b, n / 2, "zip in memory", 0.0, 0, &e, &err), &err,
                 "zip in memory", NULL);
    free(b);

    static const char *const AZ[] = {"A", "Z"}, *const RG[] = {"R", "G"};
    expect_file_error(small_map("az.exr", 8, 4, -1, AZ, 2, 1.0f), "no usable channel");
    expect_file_error(small_map("rg.exr", 8, 4, -1, RG, 2, 1.0f), "no usable channel");
    expect_file_error(small_map("cube_aspect.exr", 16, 64, EXR_ENVMAP_CUBE, RGB, 3, 1.0f),
                      "marked as a cube map");
    expect_file_error(small_map("aspect.exr", 30, 20, -1, RGB, 3, 1.0f), "neither 2:1");
    expect_file_error(small_map("thin.exr", 1, 4, EXR_ENVMAP_LATLONG, RGB, 3, 1.0f),
                      "at least 2 x 2");
}
END_TEST

/* Rewrite the dataWindow attribute of an EXR file in place. */
static void set_data_window(const char *path, int32_t x1, int32_t y1)
{
    size_t n;
    unsigned char *b = read_all(path, &n);
    static const char key[] = "dataWindow\0box2i"; /* then the size, 16, and 4 int32 */
    unsigned char *p = memmem(b, n, key, sizeof key);
    ck_assert_ptr_nonnull(p);
    int32_t box[4] = {0, 0, x1, y1}; /* little-endian, as the file (x86) */
    memcpy(p + sizeof key + 4, box, sizeof box);
    write_bytes(path, b, n);
    free(b);
}

START_TEST(test_bad_sizes)
{
    const char *p = small_map("zero.exr", 8, 4, -1, RGB, 3, 1.0f);
    set_data_window(p, -1, -1);
    expect_file_error(p, NULL);
    p = small_map("huge.exr", 8, 4, -1, RGB, 3, 1.0f);
    set_data_window(p, 16383, 8191); /* 2^27 pixels */
    expect_file_error(p, "limit");
    p = small_map("absurd.exr", 8, 4, -1, RGB, 3, 1.0f);
    set_data_window(p, 2000000000, 1000000000);
    expect_file_error(p, NULL);
    /* the in-memory entry points refuse the same */
    float px[3 * 4] = {0};
    ts_env e;
    ts_error err;
    expect_error(ts_env_from_latlong(px, 1, 4, 0.0, &e, &err), &err, "lat-long image", NULL);
    expect_error(ts_env_from_cube(px, 0, 0.0, &e, &err), &err, "cube-face image", NULL);
    expect_error(ts_env_from_latlong(NULL, 2, 2, 0.0, &e, &err), &err, "lat-long image", NULL);
    ck_assert_int_eq(ts_env_from_latlong(px, 2, 2, NAN, &e, &err), TS_ERR_ARG);
    ck_assert_int_eq(ts_env_from_latlong(px, 2, 2, 0.0, NULL, &err), TS_ERR_ARG);
    ck_assert_int_eq(ts_env_load_exr_file(NULL, 0.0, 0, &e, &err), TS_ERR_ARG);
    ck_assert_int_eq(ts_env_load_exr_memory(NULL, 10, NULL, 0.0, 0, &e, &err), TS_ERR_ARG);
    ck_assert_int_eq(ts_env_load_exr_file(p, 0.0, 0, &e, NULL), TS_ERR_ARG);
}
END_TEST

/* NaN and infinity are refused, negative values clamped to 0. */
START_TEST(test_bad_pixels)
{
    static const struct {
        float v;
        const char *word;
    } bad[] = {{NAN, "NaN"}, {INFINITY, "infinite"}, {-INFINITY, "infinite"}};
    for (size_t k = 0; k < 3; k++) {
        float *rgb = tenv_random_image(W, H, 21);
        rgb[(10 * W + 20) * 3 + 1] = bad[k].v;
        const char *path = tenv_tmp("nan.exr");
        texr_spec s = {.width = W, .height = H, .channels = RGB, .nchannels = 3,
                       .type = EXR_PIXEL_FLOAT, .compression = EXR_COMPRESSION_PIZ, .envmap = -1};
        ck_assert_int_eq(texr_write(path, &s, rgb), 0);
        expect_file_error(path, bad[k].word);
        free(rgb);
    }
    float *rgb = tenv_random_image(W, H, 22);
    rgb[(10 * W + 20) * 3 + 2] = -5.0f;
    const char *path = tenv_tmp("negative.exr");
    texr_spec s = {.width = W, .height = H, .channels = RGB, .nchannels = 3,
                   .type = EXR_PIXEL_HALF, .compression = EXR_COMPRESSION_ZIP, .envmap = -1};
    ck_assert_int_eq(texr_write(path, &s, rgb), 0);
    ts_env e;
    ts_error err;
    ck_assert_int_eq(ts_env_load_exr_file(path, 0.0, 0, &e, &err), TS_OK);
    ck_assert(e.texels[10 * W + 20].rgb[2] == 0.0f);
    ck_assert(e.texels[10 * W + 20].rgb[1] == rgb[(10 * W + 20) * 3 + 1]);
    ts_env_free(&e);
    free(rgb);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("env_map_files");
    TCase *ok = tcase_create("variants");
    tcase_add_test(ok, test_variants_latlong);
    tcase_add_test(ok, test_variants_lossy);
    tcase_add_test(ok, test_variants_uint_and_grey);
    tcase_add_test(ok, test_variants_cube);
    tcase_add_test(ok, test_dwa_from_memory);
    tcase_add_test(ok, test_header_info);
    tcase_add_test(ok, test_coarse_maps_cut);
    suite_add_tcase(s, ok);
    TCase *bad = tcase_create("bad input");
    tcase_add_test(bad, test_bad_files);
    tcase_add_test(bad, test_bad_sizes);
    tcase_add_test(bad, test_bad_pixels);
    suite_add_tcase(s, bad);
    tenv_tmp_begin();
    int rc = test_run_suite(s);
    tenv_tmp_end();
    return rc;
}
