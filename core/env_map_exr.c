/* Reading environment maps from OpenEXR files with OpenEXRCore (the C
 * API): the first part, scanline or tiled, any pixel type and compression,
 * decoded to RGB floats and handed to env_from_image. Files and memory
 * buffers share one path: a custom stream (read_fn/size_fn). */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>

#include "env_map_exr_cxx.h"
#include "env_map_internal.h"
#include "status_internal.h"

/* Where the bytes come from: a file descriptor or a memory buffer. */
typedef struct {
    const char *name;
    int fd; /* -1 for memory */
    const unsigned char *mem;
    uint64_t size;
    char lib_msg[160]; /* OpenEXRCore's last error message */
} exr_source;

/* pread over the source: the count read (short at the end), -1 on error. */
static int64_t source_pread(void *user, void *buffer, uint64_t sz, uint64_t offset)
{
    exr_source *s = user;
    if (offset >= s->size)
        return 0;
    uint64_t n = sz < s->size - offset ? sz : s->size - offset;
    if (s->fd < 0) {
        memcpy(buffer, s->mem + offset, (size_t)n);
        return (int64_t)n;
    }
    uint64_t done = 0;
    while (done < n) {
        ssize_t got = pread(s->fd, (char *)buffer + done, (size_t)(n - done),
                            (off_t)(offset + done));
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0)
            return -1;
        if (got == 0)
            break;
        done += (uint64_t)got;
    }
    return (int64_t)done;
}

static int64_t source_read(exr_const_context_t ctxt, void *user, void *buffer, uint64_t sz,
                           uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    int64_t got = source_pread(user, buffer, sz, offset);
    if (got < 0)
        error_cb(ctxt, EXR_ERR_READ_IO, "cannot read: %s", strerror(errno));
    return got;
}

static int64_t source_size(exr_const_context_t ctxt, void *user)
{
    (void)ctxt;
    return (int64_t)((exr_source *)user)->size;
}

/* Keep the library's message for our error sentence instead of printing it. */
static void source_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *user = NULL;
    (void)code;
    if (exr_get_user_data(ctxt, &user) == EXR_ERR_SUCCESS && user)
        snprintf(((exr_source *)user)->lib_msg, sizeof ((exr_source *)user)->lib_msg, "%s",
                 msg ? msg : "");
}

static const char *lib_message(const exr_source *s, exr_result_t rv)
{
    return s->lib_msg[0] ? s->lib_msg : exr_get_default_error_message(rv);
}

/* The channels used: R, G, B into slots 0..2, or Y into slot 0 (grey);
 * chroma: grey from a luminance/chroma file (RY and BY left). */
typedef struct {
    int grey, chroma;
} channel_plan;

/* Channel name `name` appended to the list in listed[size] (", " between),
 * its bytes other than printable ASCII as '?' (a name cut within a UTF-8
 * character made the whole error unreadable to Python), at most 24 of
 * them, and "..." where the list is full. */
static void list_channel(char *listed, size_t size, const char *name)
{
    size_t used = strlen(listed);
    if (used + 32 >= size) {
        if (used + 4 < size && (used < 3 || strcmp(listed + used - 3, "...") != 0))
            snprintf(listed + used, size - used, "...");
        return;
    }
    if (used)
        used += (size_t)snprintf(listed + used, size - used, ", ");
    size_t k = 0;
    for (; name[k] && k < 24; k++)
        listed[used + k] = name[k] >= 0x20 && name[k] < 0x7f ? name[k] : '?';
    listed[used + k] = '\0';
    if (name[k])
        snprintf(listed + used + k, size - used - k, "...");
}

static int slot_of(const channel_plan *plan, const char *channel)
{
    if (plan->grey)
        return strcmp(channel, "Y") == 0 ? 0 : -1;
    if (strcmp(channel, "R") == 0)
        return 0;
    if (strcmp(channel, "G") == 0)
        return 1;
    if (strcmp(channel, "B") == 0)
        return 2;
    return -1;
}

