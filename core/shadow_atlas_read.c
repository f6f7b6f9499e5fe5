/*
 * Reading a far-shadow atlas (docs/atlas-format.md): the header, its
 * checksums, the step table (shadow_atlas_steps.c), the LZMA-compressed
 * tile dictionary and index maps; blocks decoded on request.
 */
#include <lzma.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shadow_atlas.h"
#include "shadow_atlas_internal.h"
#include "status_internal.h"

/* Little-endian reading. */
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

/* Decode one .xz section that must hold exactly `expect` bytes into a new
 * buffer (*out, free with free()). The buffer grows with what the stream
 * really decodes to, so a damaged header announcing gigabytes costs no more
 * memory than the section's real contents. */
static ts_status xz_decompress(const uint8_t *in, size_t n, size_t expect, uint8_t **out,
                               const char *what, ts_error *err)
{
    lzma_stream s = LZMA_STREAM_INIT;
    *out = NULL;
    /* 1 GiB: a damaged header cannot ask for more decoder memory */
    if (lzma_stream_decoder(&s, (uint64_t)1 << 30, 0) != LZMA_OK)
        return ts_fail(err, TS_ERR_NOMEM, "out of memory decompressing the atlas's %s",
                       what);
    /* one byte past `expect`: room to see a stream that decodes to more */
    size_t cap = expect < 65536 ? expect + 1 : 65536;
    uint8_t *buf = malloc(cap);
    lzma_ret r = buf ? LZMA_OK : LZMA_MEM_ERROR;
    s.next_in = in;
    s.avail_in = n;
    s.next_out = buf;
    s.avail_out = cap;
    while (r == LZMA_OK) {
        r = lzma_code(&s, LZMA_FINISH);
        if (r == LZMA_OK && s.avail_out == 0) {
            if (cap > expect)
                break; /* already more than announced */
            size_t grown = cap > (expect + 1) / 2 ? expect + 1 : 2 * cap;
            uint8_t *b = realloc(buf, grown);
            if (!b) {
                r = LZMA_MEM_ERROR;
                break;
            }
            buf = b;
            s.next_out = buf + cap;
            s.avail_out = grown - cap;
            cap = grown;
        }
    }
    size_t in_pos = (size_t)s.total_in, out_pos = (size_t)s.total_out;
    lzma_end(&s);
    if (r == LZMA_MEM_ERROR) {
        free(buf);
        return ts_fail(err, TS_ERR_NOMEM, "out of memory decompressing the atlas's %s",
                       what);
    }
    if (r != LZMA_STREAM_END || in_pos != n || out_pos != expect) {
        free(buf);
        return ts_fail(err, TS_ERR_ARG,
                       "the atlas is damaged: its %s (LZMA) do not decode to the "
                       "%zu bytes the header announces (liblzma %d, %zu of %zu bytes "
                       "read, %zu written)", what, expect, (int)r, in_pos, n, out_pos);
    }
    *out = buf;
    return TS_OK;
}

