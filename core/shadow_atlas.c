/*
 * The far-shadow atlas (Chajdas et al. 2015): a day's binary far-shadow
 * maps as a dictionary of 8 x 8 tiles and LZMA-compressed index maps; see
 * shadow_atlas.h and docs/atlas-format.md. The maps come from
 * far_horizon.c. This file writes atlases; shadow_atlas_read.c reads them.
 */
#include <lzma.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shadow_atlas.h"
#include "shadow_atlas_internal.h"
#include "status_internal.h"

/* ================================================================ atlas */

/* Little-endian writing. */
static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void putf64(uint8_t *p, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put64(p, u);
}

/* Tile (tx, ty) of a plane as 64 bits: bit 8 r + c is cell (8 tx + c,
 * 8 ty + r); `want` selects the cells that are set (1 = shadow bits,
 * TS_ATLAS_NODATA = the nodata mask). Cells past the edge are 0. */
static uint64_t tile_bits(const uint8_t *plane, ptrdiff_t stride, int W, int H, int tx,
                          int ty, uint8_t want)
{
    uint64_t bits = 0;
    int x0 = tx * TS_ATLAS_TILE, y0 = ty * TS_ATLAS_TILE;
    int nx = W - x0 < TS_ATLAS_TILE ? W - x0 : TS_ATLAS_TILE;
    int ny = H - y0 < TS_ATLAS_TILE ? H - y0 : TS_ATLAS_TILE;
    for (int r = 0; r < ny; r++) {
        const uint8_t *row = plane + (ptrdiff_t)(y0 + r) * stride + x0;
        unsigned byte = 0;
        for (int c = 0; c < nx; c++)
            byte |= (unsigned)(row[c] == want) << c;
        bits |= (uint64_t)byte << (8 * r);
    }
    return bits;
}

struct ts_atlas_writer {
    int W, H, tx, ty;
    size_t tiles; /* per map */
    /* dictionary: hash of tile -> id, and the tiles by id */
    uint64_t *keys;
    uint32_t *vals;
    size_t cap, used;
    uint64_t *dict;
    size_t dict_cap;
    /* index maps of the added maps */
    uint32_t *index;
    size_t index_len, index_cap;
    /* nodata mask tiles (of map 0) */
    uint64_t *mask;
    int steps;
    ts_atlas_step *rec;
    size_t rec_cap;
};

static inline size_t hash64(uint64_t k, size_t cap)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    k *= 0xc4ceb9fe1a85ec53ULL;
    k ^= k >> 33;
    return (size_t)k & (cap - 1);
}

static int dict_grow(ts_atlas_writer *w)
{
    size_t cap = w->cap ? w->cap * 2 : 1024;
    uint64_t *keys = malloc(cap * sizeof *keys);
    uint32_t *vals = malloc(cap * sizeof *vals);
    if (!keys || !vals) {
        free(keys);
        free(vals);
        return -1;
    }
    for (size_t i = 0; i < cap; i++)
        vals[i] = UINT32_MAX;
    for (size_t i = 0; i < w->cap; i++) {
        if (w->vals[i] == UINT32_MAX)
            continue;
        size_t h = hash64(w->keys[i], cap);
        while (vals[h] != UINT32_MAX)
            h = (h + 1) & (cap - 1);
        keys[h] = w->keys[i];
        vals[h] = w->vals[i];
    }
    free(w->keys);
    free(w->vals);
    w->keys = keys;
    w->vals = vals;
    w->cap = cap;
    return 0;
}

/* Id of a tile, adding it to the dictionary if new; UINT32_MAX when out
 * of memory. */
static uint32_t dict_id(ts_atlas_writer *w, uint64_t tile)
{
    if (2 * (w->used + 1) > w->cap && dict_grow(w) != 0)
        return UINT32_MAX;
    size_t h = hash64(tile, w->cap);
    while (w->vals[h] != UINT32_MAX) {
        if (w->keys[h] == tile)
            return w->vals[h];
        h = (h + 1) & (w->cap - 1);
    }
    if (w->used == w->dict_cap) {
        size_t cap = w->dict_cap ? w->dict_cap * 2 : 1024;
        uint64_t *d = realloc(w->dict, cap * sizeof *d);
        if (!d)
            return UINT32_MAX;
        w->dict = d;
        w->dict_cap = cap;
    }
    if (w->used >= UINT32_MAX - 1)
        return UINT32_MAX;
    uint32_t id = (uint32_t)w->used++;
    w->dict[id] = tile;
    w->keys[h] = tile;
    w->vals[h] = id;
    return id;
}

