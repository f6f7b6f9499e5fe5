/* Where the sun is seen from: the DEM's centre, or a lattice of sites
 * (SUN_POSITION=per_cell) in longitude, latitude and the grid azimuth of
 * true north. */
#include "tsd_geodesy.h"

#include "tsd_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Longitude into [-180, 180]. */
static double wrap_lon(double lon)
{
    lon = fmod(lon + 180.0, 360.0);
    if (lon < 0)
        lon += 360.0;
    return lon - 180.0;
}

/* The lattice's nodes a side: every 32 cells or so, at most 65, unless
 * grow_sites asks for more; odd, so that the middle node, whose sun the
 * metadata reports, is the DEM's centre (with 2 nodes it was a corner). */
static int site_nodes(int cells, int at_least)
{
    if (cells < 2)
        return 1;
    int k = cells / 32 + 2;
    k = k > 65 ? 65 : k;
    k = k < at_least ? at_least : k;
    return k + (k % 2 == 0);
}

static void site_grid(tsd_sites *s, int width, int height)
{
    s->x0 = s->nx > 1 ? 0.5 : 0.5 * width;
    s->y0 = s->ny > 1 ? 0.5 : 0.5 * height;
    s->dx = s->nx > 1 ? (width - 1.0) / (s->nx - 1) : 1.0;
    s->dy = s->ny > 1 ? (height - 1.0) / (s->ny - 1) : 1.0;
}

/* The turn of a distant sun's grid azimuth from a place (lon, lat, grid
 * azimuth of true north) to another, degrees: its true azimuth turns with
 * the meridians, dlon sin(mid-latitude), its grid azimuth by that plus the
 * turn of grid north (they cancel on a conformal grid, not on a geographic
 * one near a pole). (The sum wrapped: across a pole dlon and the norths'
 * difference are each 180, and wrapped apart they added to 360.) */
static double sun_turn(double lon_a, double lat_a, double north_a, double lon_b, double lat_b,
                       double north_b)
{
    const double dlon = remainder(lon_b - lon_a, 360.0);
    return fabs(remainder(dlon * sin(0.5 * (lat_a + lat_b) * M_PI / 180.0) + north_b - north_a,
                          360.0));
}

/* Degrees of arc, about, between sites a and b, or the turn of the sun's
 * grid azimuth between them where that is larger: the sun's elevation and
 * azimuth curve with the hour angle and the latitude, so the bilinear
 * interpolation's error grows as the square of this. The turn is the
 * meridians' convergence, dlon sin(lat), less that of grid north (0 on a
 * geographic grid; nearly all of it on a conformal one): near a pole, sites
 * 2 degrees of arc apart may be tens of degrees of longitude apart, and
 * their suns' directions, interpolated between, came up to 7.6 deg too
 * high (session 56's audit of per_cell near the poles). */
static double site_step(const tsd_sites *s, size_t a, size_t b)
{
    const double mid = 0.5 * (s->lat[a] + s->lat[b]) * M_PI / 180.0;
    const double lat = fabs(s->lat[b] - s->lat[a]);
    const double lon = fabs(remainder(s->lon[b] - s->lon[a], 360.0)) * cos(mid);
    const double turn =
        sun_turn(s->lon[a], s->lat[a], s->north[a], s->lon[b], s->lat[b], s->north[b]);
    return fmax(fmax(lat, lon), turn);
}

/* Nodes a side so that neighbours lie at most SITE_MAX_STEP_DEG apart
 * (one per cell at most, SITE_MAX_NODES a side): on a DEM of coarse cells
 * or a continent, 32 cells can span tens of degrees, where interpolating
 * the sun across them put it below the horizon for hours at noon.
 * Returns 1 if nx or ny grew. */
#define SITE_MAX_STEP_DEG 2.0
#define SITE_MAX_NODES 181
static int finer_nodes(int nodes, double step, int cells)
{
    int cap = cells < SITE_MAX_NODES ? cells : SITE_MAX_NODES;
    if (step <= SITE_MAX_STEP_DEG || nodes >= cap)
        return nodes;
    int k = (nodes - 1) * (int)ceil(step / SITE_MAX_STEP_DEG) + 1;
    return k < cap ? k : cap;
}

