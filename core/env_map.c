/* Environment images as texels: the directions and solid angles of
 * OpenEXR's lat-long and cube-face layouts (ImfEnvmap.cpp, followed
 * exactly), turned into the terrain frame and rotated; large maps merged
 * into blocks. Conventions: terrashade_env.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "env_map_internal.h"
#include "status_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void ts_env_free(ts_env *env)
{
    if (!env)
        return;
    free(env->texels);
    env->texels = NULL;
    env->count = 0;
}

/* One pixel: its direction in the map frame (not normalised) and its
 * solid angle. */
typedef struct {
    double dir[3];
    double solid_angle;
} pixel_geom;

static double clamp1(double x)
{
    return x < -1.0 ? -1.0 : x > 1.0 ? 1.0 : x;
}

/* Which part of a pixel a texel is: the pixel cut into nx x ny equal
 * parts (in longitude and latitude, or in the face's u and v), part
 * (ix, iy); 1 x 1 is the whole pixel at its own centre. */
typedef struct {
    int nx, ny, ix, iy;
} pixel_part;

/* LatLongMap::latLong and ::direction: pixel centres on the poles and on
 * longitude +-pi at both ends (spacings divide by w-1 and h-1); a pixel
 * covers half a spacing either side, clipped to the sphere. */
static void latlong_pixel(int w, int h, int i, int j, const pixel_part *q, pixel_geom *g)
{
    double dlat = M_PI / (h - 1), dlon = 2.0 * M_PI / (w - 1);
    double lat = 0.5 * M_PI - j * dlat;
    double lon = M_PI - i * dlon;
    double top = fmin(lat + 0.5 * dlat, 0.5 * M_PI);
    double bottom = fmax(lat - 0.5 * dlat, -0.5 * M_PI);
    double span = (i == 0 || i == w - 1) ? 0.5 * dlon : dlon;
    if (q->nx * q->ny > 1) {
        double east = i == 0 ? lon : lon + 0.5 * dlon, rise = (top - bottom) / q->ny;
        span /= q->nx;
        lon = east - (q->ix + 0.5) * span;
        top -= q->iy * rise;
        bottom = top - rise;
        lat = 0.5 * (top + bottom);
    }
    g->dir[0] = sin(lon) * cos(lat);
    g->dir[1] = sin(lat);
    g->dir[2] = cos(lon) * cos(lat);
    g->solid_angle = span * (sin(top) - sin(bottom));
}

/* Solid angle seen from the centre of the unit cube's face rectangle
 * [u0,u1] x [v0,v1] at distance 1. */
static double face_rect_solid_angle(double u0, double v0, double u1, double v1)
{
#define CORNER(u, v) atan2((u) * (v), sqrt(1.0 + (u) * (u) + (v) * (v)))
    return CORNER(u1, v1) - CORNER(u0, v1) - CORNER(u1, v0) + CORNER(u0, v0);
#undef CORNER
}

/* CubeMap: image pixel (x, y) of a w x 6w map. The face position (px, py)
 * inverts CubeMap::pixelPosition, the direction is CubeMap::direction. */