/* Choose RGB or Y; a sentence listing the channels when neither is there. */
static ts_status plan_channels(exr_context_t ctx, const exr_source *src, channel_plan *plan,
                               ts_error *err)
{
    const exr_attr_chlist_t *chl = NULL;
    if (exr_get_channels(ctx, 0, &chl) != EXR_ERR_SUCCESS || !chl)
        return ts_fail(err, TS_ERR_ARG, "environment map '%s' has no channel list", src->name);
    int found[6] = {0, 0, 0, 0, 0, 0}; /* R, G, B, Y, and chroma RY, BY */
    static const char *const names[6] = {"R", "G", "B", "Y", "RY", "BY"};
    char listed[256] = "";
    for (int c = 0; c < chl->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        list_channel(listed, sizeof listed, e->name.str);
        for (int k = 0; k < 6; k++)
            if (strcmp(e->name.str, names[k]) == 0)
                found[k] = (e->x_sampling == 1 && e->y_sampling == 1) ? 1 : -1;
    }
    plan->grey = !(found[0] == 1 && found[1] == 1 && found[2] == 1);
    plan->chroma = plan->grey && found[4] && found[5];
    if (!plan->grey || found[3] == 1)
        return TS_OK;
    int parts = 1;
    exr_get_count(ctx, &parts);
    return ts_fail(err, TS_ERR_ARG,
                   "environment map '%s' has no usable channel: it needs R, G and B, or Y, "
                   "not subsampled (%s has: %s)", src->name,
                   parts > 1 ? "its first part, the one read," : "it",
                   listed[0] ? listed : "none");
}

/* The layout from the envmap attribute, else from the aspect ratio. */
static ts_status plan_layout(exr_context_t ctx, const exr_source *src, int64_t w, int64_t h,
                             env_layout *layout, ts_error *err)
{
    exr_envmap_t em;
    if (exr_attr_get_envmap(ctx, 0, "envmap", &em) == EXR_ERR_SUCCESS &&
        (em == EXR_ENVMAP_LATLONG || em == EXR_ENVMAP_CUBE)) {
        *layout = em == EXR_ENVMAP_CUBE ? ENV_CUBE : ENV_LATLONG;
        if (*layout == ENV_CUBE && h != 6 * w)
            return ts_fail(err, TS_ERR_ARG,
                           "environment map '%s' is marked as a cube map but is %lld x %lld "
                           "pixels; a cube map is w x 6w (six square faces stacked)",
                           src->name, (long long)w, (long long)h);
        return TS_OK;
    }
    if (w == 2 * h)
        *layout = ENV_LATLONG;
    else if (h == 6 * w)
        *layout = ENV_CUBE;
    else
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' has no envmap attribute and its size %lld x %lld "
                       "is neither 2:1 (lat-long) nor 1:6 (cube faces)",
                       src->name, (long long)w, (long long)h);
    return TS_OK;
}

/* Where the channels no product reads are decoded to, and thrown away. */
typedef struct {
    uint8_t *buf;
    size_t size;
} discard_buffer;

/* Decode one chunk whose top-left pixel is (x0, y0) from the data window's
 * corner into the interleaved rgb image of width w. */
static exr_result_t decode_chunk(exr_context_t ctx, const exr_chunk_info_t *ci, int x0, int y0,
                                 int w, float *rgb, const channel_plan *plan,
                                 exr_decode_pipeline_t *dec, int *started, discard_buffer *discard)
{
    exr_result_t rv = *started ? exr_decoding_update(ctx, 0, ci, dec)
                               : exr_decoding_initialize(ctx, 0, ci, dec);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    *started = 1;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        int slot = slot_of(plan, ch->channel_name);
        if (slot < 0) {
            /* Every channel gets a destination: OpenEXRCore 3.1's unpackers
             * can write through a NULL decode_to_ptr when only some channels
             * are wanted (a fuzzed tiled file with B, G and Y crashed there).
             * The unused ones go, in their own type, to a scratch buffer. */
            size_t need = (size_t)(ch->width > 0 ? ch->width : 1) *
                          (size_t)(ch->height > 0 ? ch->height : 1) * sizeof(float);
            if (need > discard->size) {
                uint8_t *b = realloc(discard->buf, need);
                if (!b)
                    return EXR_ERR_OUT_OF_MEMORY;
                discard->buf = b;
                discard->size = need;
            }
            ch->decode_to_ptr = discard->buf;
            ch->user_pixel_stride = (int32_t)sizeof(float);
            ch->user_line_stride = (int32_t)sizeof(float) * (ch->width > 0 ? ch->width : 1);
            ch->user_data_type = ch->data_type;
            ch->user_bytes_per_element = ch->bytes_per_element;
            continue;
        }
        ch->decode_to_ptr = (uint8_t *)(rgb + ((size_t)y0 * (size_t)w + (size_t)x0) * 3 + slot);
        ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
        ch->user_line_stride = 3 * (int32_t)sizeof(float) * w;
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = (int16_t)sizeof(float);
    }
    rv = exr_decoding_choose_default_routines(ctx, 0, dec);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    return exr_decoding_run(ctx, 0, dec);
}

