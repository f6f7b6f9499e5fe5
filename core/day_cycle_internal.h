/*
 * Internal helpers shared by the day products (day_sun.c, day_cycle.c,
 * clear_sky.c, sun_range.c). Not part of the public API.
 */
#ifndef TS_DAY_CYCLE_INTERNAL_H
#define TS_DAY_CYCLE_INTERNAL_H

#include "day_cycle.h"

/* Check the day options (horizon options with any direction count, Linke
 * turbidity, sun-hours rule); the message names what is wrong. */
ts_status ts_day_opts_check(const ts_day_opts *o, ts_error *err);

/* The horizon sweep of a day product: ts_horizon_sweep of `azimuth` with
 * options h into plane, then o->plane_hook (sun_elevation as it says). */
ts_status ts_day_sweep(const ts_grid *g, double azimuth, const ts_horizon_opts *h,
                       const ts_day_opts *o, double sun_elevation, float *plane,
                       ts_error *err);

/* The sun (SPA) at lattice node i of s at unix time t. */
ts_status ts_day_node_sun(const ts_sun_sites *s, const ts_day_opts *o, int i,
                          double t, ts_sun_sample *out, ts_error *err);

/* The sun at every node of s at unix time t into ns (nx * ny): the SPA's
 * part that depends on the instant computed once (ts_sun_position_from),
 * the same bits as ts_day_node_sun node by node. */
ts_status ts_day_nodes_sun(const ts_sun_sites *s, const ts_day_opts *o, double t,
                           ts_sun_sample *ns, ts_error *err);

/* The sun seen from every cell at an instant (sun_visibility.c): what
 * stays the same from one instant to the next. */
typedef struct {
    const ts_grid *g;
    const ts_sun_sites *s;
    const ts_day_opts *o;
    int W, H, nodes;
    size_t cells;
    float *floor;       /* Earth horizon per cell, or NULL (terrain only) */
    double floor_min;   /* the lowest horizon any cell can have */
    float *pa, *pb;     /* horizon planes */
    float *cel, *caz;   /* lattice: per-cell elevation and azimuth offset */
    ts_sun_sample *ns;  /* per-node sun */
    double *noff;       /* per-node azimuth from the reference's, unwrapped */
    /* lattice: planes at azimuth s * LATTICE_AZ_STEP kept from earlier
     * steps (NULL: not kept), and how many more may be */
    float **kept;
    int room;
} ts_vis_ctx;

/* keep: whether planes may be kept from one instant to the next (up to
 * o->plane_cache_bytes; 0 for a single instant, which has no next one).
 * Nothing to free on failure. */
ts_status ts_vis_init(ts_vis_ctx *c, const ts_grid *g, const ts_sun_sites *s,
                      const ts_day_opts *o, int keep, ts_error *err);
void ts_vis_free(ts_vis_ctx *c);

/* Visibility at instant t into vis; az/el (may be NULL) per cell, ref (may
 * be NULL) the reference node's sun. *dark = 1 when the sun is below every
 * cell's horizon (vis = 0 for valid cells), so callers may skip the step. */
ts_status ts_vis_step(ts_vis_ctx *c, double t, float *vis, float *az, float *el,
                      ts_sun_sample *ref, int *dark, ts_error *err);

/* Index of the reference node: the single site, or the lattice's middle. */
int ts_day_ref_node(const ts_sun_sites *s);

/* The Earth's horizon of every cell (ts_earth_horizon of its height, NaN
 * for nodata) into floor (width*height); returns the lowest, at most 0. */
double ts_day_earth_floor(const ts_grid *g, const ts_horizon_opts *o, float *floor);

/* Angles wrapped to [0, 360) and to (-180, 180]. */
double ts_wrap360(double a);
double ts_wrap180(double a);

/* ESRA pieces (clear_sky.c): Kasten & Young air mass at sea level for an
 * apparent elevation h > 0 (degrees); beam transmittance at air mass m;
 * diffuse transmittance times its angular function at sin(elevation). */
double ts_esra_air_mass(double h);
double ts_esra_beam_transmittance(double m, double linke);
double ts_esra_diffuse_factor(double linke, double sin_h);

#endif