static void cube_pixel(int w, int x, int y, const pixel_part *q, pixel_geom *g)
{
    int face = y / w, yf = y - face * w, m = w - 1;
    int px, py;
    switch (face) {
    case 0: px = m - yf; py = x; break;          /* +X */
    case 1: px = m - yf; py = m - x; break;      /* -X */
    case 2: px = x; py = m - yf; break;          /* +Y */
    case 3: px = x; py = yf; break;              /* -Y */
    case 4: px = m - x; py = m - yf; break;      /* +Z */
    default: px = x; py = m - yf; break;         /* -Z */
    }
    double u = 0.0, v = 0.0, half = 1.0; /* a 1 x 6 map: each pixel a whole face */
    if (m > 0) {
        u = 2.0 * px / m - 1.0;
        v = 2.0 * py / m - 1.0;
        half = 1.0 / m;
    }
    double u0 = clamp1(u - half), v0 = clamp1(v - half), u1 = clamp1(u + half);
    double v1 = clamp1(v + half);
    if (q->nx * q->ny > 1) {
        double du = (u1 - u0) / q->nx, dv = (v1 - v0) / q->ny;
        u0 += q->ix * du, v0 += q->iy * dv;
        u1 = u0 + du, v1 = v0 + dv;
        u = 0.5 * (u0 + u1), v = 0.5 * (v0 + v1);
    }
    g->solid_angle = face_rect_solid_angle(u0, v0, u1, v1);
    double s = (face & 1) ? -1.0 : 1.0;
    switch (face / 2) {
    case 0: g->dir[0] = s; g->dir[1] = u; g->dir[2] = v; break;
    case 1: g->dir[0] = u; g->dir[1] = s; g->dir[2] = v; break;
    default: g->dir[0] = u; g->dir[1] = v; g->dir[2] = s; break;
    }
}

/* The image split into panels that blocks must not straddle: the whole
 * lat-long map, or each cube face. */
typedef struct {
    int panels, panel_w, panel_h;
} panel_split;

static panel_split split_of(const env_image *img)
{
    panel_split p;
    p.panels = img->layout == ENV_CUBE ? 6 : 1;
    p.panel_w = img->width;
    p.panel_h = img->layout == ENV_CUBE ? img->width : img->height;
    return p;
}

static size_t texels_for_block(const panel_split *p, int k)
{
    size_t bw = (size_t)(p->panel_w + k - 1) / k, bh = (size_t)(p->panel_h + k - 1) / k;
    return (size_t)p->panels * bw * bh;
}

/* The smallest block size k giving at most max_texels texels (1 when
 * max_texels is 0 or already enough). */
static int block_size(const panel_split *p, size_t max_texels)
{
    if (max_texels == 0 || texels_for_block(p, 1) <= max_texels)
        return 1;
    int kmax = p->panel_w > p->panel_h ? p->panel_w : p->panel_h;
    int k = (int)floor(sqrt((double)texels_for_block(p, 1) / (double)max_texels));
    if (k < 1)
        k = 1;
    while (k < kmax && texels_for_block(p, k) > max_texels)
        k++;
    return k;
}

/* Texels wider than this many degrees are cut into parts (with the
 * pixel's radiance over each part's exact solid angle): a texel's light
 * comes from its centre, so a coarse map put the light of whole caps and
 * rows in one direction (a 4 x 2 map of radiance 1 lit flat ground as 2, a
 * 1 x 6 cube as 0.67). One degree is the light table's default step. */
#define TS_ENV_PART_DEG 1.0

/* The parts of a pixel for img: 1 x 1 for maps of one-degree pixels or
 * finer, else parts of at most TS_ENV_PART_DEG (their count kept within
 * max_texels). */
static pixel_part parts_of(const env_image *img, size_t pixels, size_t max_texels)
{
    pixel_part q = {1, 1, 0, 0};
    double rad = TS_ENV_PART_DEG * M_PI / 180.0, sx, sy;
    if (img->layout == ENV_CUBE) /* widest at the face's centre: du = 2 / (w - 1) */
        sx = sy = (img->width > 1 ? 2.0 / (img->width - 1) : 2.0) / rad;
    else
        sx = 2.0 * M_PI / (img->width - 1) / rad, sy = M_PI / (img->height - 1) / rad;
    sx = ceil(sx - 1e-9), sy = ceil(sy - 1e-9);
    double f = (double)max_texels / ((double)pixels * sx * sy);
    if (f < 1.0) /* within max_texels */
        sx = fmax(1.0, floor(sx * sqrt(f))), sy = fmax(1.0, floor(sy * sqrt(f)));
    q.nx = (int)sx, q.ny = (int)sy;
    return q;
}

/* Accumulates the pixels of one block: solid angle, solid-angle-weighted
 * radiance, and the directions weighted by solid angle (dir) and by
 * power, r + g + b times solid angle (lit_dir). */