/* Decode level 0 of the first part, chunk by chunk. */
static exr_result_t decode_pixels(exr_context_t ctx, exr_storage_t storage, int w, int h,
                                  float *rgb, const channel_plan *plan)
{
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    discard_buffer discard = {NULL, 0};
    int started = 0;
    exr_result_t rv = EXR_ERR_SUCCESS;
    exr_chunk_info_t ci;
    if (storage == EXR_STORAGE_TILED) {
        int32_t tw = 0, th = 0;
        rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th);
        if (rv == EXR_ERR_SUCCESS && (tw <= 0 || th <= 0))
            rv = EXR_ERR_INVALID_ATTR;
        for (int ty = 0; rv == EXR_ERR_SUCCESS && (int64_t)ty * th < h; ty++)
            for (int tx = 0; rv == EXR_ERR_SUCCESS && (int64_t)tx * tw < w; tx++) {
                rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = decode_chunk(ctx, &ci, tx * tw, ty * th, w, rgb, plan, &dec, &started,
                                      &discard);
            }
    } else {
        exr_attr_box2i_t dw;
        int32_t lines = 0;
        rv = exr_get_data_window(ctx, 0, &dw);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        if (rv == EXR_ERR_SUCCESS && lines <= 0)
            rv = EXR_ERR_INVALID_ATTR;
        for (int64_t y = 0; rv == EXR_ERR_SUCCESS && y < h; y += lines) {
            rv = exr_read_scanline_chunk_info(ctx, 0, dw.min.y + (int)y, &ci);
            if (rv == EXR_ERR_SUCCESS)
                rv = decode_chunk(ctx, &ci, 0, ci.start_y - dw.min.y, w, rgb, plan, &dec,
                                  &started, &discard);
        }
    }
    if (started)
        exr_decoding_destroy(ctx, &dec);
    free(discard.buf);
    return rv;
}

/* Everything after the header was parsed; ctx is finished by the caller. */
static ts_status read_part0(exr_context_t ctx, exr_source *src, double rotation_deg,
                            size_t max_texels, ts_env *out, ts_env_map_info *info,
                            ts_error *err)
{
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    exr_result_t rv = exr_get_storage(ctx, 0, &storage);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_data_window(ctx, 0, &dw);
    if (rv != EXR_ERR_SUCCESS)
        return ts_fail(err, TS_ERR_ARG, "environment map '%s' has a bad header (%s)", src->name,
                       lib_message(src, rv));
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' holds deep data, not an image", src->name);
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0)
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' has an empty data window (%lld x %lld)", src->name,
                       (long long)(w > 0 ? w : 0), (long long)(h > 0 ? h : 0));
    if ((uint64_t)w * (uint64_t)h > TS_ENV_MAX_PIXELS)
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' is %lld x %lld pixels, more than the limit of %zu",
                       src->name, (long long)w, (long long)h, (size_t)TS_ENV_MAX_PIXELS);
    channel_plan plan;
    env_layout layout;
    ts_status st = plan_channels(ctx, src, &plan, err);
    if (st == TS_OK)
        st = plan_layout(ctx, src, w, h, &layout, err);
    if (st != TS_OK)
        return st;
    if (info) { /* the header is all that was asked for */
        info->cube = layout == ENV_CUBE;
        info->grey = plan.grey;
        info->chroma = plan.chroma;
        info->width = (int)w;
        info->height = (int)h;
        return TS_OK;
    }

    float *rgb = calloc((size_t)w * (size_t)h * 3, sizeof *rgb);
    if (!rgb)
        return ts_fail(err, TS_ERR_NOMEM, "no memory to read environment map '%s' (%lld x %lld)",
                       src->name, (long long)w, (long long)h);
    rv = decode_pixels(ctx, storage, (int)w, (int)h, rgb, &plan);
    if (rv == EXR_ERR_FEATURE_NOT_IMPLEMENTED) { /* e.g. DWA before OpenEXR 3.2 */
        char msg[160];
        if (env_exr_decode_cxx(source_pread, src, src->size, src->name, plan.grey, (int)w,
                               (int)h, rgb, msg, sizeof msg) != 0) {
            free(rgb);
            return ts_fail(err, TS_ERR_ARG, "environment map '%s' is damaged or truncated: %s",
                           src->name, msg);
        }
        rv = EXR_ERR_SUCCESS;
    }
    if (rv != EXR_ERR_SUCCESS) {
        free(rgb);
        return ts_fail(err, rv == EXR_ERR_OUT_OF_MEMORY ? TS_ERR_NOMEM : TS_ERR_ARG,
                       "environment map '%s' is damaged or truncated: %s", src->name,
                       lib_message(src, rv));
    }
    if (plan.grey)
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            rgb[3 * i + 1] = rgb[3 * i + 2] = rgb[3 * i];
    env_image img = {rgb, (int)w, (int)h, layout};
    st = env_from_image(&img, rotation_deg, max_texels, src->name, out, err);
    free(rgb);
    return st;
}

