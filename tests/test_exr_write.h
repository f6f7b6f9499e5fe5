/* Writing small OpenEXR files with OpenEXRCore's writer, for the tests of
 * the environment-map reader (check_env_map.c). */
#ifndef TS_TEST_EXR_WRITE_H
#define TS_TEST_EXR_WRITE_H

#include <openexr.h>

typedef struct {
    int width, height;
    const char *const *channels; /* names, e.g. {"R","G","B"} */
    int nchannels;
    exr_pixel_type_t type;       /* of every channel */
    exr_compression_t compression;
    int tile_size;               /* 0: scanline file, else square tiles */
    int envmap;                  /* -1: no attribute, else EXR_ENVMAP_LATLONG/CUBE */
    int extra_part;              /* 1: add a second part (an 8 x 4 image of 1000s) */
    int origin_x, origin_y;      /* the data window's top-left corner */
} texr_spec;

/* Write pixels (nchannels floats per pixel, interleaved, row 0 first; for
 * EXR_PIXEL_UINT the values are rounded to integers) to path. 0 on
 * success, else the OpenEXRCore error code (message printed). */
int texr_write(const char *path, const texr_spec *spec, const float *pixels);

#endif