typedef struct {
    double solid_angle, dir[3], lit_dir[3], rgb[3];
    double first_dir[3];
} block_sum;

/* Add pixel (x, y); TS_ERR_ARG when it is not finite. */
static ts_status add_pixel(const env_image *img, int x, int y, const pixel_part *q, block_sum *b,
                           const char *name, ts_error *err)
{
    const float *px = img->rgb + ((size_t)y * (size_t)img->width + (size_t)x) * 3;
    for (int c = 0; c < 3; c++)
        if (!isfinite(px[c]))
            return ts_fail(err, TS_ERR_ARG,
                           "environment map '%s': pixel (%d, %d) (column, row, from the "
                           "top left of its data window) is %s; NaN and infinite values are "
                           "refused (negative ones are clamped to 0)",
                           name, x, y, isnan(px[c]) ? "NaN" : "infinite");
    pixel_geom g;
    if (img->layout == ENV_CUBE)
        cube_pixel(img->width, x, y, q, &g);
    else
        latlong_pixel(img->width, img->height, x, y, q, &g);
    double len = sqrt(g.dir[0] * g.dir[0] + g.dir[1] * g.dir[1] + g.dir[2] * g.dir[2]);
    if (b->solid_angle == 0.0)
        for (int c = 0; c < 3; c++)
            b->first_dir[c] = g.dir[c] / len;
    double power = 0.0;
    b->solid_angle += g.solid_angle;
    for (int c = 0; c < 3; c++) {
        double v = g.solid_angle * (px[c] > 0.0f ? (double)px[c] : 0.0);
        b->rgb[c] += v;
        power += v;
    }
    for (int c = 0; c < 3; c++) {
        b->dir[c] += g.solid_angle * g.dir[c] / len;
        b->lit_dir[c] += power * g.dir[c] / len;
    }
    return TS_OK;
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* The block's texel: its direction is where its light comes from (the
 * power-weighted mean direction; the solid-angle-weighted one for a black
 * block), so a bright spot keeps its place; then map frame -> terrain
 * (east, north, up) = (-x, z, y), turned clockwise by the rotation. */
static void block_texel(const block_sum *b, double cos_r, double sin_r, ts_env_texel *t)
{
    const double *d = b->lit_dir;
    double len = norm3(d);
    if (!(len > 0.0)) {
        d = b->dir;
        len = norm3(d);
    }
    double inv = 1.0 / len;
    if (!(len > 1e-12 * b->solid_angle)) { /* a block around the whole sphere */
        d = b->first_dir;
        inv = 1.0;
    }
    double east = -d[0] * inv, north = d[2] * inv, up = d[1] * inv;
    t->dir[0] = (float)(east * cos_r + north * sin_r);
    t->dir[1] = (float)(north * cos_r - east * sin_r);
    t->dir[2] = (float)up;
    t->solid_angle = (float)b->solid_angle;
    for (int c = 0; c < 3; c++)
        t->rgb[c] = (float)(b->solid_angle > 0.0 ? b->rgb[c] / b->solid_angle : 0.0);
}

static ts_status check_image(const env_image *img, const char *name, ts_error *err)
{
    if (img->layout == ENV_CUBE) {
        if (img->width < 1 || img->height != 6 * img->width)
            return ts_fail(err, TS_ERR_ARG,
                           "environment map '%s' is %d x %d pixels; a cube-face map must be "
                           "w x 6w (six square faces stacked)", name, img->width, img->height);
    } else if (img->width < 2 || img->height < 2) {
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' is %d x %d pixels; a lat-long map needs at least "
                       "2 x 2", name, img->width, img->height);
    }
    if ((size_t)img->width * (size_t)img->height > TS_ENV_MAX_PIXELS)
        return ts_fail(err, TS_ERR_ARG,
                       "environment map '%s' is %d x %d pixels, more than the limit of %zu",
                       name, img->width, img->height, (size_t)TS_ENV_MAX_PIXELS);
    return TS_OK;
}

