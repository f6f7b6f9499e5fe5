/* Helpers for the environment-map tests: sums over texels, directions,
 * images and temporary files. */
#ifndef TS_TEST_ENV_H
#define TS_TEST_ENV_H

#include <stddef.h>

#include "terrashade_env.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Sum of the texels' solid angles. */
double tenv_total_solid_angle(const ts_env *e);
/* Irradiance per colour onto a plane of unit normal n (terrain frame):
 * sum of rgb * max(0, n . dir) * solid angle. */
void tenv_irradiance(const ts_env *e, const double n[3], double out[3]);
/* Sum of rgb * solid angle per colour. */
void tenv_power(const ts_env *e, double out[3]);
/* Index of the texel of largest r + g + b. */
size_t tenv_brightest(const ts_env *e);

/* n_pixels RGB pixels of value v (malloc'd). */
float *tenv_constant(size_t n_pixels, float v);
/* w x h RGB pixels of random values in [0, 10) that half floats hold
 * exactly (multiples of 1/64). */
float *tenv_random_image(int w, int h, unsigned seed);

/* A random unit direction (any frame). */
void tenv_random_direction(unsigned *seed, double d[3]);
/* Direction k of n spread evenly over the sphere (Fibonacci lattice). */
void tenv_fibonacci_direction(int k, int n, double d[3]);
/* The pixel (x, y) of a face_size x 6 face_size cube map that OpenEXR
 * assigns to map direction d (CubeMap::faceAndPixelPosition, then
 * ::pixelPosition), rounded to the nearest pixel. */
void tenv_cube_pixel_of(const double d[3], int face_size, int *x, int *y);
/* The median of v[0..n) (sorts v). */
double tenv_median(double *v, int n);

/* A temporary directory for the test files: made by tenv_tmp_begin,
 * emptied and removed by tenv_tmp_end; tenv_tmp gives a path inside it
 * (a static buffer, one of 8 in turn). */
void tenv_tmp_begin(void);
const char *tenv_tmp(const char *name);
void tenv_tmp_end(void);

#endif
