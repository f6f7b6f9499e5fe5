/*
 * The far-shadow atlas (Chajdas et al. 2015): a day's binary far-shadow
 * maps as a dictionary of 8 x 8 tiles and LZMA-compressed index maps; see
 * shadow_atlas.h and docs/atlas-format.md. The maps come from
 * far_horizon.c.
 */
#include <lzma.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shadow_atlas.h"
#include "status_internal.h"

/* ================================================================ atlas */

static const uint8_t MAGIC[8] = {0x89, 'T', 'S', 'A', 'T', 'L', 'A', 'S'};

/* Little-endian writing and reading. */
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

static uint32_t get32(const uint8_t *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)p[i] << (8 * i);
    return v;
}

static uint64_t get64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static double getf64(const uint8_t *p)
{
    uint64_t u = get64(p);
    double v;
    memcpy(&v, &u, 8);
    return v;
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

static ts_status xz_decompress(const uint8_t *in, size_t n, uint8_t *out, size_t expect,
                               const char *what, ts_error *err)
{
    uint64_t memlimit = (uint64_t)1 << 30; /* a damaged header cannot ask for more */
    size_t in_pos = 0, out_pos = 0;
    lzma_ret r = lzma_stream_buffer_decode(&memlimit, 0, NULL, in, &in_pos, n, out,
                                           &out_pos, expect);
    if (r == LZMA_MEM_ERROR)
        return ts_fail(err, TS_ERR_NOMEM, "out of memory decompressing the atlas's %s",
                       what);
    if (r != LZMA_OK || in_pos != n || out_pos != expect)
        return ts_fail(err, TS_ERR_ARG,
                       "the atlas is damaged: its %s (LZMA) do not decode to the "
                       "%zu bytes the header announces (liblzma %d, %zu of %zu bytes "
                       "read, %zu written)", what, expect, (int)r, in_pos, n, out_pos);
    return TS_OK;
}

int ts_atlas_identify(const uint8_t *head, size_t n)
{
    return head && n >= sizeof MAGIC && memcmp(head, MAGIC, sizeof MAGIC) == 0;
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
        memcpy(h, MAGIC, 8);
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

/* ------------------------------------------------------------- reading */

struct ts_atlas {
    ts_atlas_info info;
    char *text;
    ts_atlas_step *steps;
    uint64_t *dict;
    uint8_t *index; /* planes x tiles little-endian words */
    int tx, ty;
    size_t tiles;
};

void ts_atlas_free(ts_atlas *a)
{
    if (!a)
        return;
    free(a->text);
    free(a->steps);
    free(a->dict);
    free(a->index);
    free(a);
}

static inline uint32_t index_at(const ts_atlas *a, size_t plane, size_t tile)
{
    const uint8_t *p = a->index + (plane * a->tiles + tile) * (size_t)a->info.index_bytes;
    return a->info.index_bytes == 2 ? (uint32_t)p[0] | (uint32_t)p[1] << 8 : get32(p);
}

#define BAD(...) do { st = ts_fail(err, TS_ERR_ARG, __VA_ARGS__); goto fail; } while (0)

ts_status ts_atlas_open(const uint8_t *b, size_t n, ts_atlas **out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_open: the output is NULL");
    *out = NULL;
    if (!b || !ts_atlas_identify(b, n))
        return ts_fail(err, TS_ERR_ARG, "not a terrashade atlas (the file does not start "
                       "with the atlas magic \\x89TSATLAS)");
    ts_status st;
    ts_atlas *a = calloc(1, sizeof *a);
    if (!a)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the atlas");
    if (n < 16)
        BAD("the atlas is truncated: %zu bytes, the header alone has %d", n,
            TS_ATLAS_HEADER_SIZE);
    uint32_t version = get32(b + 8), hsize = get32(b + 12);
    if (version == 1)
        BAD("the atlas has format version 1, whose metadata and step table carry no "
            "checksum and cannot be validated; this terrashade reads version %d: "
            "recreate the atlas (gdal_translate -of TERRASHADE from PRODUCT=farshadow)",
            TS_ATLAS_VERSION);
    if (version != TS_ATLAS_VERSION)
        BAD("the atlas has format version %u; this terrashade reads version %d",
            version, TS_ATLAS_VERSION);
    if (hsize < TS_ATLAS_HEADER_SIZE || n < hsize)
        BAD("the atlas is truncated or its header is damaged (header of %u bytes in a "
            "%zu-byte file)", hsize, n);
    if (lzma_crc32(b, 160, 0) != get32(b + 160))
        BAD("the atlas's header is damaged (CRC32 mismatch)");
    uint32_t W = get32(b + 16), H = get32(b + 20), steps = get32(b + 24);
    uint32_t tile = get32(b + 28), flags = get32(b + 32), ib = get32(b + 36);
    uint32_t ntiles = get32(b + 40);
    if (W < 1 || H < 1 || W > INT32_MAX / 2 || H > INT32_MAX / 2 || steps < 1 ||
        steps > INT32_MAX / 2 || tile != TS_ATLAS_TILE || (ib != 2 && ib != 4) ||
        ntiles < 1 || (ib == 2 && ntiles > 65536))
        BAD("the atlas's header is inconsistent (%u x %u cells, %u maps, tile %u, "
            "%u-byte indices, %u tiles)", W, H, steps, tile, ib, ntiles);
    uint64_t so = get64(b + 104), to = get64(b + 112), tn = get64(b + 120),
             dof = get64(b + 128), dn = get64(b + 136), io = get64(b + 144),
             in = get64(b + 152);
    uint64_t sn = (uint64_t)steps * TS_ATLAS_STEP_SIZE;
    uint64_t secs[4][2] = {{so, sn}, {to, tn}, {dof, dn}, {io, in}};
    for (int i = 0; i < 4; i++)
        if (secs[i][0] < hsize || secs[i][0] > n || secs[i][1] > n - secs[i][0])
            BAD("the atlas is truncated: a section at byte %llu of %llu bytes lies "
                "beyond the end of the %zu-byte file",
                (unsigned long long)secs[i][0], (unsigned long long)secs[i][1], n);
    if (lzma_crc32(b + to, (size_t)tn, lzma_crc32(b + so, (size_t)sn, 0)) != get32(b + 164))
        BAD("the atlas's step table or metadata text is damaged (CRC32 mismatch)");
    a->info.width = (int)W;
    a->info.height = (int)H;
    a->info.steps = (int)steps;
    a->info.threshold_cells = (int)(get32(b + 44) > INT32_MAX ? 0 : get32(b + 44));
    a->info.threshold_m = getf64(b + 48);
    a->info.has_geotransform = flags & 1;
    a->info.has_nodata = (flags & 2) != 0;
    for (int i = 0; i < 6; i++)
        if (!isfinite(a->info.geotransform[i] = getf64(b + 56 + 8 * i)))
            BAD("the atlas's geotransform is invalid (%g in place %d)",
                a->info.geotransform[i], i);
    if (!isnan(a->info.threshold_m) && !(isfinite(a->info.threshold_m) && a->info.threshold_m > 0))
        BAD("the atlas's far threshold (%g m) is not a distance", a->info.threshold_m);
    a->info.dictionary_tiles = ntiles;
    a->info.index_bytes = (int)ib;
    a->info.dictionary_bytes = dn;
    a->info.index_bytes_total = in;
    a->info.file_bytes = n;
    a->tx = (int)((W + TS_ATLAS_TILE - 1) / TS_ATLAS_TILE);
    a->ty = (int)((H + TS_ATLAS_TILE - 1) / TS_ATLAS_TILE);
    a->tiles = (size_t)a->tx * a->ty;
    size_t planes = steps + (a->info.has_nodata ? 1 : 0);
    if (a->tiles > SIZE_MAX / 4 / planes)
        BAD("the atlas is too large for this machine");
    size_t idx_raw = planes * a->tiles * ib;
    a->text = malloc(tn + 1);
    a->steps = malloc(steps * sizeof *a->steps);
    a->dict = malloc((size_t)ntiles * sizeof *a->dict);
    a->index = malloc(idx_raw);
    uint8_t *dict_raw = malloc((size_t)ntiles * 8);
    if (!a->text || !a->steps || !a->dict || !a->index || !dict_raw) {
        free(dict_raw);
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate %zu bytes for the atlas's index "
                     "maps", idx_raw);
        goto fail;
    }
    memcpy(a->text, b + to, tn);
    a->text[tn] = '\0';
    if (memchr(a->text, '\0', tn)) {
        free(dict_raw);
        BAD("the atlas's metadata text is damaged (it holds a NUL byte)");
    }
    a->info.metadata = a->text;
    for (uint32_t s = 0; s < steps; s++) {
        const uint8_t *r = b + so + (size_t)s * TS_ATLAS_STEP_SIZE;
        a->steps[s].unix_time = getf64(r);
        a->steps[s].azimuth = getf64(r + 8);
        a->steps[s].grid_azimuth = getf64(r + 16);
        a->steps[s].elevation = getf64(r + 24);
        a->steps[s].utc_offset_minutes = (int32_t)get32(r + 32);
    }
    if ((st = ts_atlas_check_steps(a->steps, (int)steps, "the atlas's step table is invalid",
                                   err)) != TS_OK) {
        free(dict_raw);
        goto fail;
    }
    st = xz_decompress(b + dof, dn, dict_raw, (size_t)ntiles * 8, "tile dictionary words", err);
    if (st == TS_OK)
        for (uint32_t i = 0; i < ntiles; i++)
            a->dict[i] = get64(dict_raw + 8 * (size_t)i);
    free(dict_raw);
    if (st != TS_OK)
        goto fail;
    if ((st = xz_decompress(b + io, in, a->index, idx_raw, "index maps", err)) != TS_OK)
        goto fail;
    for (size_t p = 0; p < planes; p++)
        for (size_t t = 0; t < a->tiles; t++)
            if (index_at(a, p, t) >= ntiles)
                BAD("the atlas's index maps are damaged: tile %zu of map %zu points past "
                    "the %u-tile dictionary", t, p, ntiles);
    *out = a;
    return ts_ok(err);
fail:
    ts_atlas_free(a);
    return st;
}
#undef BAD

const ts_atlas_info *ts_atlas_get_info(const ts_atlas *a)
{
    return a ? &a->info : NULL;
}

const ts_atlas_step *ts_atlas_get_step(const ts_atlas *a, int step)
{
    return a && step >= 0 && step < a->info.steps ? &a->steps[step] : NULL;
}

ts_status ts_atlas_read(const ts_atlas *a, int step, int x0, int y0, int w, int h,
                        uint8_t *out, ptrdiff_t stride, ts_error *err)
{
    if (!a || !out)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_read: NULL argument");
    if (step < 0 || step >= a->info.steps)
        return ts_fail(err, TS_ERR_ARG, "the atlas has maps 1 to %d, not %d",
                       a->info.steps, step + 1);
    if (w < 0 || h < 0 || x0 < 0 || y0 < 0 || x0 > a->info.width - w ||
        y0 > a->info.height - h || stride < w)
        return ts_fail(err, TS_ERR_ARG, "window %d,%d %dx%d lies outside the %d x %d atlas",
                       x0, y0, w, h, a->info.width, a->info.height);
    size_t plane = (size_t)step + (a->info.has_nodata ? 1 : 0);
    for (int y = y0; y < y0 + h; y++) {
        uint8_t *row = out + (ptrdiff_t)(y - y0) * stride;
        int ty = y / TS_ATLAS_TILE, r = y % TS_ATLAS_TILE;
        int x = x0;
        while (x < x0 + w) {
            int tx = x / TS_ATLAS_TILE;
            size_t t = (size_t)ty * a->tx + tx;
            unsigned bits = (unsigned)(a->dict[index_at(a, plane, t)] >> (8 * r)) & 0xffu;
            unsigned nd = a->info.has_nodata
                              ? (unsigned)(a->dict[index_at(a, 0, t)] >> (8 * r)) & 0xffu
                              : 0u;
            int end = (tx + 1) * TS_ATLAS_TILE;
            if (end > x0 + w)
                end = x0 + w;
            for (; x < end; x++) {
                int c = x % TS_ATLAS_TILE;
                row[x - x0] = (nd >> c) & 1u ? TS_ATLAS_NODATA : (uint8_t)((bits >> c) & 1u);
            }
        }
    }
    return ts_ok(err);
}