ts_status ts_atlas_writer_new(int width, int height, ts_atlas_writer **out,
                              ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_writer_new: the output is NULL");
    *out = NULL;
    if (width < 1 || height < 1)
        return ts_fail(err, TS_ERR_ARG, "an atlas needs at least one cell, got %d x %d",
                       width, height);
    ts_atlas_writer *w = calloc(1, sizeof *w);
    if (!w)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the atlas writer");
    w->W = width;
    w->H = height;
    w->tx = (width + TS_ATLAS_TILE - 1) / TS_ATLAS_TILE;
    w->ty = (height + TS_ATLAS_TILE - 1) / TS_ATLAS_TILE;
    w->tiles = (size_t)w->tx * w->ty;
    /* the empty and the full tile come first */
    if (dict_id(w, 0) != 0 || dict_id(w, ~(uint64_t)0) != 1) {
        ts_atlas_writer_free(w);
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the tile dictionary");
    }
    *out = w;
    return ts_ok(err);
}

void ts_atlas_writer_free(ts_atlas_writer *w)
{
    if (!w)
        return;
    free(w->keys);
    free(w->vals);
    free(w->dict);
    free(w->index);
    free(w->mask);
    free(w->rec);
    free(w);
}

ts_status ts_atlas_writer_add(ts_atlas_writer *w, const uint8_t *plane, ptrdiff_t stride,
                              const ts_atlas_step *step, ts_error *err)
{
    if (!w || !plane || stride < w->W)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_writer_add: bad arguments");
    if (w->steps >= INT32_MAX / 2)
        return ts_fail(err, TS_ERR_ARG, "too many maps in one atlas");
    /* values first: 0, 1 or nodata only */
    for (int y = 0; y < w->H; y++) {
        const uint8_t *row = plane + (ptrdiff_t)y * stride;
        for (int x = 0; x < w->W; x++)
            if (row[x] > 1 && row[x] != TS_ATLAS_NODATA)
                return ts_fail(err, TS_ERR_ARG,
                               "map %d holds the value %d at column %d, row %d: an "
                               "atlas stores binary maps (0, 1, and %d for nodata)",
                               w->steps + 1, row[x], x, y, TS_ATLAS_NODATA);
    }
    if (!w->mask) {
        w->mask = malloc(w->tiles * sizeof *w->mask);
        if (!w->mask)
            return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the nodata mask");
        for (int ty = 0; ty < w->ty; ty++)
            for (int tx = 0; tx < w->tx; tx++)
                w->mask[(size_t)ty * w->tx + tx] =
                    tile_bits(plane, stride, w->W, w->H, tx, ty, TS_ATLAS_NODATA);
    } else {
        for (int ty = 0; ty < w->ty; ty++)
            for (int tx = 0; tx < w->tx; tx++)
                if (w->mask[(size_t)ty * w->tx + tx] !=
                    tile_bits(plane, stride, w->W, w->H, tx, ty, TS_ATLAS_NODATA))
                    return ts_fail(err, TS_ERR_ARG,
                                   "map %d has nodata cells that map 1 has not (or the "
                                   "other way round) near column %d, row %d: the maps of "
                                   "an atlas share one nodata mask",
                                   w->steps + 1, tx * TS_ATLAS_TILE, ty * TS_ATLAS_TILE);
    }
    if (w->index_len + w->tiles > w->index_cap) {
        size_t cap = w->index_cap ? w->index_cap * 2 : w->tiles * 8;
        while (cap < w->index_len + w->tiles)
            cap *= 2;
        uint32_t *p = realloc(w->index, cap * sizeof *p);
        if (!p)
            return ts_fail(err, TS_ERR_NOMEM, "cannot grow the index maps to %zu tiles", cap);
        w->index = p;
        w->index_cap = cap;
    }
    if ((size_t)w->steps >= w->rec_cap) {
        size_t cap = w->rec_cap ? w->rec_cap * 2 : 64;
        ts_atlas_step *p = realloc(w->rec, cap * sizeof *p);
        if (!p)
            return ts_fail(err, TS_ERR_NOMEM, "cannot grow the step table");
        w->rec = p;
        w->rec_cap = cap;
    }
    uint32_t *idx = w->index + w->index_len;
    for (int ty = 0; ty < w->ty; ty++)
        for (int tx = 0; tx < w->tx; tx++) {
            uint32_t id = dict_id(w, tile_bits(plane, stride, w->W, w->H, tx, ty, 1));
            if (id == UINT32_MAX)
                return ts_fail(err, TS_ERR_NOMEM, "cannot grow the tile dictionary");
            idx[(size_t)ty * w->tx + tx] = id;
        }
    w->index_len += w->tiles;
    if (step) {
        w->rec[w->steps] = *step;
    } else {
        w->rec[w->steps] = (ts_atlas_step){NAN, NAN, NAN, NAN, 0};
    }
    w->steps++;
    return ts_ok(err);
}

