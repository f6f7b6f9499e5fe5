/* fBm value-noise DEM generator (see fractal_dem.h). */
#include <math.h>
#include <stdint.h>

#include "fractal_dem.h"

static inline float lattice(uint32_t x, uint32_t y, uint32_t seed)
{
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return (float)(h & 0xffffff) / (float)0xffffff - 0.5f;
}

void ts_fractal_fill(ts_grid *g, unsigned seed, double hurst, double relief)
{
    int W = g->width, H = g->height;
    int side = W > H ? W : H;
    double wavelength = side;
    double amp = 1.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            g->z[(ptrdiff_t)y * g->stride + x] = 0.0f;
    for (int oct = 0; wavelength >= 2.0; oct++, wavelength /= 2, amp *= pow(2.0, -hurst)) {
        float inv = (float)(1.0 / wavelength), a = (float)amp;
        for (int y = 0; y < H; y++) {
            float fy = y * inv;
            uint32_t iy = (uint32_t)fy;
            float ty = fy - iy;
            for (int x = 0; x < W; x++) {
                float fx = x * inv;
                uint32_t ix = (uint32_t)fx;
                float tx = fx - ix;
                uint32_t s = seed + (uint32_t)oct;
                float v00 = lattice(ix, iy, s), v10 = lattice(ix + 1, iy, s);
                float v01 = lattice(ix, iy + 1, s), v11 = lattice(ix + 1, iy + 1, s);
                float v0 = v00 + tx * (v10 - v00), v1 = v01 + tx * (v11 - v01);
                g->z[(ptrdiff_t)y * g->stride + x] += a * (v0 + ty * (v1 - v0));
            }
        }
    }
    float lo = INFINITY, hi = -INFINITY;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float v = g->z[(ptrdiff_t)y * g->stride + x];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    float scale = hi > lo ? (float)(relief / (hi - lo)) : 0.0f;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = &g->z[(ptrdiff_t)y * g->stride + x];
            *p = (*p - lo) * scale;
        }
}