/* The texels env_from_image makes of img: its blocks of k x k pixels, each
 * cut into parts where a coarse map is fit for lighting (one count, for
 * env_from_image and for ts_env_map_texels's estimate of its memory). */
static size_t texel_count(const env_image *img, size_t max_texels)
{
    panel_split p = split_of(img);
    int k = block_size(&p, max_texels);
    size_t count = texels_for_block(&p, k);
    if (max_texels != 0 && k == 1) { /* a map fit for lighting: coarse pixels cut */
        pixel_part q = parts_of(img, count, max_texels);
        count *= (size_t)q.nx * (size_t)q.ny;
    }
    return count;
}

size_t ts_env_map_texels(const ts_env_map_info *info, size_t max_texels)
{
    if (!info || info->width < 1 || info->height < 1)
        return 0;
    env_image img = {NULL, info->width, info->height, info->cube ? ENV_CUBE : ENV_LATLONG};
    return texel_count(&img, max_texels);
}

ts_status env_from_image(const env_image *img, double rotation_deg, size_t max_texels,
                         const char *name, ts_env *out, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "no environment to fill (out is NULL)");
    out->count = 0;
    out->texels = NULL;
    if (!img->rgb)
        return ts_fail(err, TS_ERR_ARG, "environment map '%s': no pixels (NULL)", name);
    if (!isfinite(rotation_deg))
        return ts_fail(err, TS_ERR_ARG, "the environment rotation must be a finite angle");
    ts_status st = check_image(img, name, err);
    if (st != TS_OK)
        return st;

    panel_split p = split_of(img);
    int k = block_size(&p, max_texels);
    pixel_part q = {1, 1, 0, 0};
    if (max_texels != 0 && k == 1) /* a map fit for lighting: coarse pixels cut */
        q = parts_of(img, texels_for_block(&p, k), max_texels);
    const size_t count = texel_count(img, max_texels); /* (the same count) */
    ts_env_texel *texels = malloc(count * sizeof *texels);
    if (!texels)
        return ts_fail(err, TS_ERR_NOMEM, "no memory for the %zu texels of environment map '%s'",
                       count, name);
    double r = rotation_deg * (M_PI / 180.0);
    double cos_r = cos(r), sin_r = sin(r);
    size_t n = 0;
    for (int panel = 0; panel < p.panels; panel++)
        for (int by = 0; by < p.panel_h; by += k)
            for (int bx = 0; bx < p.panel_w; bx += k)
                for (int part = 0; part < q.nx * q.ny; part++) {
                    block_sum b;
                    memset(&b, 0, sizeof b);
                    q.ix = part % q.nx, q.iy = part / q.nx;
                    int y1 = by + k < p.panel_h ? by + k : p.panel_h;
                    int x1 = bx + k < p.panel_w ? bx + k : p.panel_w;
                    for (int y = by; y < y1; y++)
                        for (int x = bx; x < x1; x++) {
                            st = add_pixel(img, x, panel * p.panel_h + y, &q, &b, name, err);
                            if (st != TS_OK) {
                                free(texels);
                                return st;
                            }
                        }
                    block_texel(&b, cos_r, sin_r, &texels[n++]);
                }
    out->count = n;
    out->texels = texels;
    return ts_ok(err);
}

ts_status ts_env_from_latlong(const float *rgb, int width, int height, double rotation_deg,
                              ts_env *out, ts_error *err)
{
    env_image img = {rgb, width, height, ENV_LATLONG};
    return env_from_image(&img, rotation_deg, 0, "lat-long image", out, err);
}

ts_status ts_env_from_cube(const float *rgb, int face_size, double rotation_deg, ts_env *out,
                           ts_error *err)
{
    /* 6 * face_size overflowing int would wrap: refuse before multiplying */
    int height = face_size > 0 && face_size <= (1 << 26) ? 6 * face_size : 0;
    env_image img = {rgb, face_size, height, ENV_CUBE};
    return env_from_image(&img, rotation_deg, 0, "cube-face image", out, err);
}