/* xz-compress `in` with LZMA2 tuned for `word`-byte little-endian words. */
static ts_status xz_compress(const uint8_t *in, size_t n, int word, uint8_t **out,
                             size_t *out_n, ts_error *err)
{
    lzma_options_lzma opt;
    if (lzma_lzma_preset(&opt, 6))
        return ts_fail(err, TS_ERR_INTERNAL, "liblzma has no preset 6");
    /* the dictionary need not be larger than the data */
    uint32_t dict = 4096;
    while (dict < n && dict < opt.dict_size)
        dict *= 2;
    opt.dict_size = dict;
    int lp = word >= 8 ? 3 : word >= 4 ? 2 : word >= 2 ? 1 : 0;
    opt.lp = (uint32_t)lp;
    opt.pb = (uint32_t)lp;
    opt.lc = lp ? 0 : 3;
    lzma_filter filters[2] = {{LZMA_FILTER_LZMA2, &opt}, {LZMA_VLI_UNKNOWN, NULL}};
    size_t cap = lzma_stream_buffer_bound(n);
    *out = malloc(cap ? cap : 1);
    if (!*out)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate %zu bytes for compression", cap);
    size_t pos = 0;
    lzma_ret r = lzma_stream_buffer_encode(filters, LZMA_CHECK_CRC64, NULL, in, n, *out,
                                           &pos, cap);
    if (r != LZMA_OK) {
        free(*out);
        *out = NULL;
        return ts_fail(err, r == LZMA_MEM_ERROR ? TS_ERR_NOMEM : TS_ERR_INTERNAL,
                       "LZMA compression failed (liblzma error %d)", (int)r);
    }
    *out_n = pos;
    return TS_OK;
}

