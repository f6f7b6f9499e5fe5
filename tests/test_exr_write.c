/* OpenEXRCore's writer: header, then chunk by chunk (scanline or tiled). */
#include "test_exr_write.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Encode one chunk whose top-left pixel is (x0, y0), with a pipeline of
 * its own. (OpenEXRCore 3.1.5 writes some half, ZIP, 8 x 8 tiles garbled:
 * its C++ library reads the same NaNs back. The tests avoid that case.) */
static exr_result_t encode_chunk(exr_context_t ctx, int part, const exr_chunk_info_t *ci,
                                 const texr_spec *s, const uint8_t *base, size_t elem, int x0,
                                 int y0)
{
    exr_encode_pipeline_t pipe = EXR_ENCODE_PIPELINE_INITIALIZER, *enc = &pipe;
    exr_result_t rv = exr_encoding_initialize(ctx, part, ci, enc);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *ch = &enc->channels[c];
        int k = 0;
        while (k < s->nchannels && strcmp(s->channels[k], ch->channel_name) != 0)
            k++;
        size_t pixel = elem * (size_t)s->nchannels;
        ch->encode_from_ptr = base + ((size_t)y0 * (size_t)s->width + (size_t)x0) * pixel +
                              (size_t)k * elem;
        ch->user_pixel_stride = (int32_t)pixel;
        ch->user_line_stride = (int32_t)(pixel * (size_t)s->width);
        ch->user_data_type = s->type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = 4;
    }
    rv = exr_encoding_choose_default_routines(ctx, part, enc);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_encoding_run(ctx, part, enc);
    exr_encoding_destroy(ctx, enc);
    return rv;
}

static exr_result_t write_part(exr_context_t ctx, int part, const texr_spec *s,
                               const uint8_t *base, size_t elem)
{
    exr_chunk_info_t ci;
    exr_result_t rv = EXR_ERR_SUCCESS;
    if (s->tile_size > 0) {
        int t = s->tile_size;
        for (int ty = 0; rv == EXR_ERR_SUCCESS && ty * t < s->height; ty++)
            for (int tx = 0; rv == EXR_ERR_SUCCESS && tx * t < s->width; tx++) {
                rv = exr_write_tile_chunk_info(ctx, part, tx, ty, 0, 0, &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = encode_chunk(ctx, part, &ci, s, base, elem, tx * t, ty * t);
            }
    } else {
        int32_t lines = 1;
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
        for (int y = 0; rv == EXR_ERR_SUCCESS && y < s->height; y += lines) {
            rv = exr_write_scanline_chunk_info(ctx, part, s->origin_y + y, &ci);
            if (rv == EXR_ERR_SUCCESS)
                rv = encode_chunk(ctx, part, &ci, s, base, elem, 0, y);
        }
    }
    return rv;
}

static exr_result_t define_part(exr_context_t ctx, const char *name, const texr_spec *s,
                                int *part)
{
    exr_result_t rv = exr_add_part(ctx, name, s->tile_size > 0 ? EXR_STORAGE_TILED
                                                              : EXR_STORAGE_SCANLINE, part);
    exr_attr_box2i_t box;
    box.min.x = s->origin_x, box.min.y = s->origin_y;
    box.max.x = s->origin_x + s->width - 1, box.max.y = s->origin_y + s->height - 1;
    exr_attr_v2f_t centre;
    centre.x = centre.y = 0.0f;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr(ctx, *part, &box, &box, 1.0f, &centre, 1.0f,
                                          EXR_LINEORDER_INCREASING_Y, s->compression);
    for (int c = 0; rv == EXR_ERR_SUCCESS && c < s->nchannels; c++)
        rv = exr_add_channel(ctx, *part, s->channels[c], s->type, EXR_PERCEPTUALLY_LOGARITHMIC,
                             1, 1);
    if (rv == EXR_ERR_SUCCESS && s->tile_size > 0)
        rv = exr_set_tile_descriptor(ctx, *part, (uint32_t)s->tile_size, (uint32_t)s->tile_size,
                                     EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    if (rv == EXR_ERR_SUCCESS && s->envmap >= 0)
        rv = exr_attr_set_envmap(ctx, *part, "envmap", (exr_envmap_t)s->envmap);
    return rv;
}

int texr_write(const char *path, const texr_spec *s, const float *pixels)
{
    size_t n = (size_t)s->width * (size_t)s->height * (size_t)s->nchannels;
    const uint8_t *base = (const uint8_t *)pixels;
    uint32_t *ints = NULL;
    if (s->type == EXR_PIXEL_UINT) {
        ints = malloc(n * sizeof *ints);
        for (size_t i = 0; i < n; i++)
            ints[i] = (uint32_t)(pixels[i] + 0.5f);
        base = (const uint8_t *)ints;
    }
    texr_spec other = *s;
    other.width = 8, other.height = 4, other.envmap = -1, other.origin_x = other.origin_y = 0;
    float *other_px = malloc((size_t)8 * 4 * (size_t)s->nchannels * sizeof *other_px);
    for (size_t i = 0; i < (size_t)8 * 4 * (size_t)s->nchannels; i++)
        other_px[i] = 1000.0f;

    exr_context_t ctx = NULL;
    int part = 0, part2 = 1;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, NULL);
    if (rv == EXR_ERR_SUCCESS)
        rv = define_part(ctx, "envmap", s, &part);
    if (rv == EXR_ERR_SUCCESS && s->extra_part)
        rv = define_part(ctx, "other", &other, &part2);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = write_part(ctx, part, s, base, 4);
    if (rv == EXR_ERR_SUCCESS && s->extra_part)
        rv = write_part(ctx, part2, &other, (const uint8_t *)other_px, 4);
    exr_result_t fin = exr_finish(&ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = fin;
    if (rv != EXR_ERR_SUCCESS)
        fprintf(stderr, "texr_write %s: %s\n", path, exr_get_default_error_message(rv));
    free(ints);
    free(other_px);
    return (int)rv;
}