static ts_status read_source(exr_source *src, double rotation_deg, size_t max_texels,
                             ts_env *out, ts_env_map_info *info, ts_error *err)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = src;
    init.read_fn = source_read;
    init.size_fn = source_size;
    init.error_handler_fn = source_error;
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, src->name, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&ctx);
        return ts_fail(err, TS_ERR_ARG, "environment map '%s' is not a readable OpenEXR file (%s)",
                       src->name, lib_message(src, rv));
    }
    ts_status st = read_part0(ctx, src, rotation_deg, max_texels, out, info, err);
    exr_finish(&ctx);
    return st;
}

static ts_status check_out(ts_env *out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "no environment to fill (out is NULL)");
    out->count = 0;
    out->texels = NULL;
    return TS_OK;
}

ts_status ts_env_load_exr_file(const char *path, double rotation_deg, size_t max_texels,
                               ts_env *out, ts_error *err)
{
    if (check_out(out, err) != TS_OK)
        return TS_ERR_ARG;
    if (!path || !path[0])
        return ts_fail(err, TS_ERR_ARG, "no environment map file given");
    exr_source src = {path, -1, NULL, 0, ""};
    src.fd = open(path, O_RDONLY | O_CLOEXEC);
    if (src.fd < 0)
        return ts_fail(err, TS_ERR_ARG, "cannot open environment map '%s': %s", path,
                       strerror(errno));
    struct stat sb;
    if (fstat(src.fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(src.fd);
        return ts_fail(err, TS_ERR_ARG, "environment map '%s' is not a regular file", path);
    }
    src.size = (uint64_t)sb.st_size;
    ts_status st = read_source(&src, rotation_deg, max_texels, out, NULL, err);
    close(src.fd);
    return st;
}

ts_status ts_env_load_exr_memory(const void *buf, size_t size, const char *name,
                                 double rotation_deg, size_t max_texels, ts_env *out,
                                 ts_error *err)
{
    if (check_out(out, err) != TS_OK)
        return TS_ERR_ARG;
    if (!name || !name[0])
        name = "(memory)";
    if (!buf && size > 0)
        return ts_fail(err, TS_ERR_ARG, "environment map '%s': no buffer (NULL)", name);
    exr_source src = {name, -1, buf, size, ""};
    return read_source(&src, rotation_deg, max_texels, out, NULL, err);
}

ts_status ts_env_exr_info(const void *buf, size_t size, const char *name,
                          ts_env_map_info *info, ts_error *err)
{
    if (!info)
        return ts_fail(err, TS_ERR_ARG, "no map description to fill (info is NULL)");
    memset(info, 0, sizeof *info);
    if (!name || !name[0])
        name = "(memory)";
    if (!buf && size > 0)
        return ts_fail(err, TS_ERR_ARG, "environment map '%s': no buffer (NULL)", name);
    exr_source src = {name, -1, buf, size, ""};
    return read_source(&src, 0.0, 0, NULL, info, err);
}