ts_status ts_atlas_writer_finish(ts_atlas_writer *w, const ts_atlas_info *info,
                                 uint8_t **bytes, size_t *size, ts_error *err)
{
    if (!w || !bytes || !size)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_writer_finish: NULL argument");
    *bytes = NULL;
    *size = 0;
    if (w->steps < 1)
        return ts_fail(err, TS_ERR_ARG, "an atlas needs at least one map");
    ts_status checked = ts_atlas_check_steps(w->rec, w->steps, "cannot write the atlas", err);
    if (checked != TS_OK)
        return checked;
    int has_nodata = 0;
    for (size_t i = 0; i < w->tiles && !has_nodata; i++)
        has_nodata = w->mask[i] != 0;
    uint32_t *mask_idx = NULL;
    if (has_nodata) {
        mask_idx = malloc(w->tiles * sizeof *mask_idx);
        if (!mask_idx)
            return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the mask index");
        for (size_t i = 0; i < w->tiles; i++)
            if ((mask_idx[i] = dict_id(w, w->mask[i])) == UINT32_MAX) {
                free(mask_idx);
                return ts_fail(err, TS_ERR_NOMEM, "cannot grow the tile dictionary");
            }
    }
    const char *text = info && info->metadata ? info->metadata : "";
    size_t text_n = strlen(text);
    int ib = w->used <= 65536 ? 2 : 4;
    size_t planes = (size_t)w->steps + (has_nodata ? 1 : 0);
    size_t raw_index = planes * w->tiles * (size_t)ib;
    uint8_t *dict_raw = malloc(w->used * 8);
    uint8_t *idx_raw = malloc(raw_index);
    uint8_t *dict_z = NULL, *idx_z = NULL, *file = NULL;
    size_t dict_zn = 0, idx_zn = 0;
    ts_status st;
    if (!dict_raw || !idx_raw) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate %zu bytes of index maps", raw_index);
        goto done;
    }
    for (size_t i = 0; i < w->used; i++)
        put64(dict_raw + 8 * i, w->dict[i]);
    {
        uint8_t *p = idx_raw;
        for (size_t pl = 0; pl < planes; pl++) {
            const uint32_t *src = has_nodata ? (pl == 0 ? mask_idx
                                                        : w->index + (pl - 1) * w->tiles)
                                             : w->index + pl * w->tiles;
            for (size_t i = 0; i < w->tiles; i++, p += ib) {
                if (ib == 2) {
                    p[0] = (uint8_t)src[i];
                    p[1] = (uint8_t)(src[i] >> 8);
                } else {
                    put32(p, src[i]);
                }
            }
        }
    }
    if ((st = xz_compress(dict_raw, w->used * 8, 8, &dict_z, &dict_zn, err)) != TS_OK ||
        (st = xz_compress(idx_raw, raw_index, ib, &idx_z, &idx_zn, err)) != TS_OK)
        goto done;
    {
        size_t steps_off = TS_ATLAS_HEADER_SIZE;
        size_t text_off = steps_off + (size_t)w->steps * TS_ATLAS_STEP_SIZE;
        size_t dict_off = text_off + text_n;
        size_t idx_off = dict_off + dict_zn;
        size_t total = idx_off + idx_zn;
        file = calloc(total, 1);
        if (!file) {
            st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the %zu-byte atlas", total);
            goto done;
        }
        uint8_t *h = file;
        memcpy(h, TS_ATLAS_MAGIC, 8);
        put32(h + 8, TS_ATLAS_VERSION);
        put32(h + 12, TS_ATLAS_HEADER_SIZE);
        put32(h + 16, (uint32_t)w->W);
        put32(h + 20, (uint32_t)w->H);
        put32(h + 24, (uint32_t)w->steps);
        put32(h + 28, TS_ATLAS_TILE);
        uint32_t flags = (info && info->has_geotransform ? 1u : 0u) | (has_nodata ? 2u : 0u);
        put32(h + 32, flags);
        put32(h + 36, (uint32_t)ib);
        put32(h + 40, (uint32_t)w->used);
        put32(h + 44, info && info->threshold_cells > 0 ? (uint32_t)info->threshold_cells : 0);
        putf64(h + 48, info && isfinite(info->threshold_m) && info->threshold_m > 0
                           ? info->threshold_m
                           : NAN); /* 0 (a zeroed info) = unknown */
        for (int i = 0; i < 6; i++)
            putf64(h + 56 + 8 * i, info && info->has_geotransform ? info->geotransform[i]
                                                                  : (i == 1 || i == 5 ? 1.0 : 0.0));
        put64(h + 104, steps_off);
        put64(h + 112, text_off);
        put64(h + 120, text_n);
        put64(h + 128, dict_off);
        put64(h + 136, dict_zn);
        put64(h + 144, idx_off);
        put64(h + 152, idx_zn);
        put32(h + 160, lzma_crc32(h, 160, 0));
        for (int s = 0; s < w->steps; s++) {
            uint8_t *r = file + steps_off + (size_t)s * TS_ATLAS_STEP_SIZE;
            putf64(r, w->rec[s].unix_time);
            putf64(r + 8, w->rec[s].azimuth);
            putf64(r + 16, w->rec[s].grid_azimuth);
            putf64(r + 24, w->rec[s].elevation);
            put32(r + 32, (uint32_t)w->rec[s].utc_offset_minutes);
            put32(r + 36, 0);
        }
        memcpy(file + text_off, text, text_n);
        /* version 2: the step table and the text under their own CRC */
        put32(h + 164, lzma_crc32(file + text_off, text_n,
                                  lzma_crc32(file + steps_off,
                                             (size_t)w->steps * TS_ATLAS_STEP_SIZE, 0)));
        memcpy(file + dict_off, dict_z, dict_zn);
        memcpy(file + idx_off, idx_z, idx_zn);
        *bytes = file;
        *size = total;
        file = NULL;
    }
    st = ts_ok(err);
done:
    free(mask_idx);
    free(dict_raw);
    free(idx_raw);
    free(dict_z);
    free(idx_z);
    free(file);
    return st;
}