static int grow_sites(const tsd_sites *s, int width, int height, int *nx, int *ny)
{
    double sx = 0, sy = 0;
    for (int j = 0; j < s->ny; j++)
        for (int i = 0; i < s->nx; i++) {
            size_t k = (size_t)j * s->nx + i;
            if (i + 1 < s->nx)
                sx = fmax(sx, site_step(s, k, k + 1));
            if (j + 1 < s->ny)
                sy = fmax(sy, site_step(s, k, k + s->nx));
        }
    *nx = site_nodes(width, finer_nodes(s->nx, sx, width));
    *ny = site_nodes(height, finer_nodes(s->ny, sy, height));
    return *nx != s->nx || *ny != s->ny;
}

/* The longitude, latitude and grid azimuth of true north of s's nodes. */
static ts_status sites_fill(const double gt[6], int width, int height, int geographic,
                            int rotated, double deg, double pm, const tsd_lonlat *ll,
                            const tsd_cells *cells, tsd_sites *s, char *msg, size_t n)
{
    size_t nodes = (size_t)s->nx * s->ny;
    s->lon = malloc(nodes * sizeof *s->lon);
    s->lat = malloc(nodes * sizeof *s->lat);
    s->north = malloc(nodes * sizeof *s->north);
    if (!s->lon || !s->lat || !s->north)
        return tsd_fail(msg, n, TS_ERR_NOMEM, "out of memory for %zu sun sites", nodes);
    ts_status rc = TS_OK;
    for (int j = 0; j < s->ny && rc == 0; j++)
        for (int i = 0; i < s->nx && rc == 0; i++) {
            /* core pixel -> DEM pixel -> georeferenced */
            double cx = s->x0 + i * s->dx, cy = s->y0 + j * s->dy;
            double px = cells->flip_x ? width - cx : cx;
            double py = cells->flip_y ? height - cy : cy;
            double X = gt[0] + px * gt[1] + py * gt[2];
            double Y = gt[3] + px * gt[4] + py * gt[5];
            double lon, lat, north = 0.0;
            if (geographic) {
                lon = X * deg + pm;
                lat = Y * deg;
            } else {
                double x = X, y = Y;
                if (!tsd_lonlat_to(ll, 1, &x, &y, NULL) || !isfinite(x) || !isfinite(y)) {
                    rc = tsd_fail(msg, n, TS_ERR_ARG,
                                  "PROJ cannot find the longitude and latitude of "
                                  "the DEM's point (%.10g, %.10g), so the sun's position "
                                  "over it is unknown", X, Y);
                    break;
                }
                lon = x;
                lat = y;
                /* grid azimuth of true north: a small step north, back */
                double step = lat + 1e-4 <= 90.0 ? 1e-4 : -1e-4;
                double x2 = lon, y2 = lat + step;
                if (!tsd_lonlat_from(ll, 1, &x2, &y2, NULL) || !isfinite(x2) || !isfinite(y2)) {
                    rc = tsd_fail(msg, n, TS_ERR_ARG,
                                  "PROJ cannot transform a point north of (%.8g, "
                                  "%.8g) back into the DEM's CRS", lon, lat);
                    break;
                }
                double dx = (x2 - X) * (step > 0 ? 1 : -1), dy = (y2 - Y) * (step > 0 ? 1 : -1);
                if (rotated) /* degrees of a rotated pole: east-west ones shrink */
                    dx *= cos(Y * deg * M_PI / 180.0);
                north = atan2(dx, dy) * 180.0 / M_PI;
            }
            if (!isfinite(lat) || lat < -90.0 - 1e-9 || lat > 90.0 + 1e-9) {
                rc = tsd_fail(msg, n, TS_ERR_ARG,
                              "the DEM's georeferencing puts a point at latitude %g, "
                              "beyond +/-90 degrees: the geotransform or the CRS is wrong",
                              lat);
                break;
            }
            lat = lat > 90.0 ? 90.0 : lat < -90.0 ? -90.0 : lat;
            size_t k = (size_t)j * s->nx + i;
            s->lon[k] = wrap_lon(lon);
            s->lat[k] = lat;
            s->north[k] = north;
        }
    return rc;
}