int ts_atlas_identify(const uint8_t *head, size_t n)
{
    return head && n >= 8 && memcmp(head, TS_ATLAS_MAGIC, 8) == 0;
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

/* The header's fields (docs/atlas-format.md). */
typedef struct {
    uint32_t version, W, H, steps, flags, ib, ntiles;
    uint64_t so, sn, to, tn, dof, dn, io, in;
} atlas_header;

/* The checks that need only the header (the first min(n, 168) bytes at b)
 * and the file's size n, so that a reader can refuse a file longer or
 * shorter than its header says before reading it (ts_atlas_check_header). */
static ts_status read_header(const uint8_t *b, size_t head_n, uint64_t n, atlas_header *h,
                             ts_error *err)
{
    if (!b || !ts_atlas_identify(b, head_n))
        return ts_fail(err, TS_ERR_ARG, "not a terrashade atlas (the file does not start "
                       "with the atlas magic \\x89TSATLAS)");
    if (head_n < (n < TS_ATLAS_HEADER_SIZE ? n : TS_ATLAS_HEADER_SIZE))
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_check_header: %zu bytes given, the header "
                       "has %d", head_n, TS_ATLAS_HEADER_SIZE);
    if (n < 16)
        return ts_fail(err, TS_ERR_ARG, "the atlas is truncated: %llu bytes, the header "
                       "alone has %d", (unsigned long long)n, TS_ATLAS_HEADER_SIZE);
    uint32_t version = get32(b + 8), hsize = get32(b + 12);
    if (version == 1)
        return ts_fail(err, TS_ERR_ARG, "the atlas has format version 1, whose metadata and "
                       "step table carry no checksum and cannot be validated; this terrashade "
                       "reads version %d: recreate the atlas (gdal_translate -of TERRASHADE "
                       "from PRODUCT=farshadow)", TS_ATLAS_VERSION);
    if (version != TS_ATLAS_VERSION)
        return ts_fail(err, TS_ERR_ARG, "the atlas has format version %u; this terrashade "
                       "reads version %d", version, TS_ATLAS_VERSION);
    if (hsize < TS_ATLAS_HEADER_SIZE || n < hsize)
        return ts_fail(err, TS_ERR_ARG, "the atlas is truncated or its header is damaged "
                       "(header of %u bytes in a %llu-byte file)", hsize,
                       (unsigned long long)n);
    if (lzma_crc32(b, 160, 0) != get32(b + 160))
        return ts_fail(err, TS_ERR_ARG, "the atlas's header is damaged (CRC32 mismatch)");
    uint32_t W = get32(b + 16), H = get32(b + 20), steps = get32(b + 24);
    uint32_t tile = get32(b + 28), ib = get32(b + 36), ntiles = get32(b + 40);
    if (W < 1 || H < 1 || W > INT32_MAX / 2 || H > INT32_MAX / 2 || steps < 1 ||
        steps > INT32_MAX / 2 || tile != TS_ATLAS_TILE || (ib != 2 && ib != 4) ||
        ntiles < 1 || (ib == 2 && ntiles > 65536))
        return ts_fail(err, TS_ERR_ARG, "the atlas's header is inconsistent (%u x %u cells, "
                       "%u maps, tile %u, %u-byte indices, %u tiles)", W, H, steps, tile, ib,
                       ntiles);
    *h = (atlas_header){version, W, H, steps, get32(b + 32), ib, ntiles, get64(b + 104),
                        (uint64_t)steps * TS_ATLAS_STEP_SIZE, get64(b + 112), get64(b + 120),
                        get64(b + 128), get64(b + 136), get64(b + 144), get64(b + 152)};
    uint64_t secs[4][2] = {{h->so, h->sn}, {h->to, h->tn}, {h->dof, h->dn}, {h->io, h->in}};
    uint64_t end = hsize;
    for (int i = 0; i < 4; i++) {
        if (secs[i][0] < hsize || secs[i][0] > n || secs[i][1] > n - secs[i][0])
            return ts_fail(err, TS_ERR_ARG, "the atlas is truncated: a section at byte %llu "
                           "of %llu bytes lies beyond the end of the %llu-byte file",
                           (unsigned long long)secs[i][0], (unsigned long long)secs[i][1],
                           (unsigned long long)n);
        end = secs[i][0] + secs[i][1] > end ? secs[i][0] + secs[i][1] : end;
    }
    /* every byte under a checksum: bytes after the last section are none
     * of the atlas's (appended data, a copy cut into another file), and the
     * sections follow each other without gaps or overlaps */
    if (end < n)
        return ts_fail(err, TS_ERR_ARG, "the atlas is damaged: %llu bytes follow its last "
                       "section, which ends at byte %llu of the %llu-byte file",
                       (unsigned long long)(n - end), (unsigned long long)end,
                       (unsigned long long)n);
    if ((uint64_t)hsize + h->sn + h->tn + h->dn + h->in != n)
        return ts_fail(err, TS_ERR_ARG, "the atlas is damaged: its header and sections hold "
                       "%llu bytes of the %llu-byte file (gaps or overlaps between them)",
                       (unsigned long long)((uint64_t)hsize + h->sn + h->tn + h->dn + h->in),
                       (unsigned long long)n);
    return TS_OK;
}

ts_status ts_atlas_check_header(const uint8_t *head, size_t head_n, uint64_t file_size,
                                ts_error *err)
{
    atlas_header h;
    ts_status st = read_header(head, head_n, file_size, &h, err);
    return st == TS_OK ? ts_ok(err) : st;
}

#define BAD(...) do { st = ts_fail(err, TS_ERR_ARG, __VA_ARGS__); goto fail; } while (0)

ts_status ts_atlas_open(const uint8_t *b, size_t n, ts_atlas **out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "ts_atlas_open: the output is NULL");
    *out = NULL;
    atlas_header h;
    ts_status st = read_header(b, n, n, &h, err);
    if (st != TS_OK)
        return st;
    uint32_t version = h.version, W = h.W, H = h.H, steps = h.steps, flags = h.flags,
             ib = h.ib, ntiles = h.ntiles;
    uint64_t so = h.so, sn = h.sn, to = h.to, tn = h.tn, dof = h.dof, dn = h.dn, io = h.io,
             in = h.in;
    ts_atlas *a = calloc(1, sizeof *a);
    if (!a)
        return ts_fail(err, TS_ERR_NOMEM, "cannot allocate the atlas");
    if (lzma_crc32(b + to, (size_t)tn, lzma_crc32(b + so, (size_t)sn, 0)) != get32(b + 164))
        BAD("the atlas's step table or metadata text is damaged (CRC32 mismatch)");
    a->info.width = (int)W;
    a->info.height = (int)H;
    a->info.steps = (int)steps;
    a->info.threshold_cells = (int)(get32(b + 44) > INT32_MAX ? 0 : get32(b + 44));
    a->info.threshold_m = getf64(b + 48);
    /* bits and fields a version-2 writer leaves 0: set, the file is not one
     * (a later version changes the version number, refused above) */
    if (flags & ~3u)
        BAD("the atlas's header is damaged: it sets flag bits 0x%x, which version %u "
            "does not define", flags & ~3u, version);
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
    /* the text and the steps lie in the file (the section checks above);
     * the dictionary and the index are allocated as their streams decode */
    a->text = malloc(tn + 1);
    a->steps = malloc(steps * sizeof *a->steps);
    if (!a->text || !a->steps) {
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the atlas's %u map records", steps);
        goto fail;
    }
    memcpy(a->text, b + to, tn);
    a->text[tn] = '\0';
    if (memchr(a->text, '\0', tn))
        BAD("the atlas's metadata text is damaged (it holds a NUL byte)");
    a->info.metadata = a->text;
    for (uint32_t s = 0; s < steps; s++) {
        const uint8_t *r = b + so + (size_t)s * TS_ATLAS_STEP_SIZE;
        a->steps[s].unix_time = getf64(r);
        a->steps[s].azimuth = getf64(r + 8);
        a->steps[s].grid_azimuth = getf64(r + 16);
        a->steps[s].elevation = getf64(r + 24);
        a->steps[s].utc_offset_minutes = (int32_t)get32(r + 32);
        if (get32(r + 36) != 0)
            BAD("the atlas's step table is invalid: map %u's reserved field is %u, not 0",
                s + 1, get32(r + 36));
    }
    if ((st = ts_atlas_check_steps(a->steps, (int)steps, "the atlas's step table is invalid",
                                   err)) != TS_OK)
        goto fail;
    uint8_t *dict_raw = NULL;
    st = xz_decompress(b + dof, dn, (size_t)ntiles * 8, &dict_raw, "tile dictionary words",
                       err);
    /* allocated once the section really holds that many tiles */
    if (st == TS_OK && !(a->dict = malloc((size_t)ntiles * sizeof *a->dict)))
        st = ts_fail(err, TS_ERR_NOMEM, "cannot allocate the atlas's %u-tile dictionary",
                     ntiles);
    if (st == TS_OK)
        for (uint32_t i = 0; i < ntiles; i++)
            a->dict[i] = get64(dict_raw + 8 * (size_t)i);
    free(dict_raw);
    if (st != TS_OK)
        goto fail;
    if ((st = xz_decompress(b + io, in, idx_raw, &a->index, "index maps", err)) != TS_OK)
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