ts_status tsd_sites_compute(const double gt[6], int width, int height,
                      OGRSpatialReferenceH srs, const tsd_cells *cells, int per_cell,
                      tsd_sites *s, char *msg, size_t n)
{
    memset(s, 0, sizeof *s);
    if (!srs)
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM has no CRS, so the sun's position over it is "
                    "unknown: give it a CRS (gdal_edit.py -a_srs) or, for shade and "
                    "shadow, use SUN_AZIMUTH and SUN_ELEVATION");
    /* a rotated pole (a derived geographic CRS: CORDEX's, COSMO's) counts
     * in degrees that are not longitudes and latitudes: through PROJ, as a
     * projection */
    const int derived = OSRIsDerivedGeographic(srs);
    const int geographic = OSRIsGeographic(srs) && !derived;
    if (!geographic && !derived && !OSRIsProjected(srs))
        return tsd_fail(msg, n, TS_ERR_ARG, "the DEM's CRS is neither geographic nor projected (a "
                    "local or engineering CRS), so its longitudes and latitudes are "
                    "unknown: give it a geographic or projected CRS (gdal_edit.py -a_srs) or, "
                    "for shade and shadow, use SUN_AZIMUTH and SUN_ELEVATION instead");
    tsd_lonlat ll = {0};
    if (!geographic && !tsd_lonlat_open(srs, 1, &ll))
        return tsd_fail(msg, n, TS_ERR_ARG, "PROJ cannot transform the DEM's CRS to longitude and "
                    "latitude, so the sun's position over it is unknown");
    double deg = 1.0, pm = 0.0; /* a geographic CRS's unit and prime meridian */
    if (geographic || derived)
        tsd_geographic_units(srs, &deg, &pm);
    int nx = per_cell ? site_nodes(width, 1) : 1, ny = per_cell ? site_nodes(height, 1) : 1;
    ts_status rc;
    /* a finer lattice where the first one's nodes lie too far apart (the
     * second pass's spacing follows the first's, so it rarely grows again) */
    for (int pass = 0;; pass++) {
        s->nx = nx;
        s->ny = ny;
        site_grid(s, width, height);
        rc = sites_fill(gt, width, height, geographic, derived, deg, pm, &ll, cells, s, msg, n);
        if (rc != TS_OK || !per_cell || pass == 3 || !grow_sites(s, width, height, &nx, &ny))
            break;
        tsd_sites_free(s);
    }
    tsd_lonlat_close(&ll);
    if (rc != TS_OK)
        tsd_sites_free(s);
    return rc;
}

double tsd_sites_reach(const double gt[6], int width, int height, OGRSpatialReferenceH srs,
                       const tsd_cells *cells, double lon0, double lat0, double *turn)
{
    tsd_sites s;
    char msg[256];
    if (turn)
        *turn = 0;
    if (tsd_sites_compute(gt, width, height, srs, cells, 1, &s, msg, sizeof msg) != TS_OK)
        return 0;
    const double rad = M_PI / 180;
    const double north0 = s.north[(size_t)(s.ny / 2) * s.nx + s.nx / 2]; /* the centre's */
    double reach = 0, most = 0;
    for (size_t k = 0; k < (size_t)s.nx * s.ny; k++) {
        /* the central angle, by the haversine (well conditioned when small) */
        double sp = sin((s.lat[k] - lat0) * rad / 2), sl = sin((s.lon[k] - lon0) * rad / 2);
        double a = sp * sp + cos(s.lat[k] * rad) * cos(lat0 * rad) * sl * sl;
        double angle = 2 * asin(sqrt(a < 1 ? a : 1)) / rad;
        reach = angle > reach ? angle : reach;
        double t = sun_turn(lon0, lat0, north0, s.lon[k], s.lat[k], s.north[k]);
        most = t > most ? t : most;
    }
    tsd_sites_free(&s);
    if (turn)
        *turn = most;
    return reach;
}

void tsd_sites_free(tsd_sites *s)
{
    if (!s)
        return;
    free(s->lon);
    free(s->lat);
    free(s->north);
    s->lon = s->lat = s->north = NULL;
}
