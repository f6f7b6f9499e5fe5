/* The rows of the option table: one per option, with the field it fills. */
#include "tsd_option_table.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "day_cycle.h"
#include "terrashade_env.h"
#include "tsd_compute_env.h"
#include "tsd_datetime.h"
#include "tsd_text.h"
#include "tsd_window.h"

#define FIELD(f) offsetof(tsd_options, f), sizeof(((tsd_options *)0)->f)
#define P TSD_SCOPE_PRODUCT
#define A TSD_SCOPE_ATLAS
#define ALL TSD_APPLIES_ALL
#define LISTED TSD_APPLIES_LISTED

/* a text option's reading (opt_read_fn): its check and its meaning */
#define READER(f) static int f(const char *v, char *meaning, size_t mn, char *msg, size_t n)
READER(check_datetime);
READER(check_date);
READER(check_start_date);
READER(check_end_date);
READER(check_timezone);
READER(check_sky);
READER(check_exposure);
READER(check_tile_size);
READER(check_light_radius);

const opt_def TSD_OPTION_ROWS[] = {
    {"PRODUCT", K_PRODUCT, FIELD(product), "shade", 0, 0, 0, 0, NULL, 1, P,
     TSD_APPLIES_SELECTOR, NULL,
     "What to compute: " /* then each product's name (description) */},
    {"SUN_AZIMUTH", K_FLOAT, FIELD(sun_azimuth), "315", 0, 360, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Sun azimuth in degrees clockwise from (grid) north (as gdaldem -az); "
     "not with DATETIME"},
    {"SUN_ELEVATION", K_FLOAT, FIELD(sun_elevation), "45", -90, 90, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "Sun elevation in degrees above the horizontal (as gdaldem -alt); not "
     "with DATETIME"},
    {"DIRECTIONS", K_INT, FIELD(directions), "16", 1, 3600, 0, 1, NULL, 1, P, LISTED, NULL,
     "Number of azimuths of the horizon, svf, openness, sky and envlight "
     "products and of the sky terms of shade and insolation"},
    {"START_AZIMUTH", K_FLOAT, FIELD(start_azimuth), "0", 0, 360, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "First of the DIRECTIONS azimuths, degrees from north; the others "
     "follow every 360/DIRECTIONS degrees"},
    {"METHOD", K_SELECT, FIELD(method), "exact", 0, 0, 0, 0, "exact|shm|shadowmap|sh", 1, P,
     LISTED, NULL,
     "Shadow method of shade and shadow: exact (horizon sweep, penumbra "
     "from the light's disk), shm (shadow height map, faster, approximate), "
     "shadowmap (orthographic depth map from the light with "
     "percentage-closer filtering, approximate) or sh (order-4 spherical "
     "harmonics, Snyder & Nowrouzezahrai 2008: a soft key light of "
     "LIGHT_RADIUS from SWATH_DIRECTIONS horizon sweeps)"},
    {"PENUMBRA_DEPTH", K_FLOAT, FIELD(penumbra_depth), "0", 0, 1e6, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "METHOD=shm: metres below the shadow height over which light fades; "
     "0 = hard shadows"},
    {"LIGHT_RADIUS", K_FLOAT, FIELD(light_radius), "0.2666", 0, 45, 1, 1, NULL, 1, P,
     LISTED, check_light_radius,
     "Angular radius of the light's disk in degrees, greater than 0 and less "
     "than 45; 0.2666 = the sun. A wider disk casts softer shadows"},
    {"SWATH_DIRECTIONS", K_INT, FIELD(swath_directions), "3", 1, 3600, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "METHOD=sh: horizon sweeps across the azimuths the light's disk covers "
     "(its partial swath)"},
    {"SHADOWMAP_SCALE", K_FLOAT, FIELD(shadowmap_scale), "2", 0.25, 8, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "METHOD=shadowmap: depth-map texels per DEM cell along each axis "
     "(0.25 to 8); 2 samples the terrain twice as finely as the DEM"},
    {"PCF_KERNEL", K_FLOAT_AUTO, FIELD(pcf_kernel), "auto", 0, 64, 1, 1, "auto", 1, P,
     LISTED, NULL,
     "METHOD=shadowmap: width of the percentage-closer filter in DEM cells "
     "(greater than 0, at most 64), or auto: the width of the penumbra of "
     "the LIGHT_RADIUS disk at the occluder's distance read from the depth "
     "map, so shadows soften away from their caster"},
    {"Z_FACTOR", K_FLOAT_AUTO, FIELD(z_factor), "AUTO", 0, 1e6, 1, 1, "AUTO", 1, P, ALL,
     NULL,
     "Multiplies the heights: AUTO (from the vertical unit of the DEM's CRS, "
     "else the band's unit: 0.3048 for feet, 1200/3937 for US survey feet, "
     "0.01 for centimetres, 1 for metres or no unit) or a number > 0 and <= 1e6; the band's scale "
     "and offset are applied first"},
    {"CELL_SIZES", K_SELECT, FIELD(cell_sizes), "auto", 0, 0, 0, 0, "auto|grid|ground", 1,
     P, ALL, NULL,
     "How a projected DEM's cells are measured: grid (the geotransform's "
     "pixel size in the CRS's unit, as gdaldem), ground (geodesic distances "
     "on the ellipsoid: east-west per row, north-south over the DEM, as for "
     "a geographic CRS) or auto: ground where the projection's scale on the "
     "DEM departs from 1 by more than 1 % (Web Mercator beyond ~8 degrees of "
     "latitude), else grid"},
    {"MAX_DISTANCE", K_FLOAT, FIELD(max_distance), "0", 0, 1e8, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Largest distance in metres at which terrain can cast a shadow or "
     "raise the horizon; 0 = unbounded"},
    {"CURVATURE", K_BOOL, FIELD(curvature), "YES", 0, 0, 0, 0, NULL, 1, P, ALL, NULL,
     "Take Earth curvature (with refraction) into account"},
    {"REFRACTION", K_FLOAT, FIELD(refraction), TSD_XSTR(TSD_REFRACTION_DEFAULT), 0, 1, 0, 1,
     NULL, 1, P, ALL, NULL,
     "Refraction coefficient k of the curvature correction: drop = (1-k) "
     "d^2 / 2R"},
    {"SKY_WEIGHT", K_FLOAT, FIELD(sky_weight), "0", 0, 1, 0, 1, NULL, 1, P, LISTED, NULL,
     "shade only: weight of the light of a uniform sky added to the direct "
     "sun (shade = direct + SKY_WEIGHT * sky); 0 = sun only, as gdaldem"},
    {"BAND", K_INT, FIELD(band), "1", 1, 65536, 0, 1, NULL, 1, P, ALL, NULL,
     "Band of the DEM holding the heights"},
    {"THREADS", K_INT, FIELD(threads), "0", 0, 1024, 0, 1, NULL, 0, P | A, ALL, NULL,
     "Worker threads; 0 = one per CPU core"},
    {"OUTPUT_TYPE", K_SELECT, FIELD(output_type), "AUTO", 0, 0, 0, 0, "AUTO|Byte|Float32",
     1, P, LISTED, NULL,
     "Data type: Byte (1..255, 0 = nodata, as gdaldem; farshadow 0/1, 255 = "
     "nodata) or Float32 (the product's own unit: 0..1, degrees, hours, Wh/m2 "
     "or E/pi; NaN = nodata); AUTO = Byte for shade (and farshadow, Byte "
     "only), Float32 otherwise. Byte only for the 0..1 products (shade, "
     "shadow, svf, sky, daycycle, envlight)"},
    {"MAX_MEMORY", K_INT, FIELD(max_memory_mb), "0", 0, 1 << 30, 0, 1, NULL, 0, P, ALL,
     NULL,
     "Refuse to compute a product needing more than this many MiB; 0 = "
     "three quarters of the physical memory"},
    {"TILE_SIZE", K_INT, FIELD(tile_size), "4096", 0, 1 << 20, 0, 1, NULL, 0, P, LISTED,
     check_tile_size,
     "Compute the product in chunks of this many cells square, each from the DEM "
     "around it (NEAR_DISTANCE) and one coarse grid of the whole DEM, so that "
     "memory grows with the chunk and the DEM's width (a row of chunks is cached), "
     "not with its size (docs/windows.md); 0 = the whole DEM "
     "at once, as does a DEM within one chunk. At least 64"},
    {"NEAR_DISTANCE", K_FLOAT, FIELD(near_distance), "0", 0, TSD_NEAR_MAX_M, 0, 1, NULL, 1, P,
     LISTED,
     NULL,
     "Chunks (TILE_SIZE): metres within which occluders come from the "
     "full-resolution DEM, exactly; farther ones from a coarser grid "
     "(the DEM's overviews or an averaged read). 0 = 128 cells (of a cell's "
     "longer side), or 32 cells of the far grid where that is longer (a DEM of "
     "more than 2048 x 2048 far cells)"},
    {"DATETIME", K_TEXT, FIELD(datetime), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_datetime,
     "Place the sun by date and time (SPA) instead of SUN_AZIMUTH and "
     "SUN_ELEVATION: ISO 8601 with an offset, e.g. 2026-06-21T07:30:00+02:00 "
     "or 2026-06-21T05:30Z (inline: 2026-06-21T073000+0200). With the day "
     "products: the local day that contains it"},
    {"DATE", K_TEXT, FIELD(date), "", 0, 0, 0, 0, NULL, 1, P, LISTED, check_date,
     "Day of sunhours, insolation, daycycle and farshadow: YYYY-MM-DD, local "
     "to TIMEZONE"},
    {"START_DATE", K_TEXT, FIELD(start_date), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_start_date,
     "sunhours, insolation: first day of a date range, YYYY-MM-DD local to "
     "TIMEZONE; the product is the total over the range (not with DATE)"},
    {"END_DATE", K_TEXT, FIELD(end_date), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_end_date,
     "sunhours, insolation: last day of the date range, inclusive; default "
     "START_DATE"},
    {"TIMEZONE", K_TEXT, FIELD(timezone), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_timezone,
     "Fixed offset from UTC of the local day: Z or UTC, +hh:mm, -hh:mm, +hhmm, "
     "+hh; "
     "needed with DATE; with DATETIME it defaults to DATETIME's offset"},
    {"STEP_MINUTES", K_INT, FIELD(step_minutes), "5", 1, 240, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Time step of sunhours, insolation and daycycle, minutes; default 5 for "
     "one day, 30 for a date range (START_DATE)"},
    {"DAY_INTERVAL", K_INT, FIELD(day_interval), TSD_XSTR(TS_RANGE_DAY_INTERVAL), 1, 366, 0,
     1, NULL, 1, P, LISTED, NULL,
     "Date range (START_DATE): the range is cut into blocks of DAY_INTERVAL "
     "days; the middle day of each is computed and stands for the block"},
    {"HORIZON_DIRECTIONS", K_INT, FIELD(horizon_directions),
     TSD_XSTR(TS_RANGE_HORIZON_DIRECTIONS), 4, 3600, 0, 1, NULL, 1, P, LISTED, NULL,
     "Date range (START_DATE): azimuths at which the horizons are swept once, every "
     "360/HORIZON_DIRECTIONS degrees from grid north; each sun position uses the two nearest"},
    /* the ranges where the SPA's refraction (Bennett / Saemundsson form)
     * holds: the air at the Earth's surface (docs/driver.md) */
    {"PRESSURE", K_FLOAT, FIELD(pressure), "1013.25", 300, 1100, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "Mean air pressure at the DEM, hPa (atmospheric refraction of the sun); "
     "300 (above Everest's summit) to 1100 (above 1084, the highest recorded at "
     "sea level)"},
    {"TEMPERATURE", K_FLOAT, FIELD(temperature), "15", -90, 60, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "Mean air temperature at the DEM, degrees Celsius (atmospheric "
     "refraction of the sun); -90 to 60, the recorded extremes at the "
     "Earth's surface"},
    {"DELTA_T", K_FLOAT, FIELD(delta_t), "69", -8000, 8000, 0, 1, NULL, 1, P, LISTED, NULL,
     "TT - UT in seconds (about 69 in the 2020s)"},
    {"SUN_POSITION", K_SELECT, FIELD(sun_position), "center", 0, 0, 0, 0,
     "center|per_cell", 1, P, LISTED, NULL,
     "Where the sun is computed from: the DEM's centre (center), or every "
     "cell (per_cell: the SPA on a lattice over the DEM, interpolated), for "
     "extents of a degree or more"},
    {"LINKE_TURBIDITY", K_FLOAT, FIELD(linke_turbidity), "3", 1, 10, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "Linke turbidity factor of the clear-sky model of insolation (2 very "
     "clear, 3 clear, 5 hazy)"},
    {"FAR_THRESHOLD", K_INT, FIELD(far_threshold), "512", 1, 1000000, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "farshadow: occluders nearer than this many cells are left out (they "
     "are recomputed on read)"},
    {"ATLAS_STEPS", K_INT, FIELD(atlas_steps), "158", 1, 1024, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "farshadow: number of sun positions between sunrise and sunset, denser "
     "near dawn and dusk"},
    {"BACKEND", K_SELECT, FIELD(backend), "auto", 0, 0, 0, 0, "auto|opencl|c", 0, P,
     LISTED, NULL,
     "Where the horizon sweeps, shadow height maps, normals and direct sun "
     "of shade, shadow, horizon, svf, openness, sky and envlight run: opencl (falls "
     "back to c, with a warning, when OpenCL cannot run), c (the "
     "multithreaded C core), or auto (the environment variable "
     "TERRASHADE_BACKEND, else OpenCL on a GPU or accelerator or on a device "
     "named by TERRASHADE_OPENCL_DEVICE, else c). The metadata item BACKEND "
     "says what ran"},
    {"SUNHOURS_RULE", K_SELECT, FIELD(sunhours_fraction), "visible", 0, 0, 0, 0,
     "visible|fraction", 1, P, LISTED, NULL,
     "sunhours: what a time step counts: visible (the whole step while any "
     "part of the sun's disk is above the cell's horizon; on a flat plane "
     "the astronomical day length, sunrise to sunset by the upper limb) or "
     "fraction (the step times the visible fraction of the disk; on a flat "
     "plane the time the sun's centre is up)"},
    {"PROGRESS", K_SELECT, FIELD(progress_mode), "auto", 0, 0, 0, 0, "auto|yes|no", 0, P,
     ALL, NULL,
     "Print the progress of the computation to stderr: yes, no, or auto "
     "(when stderr is a terminal and the computation takes more than a "
     "second)"},
    /* environment light (tsd_compute_env.c, docs/envlight.md) */
    {"ENV_MAP", K_TEXT, FIELD(env_map), "", 0, 0, 0, 0, NULL, 1, P, LISTED, NULL,
     "OpenEXR environment map lighting envlight (or the sky term of shade): a "
     "lat-long (2:1) or cube-face (1:6) map, any GDAL path (/vsicurl/, "
     "/vsimem/...); not with SKY"},
    {"ENV_ROTATION", K_FLOAT, FIELD(env_rotation), "0", 0, 360, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "ENV_MAP: degrees by which the environment turns clockwise seen from "
     "above; at 0 the map's centre column is grid north, east to its right"},
    {"SKY", K_TEXT, FIELD(sky), "", 0, 0, 0, 0, NULL, 1, P, LISTED, check_sky,
     "A standard sky lighting envlight (or the sky term of shade): uniform, "
     "overcast (CIE standard overcast), clear (CIE standard clear) or cie:N "
     "(CIE general sky type N, 1..15; inline: cieN), the sun from SUN_AZIMUTH and "
     "SUN_ELEVATION or DATETIME; not with ENV_MAP"},
    {"ENV_HORIZON_STEPS", K_INT, FIELD(env_horizon_steps),
     TSD_XSTR(TS_ENV_DEFAULT_HORIZON_STEPS), 3, 3601, 0, 1, NULL, 1, P, LISTED, NULL,
     "ENV_MAP, SKY: nodes of the light table's horizon-angle axis over -90..90 "
     "degrees, odd (a node at 0); 181: one degree"},
    {"ENV_NORMAL_STEPS", K_INT, FIELD(env_normal_steps),
     TSD_XSTR(TS_ENV_DEFAULT_NORMAL_STEPS), 0, 1025, 0, 1, NULL, 1, P, LISTED, NULL,
     "ENV_MAP, SKY: nodes of the light table's normal-angle axis (odd, 3 or "
     "more, bilinear as Timonen), or 0: exact in the normal angle (more "
     "accurate, smaller, faster)"},
    {"EXPOSURE", K_TEXT, FIELD(exposure), "", 0, 0, 0, 0, NULL, 1, P, LISTED,
     check_exposure,
     "envlight with OUTPUT_TYPE=Byte: stops by which the light is scaled (x "
     "2^EXPOSURE) before the sRGB curve; AUTO (the default): the brightest "
     "unshadowed surface of any slope and aspect maps to 255"},

    {"ENV_METHOD", K_SELECT, FIELD(env_method), "table", 0, 0, 0, 0, "table|sh", 1, P,
     LISTED, NULL,
     "envlight: table (Timonen's L_p per azimuth from the exact horizons) or "
     "sh (order-4 spherical harmonics, Snyder & Nowrouzezahrai 2008: light, "
     "visibility wedges and clamped cosine as 16 coefficients, approximate)"},

    {"SVF_MODEL", K_SELECT, FIELD(svf_model), "radiative", 0, 0, 0, 0,
     "radiative|solid_angle", 1, P, LISTED, NULL,
     "svf: radiative (Timonen eq. 5 with the cell's normal: the "
     "cosine-weighted visible sky, the light a tilted surface gets from a "
     "uniform sky) or solid_angle (Zaksek et al. 2011, as RVT_py and "
     "GRASS r.skyview: 1 - mean sin(max(horizon, 0)), relative to the "
     "horizontal)"},
    {"OPENNESS", K_SELECT, FIELD(openness_negative), "positive", 0, 0, 0, 0,
     "positive|negative", 1, P, LISTED, NULL,
     "openness: positive (Yokoyama et al. 2002: mean over directions of 90 - "
     "the horizon elevation angle) or negative (the same on the negated DEM, "
     "as RVT_py: high in valleys and pits)"},
    {"EDGE", K_SELECT, FIELD(edge), "horizon", 0, 0, 0, 0, "horizon|open|nodata", 1, P,
     LISTED, NULL,
     "What lies beyond the DEM's edge for a ray that leaves it (within "
     "MAX_DISTANCE): horizon (the sea-level surface of the Earth, with "
     "CURVATURE and REFRACTION: nothing below the Earth's horizon lights a "
     "cell), open (an open sky down to -90 degrees) or nodata (such cells are "
     "nodata)"},
    /* pyramid horizons (tsd_pyramid.c, docs/methods.md) */
    {"HORIZON_METHOD", K_SELECT, FIELD(horizon_method), "exact", 0, 0, 0, 0, "exact|pyramid",
     1, P, LISTED, NULL,
     "How the horizons of horizon, svf, openness, sky, envlight, the sky term "
     "of shade and METHOD=sh's key light are found: exact (the sweep) or pyramid "
     "(Snyder & Nowrouzezahrai "
     "2008: a multi-resolution pyramid, approximate, smoother with distance; "
     "PYRAMID_LEVEL_STEP, PYRAMID_OFFSET; runs on the C backend)"},
    {"PYRAMID_LEVEL_STEP", K_FLOAT, FIELD(pyramid_level_step), "4", 1, 16, 0, 1, NULL, 1, P,
     LISTED, NULL,
     "HORIZON_METHOD=pyramid: level step k, the pyramid's levels per halving of "
     "resolution (b = 2^(1/k)), 1 (power of 2) to 16; more levels are smoother "
     "and slower"},
    {"PYRAMID_OFFSET", K_FLOAT, FIELD(pyramid_offset), "0", 0, 64, 0, 1, NULL, 1, P, LISTED,
     NULL,
     "HORIZON_METHOD=pyramid: level offset o, 0 to 64: each distance reads the "
     "level k*o finer, so horizons are sharper and closer to exact (docs/methods.md "
     "gives the error per offset)"},
    /* options of atlas files (*.tsa) only */
    {"SHADOWS", K_SELECT, FIELD(shadows_all), "far", 0, 0, 0, 0, "far|all", 0, A, LISTED,
     NULL,
     "Atlas files (.tsa) only: far (the stored far shadows) or all (far "
     "shadows OR near shadows recomputed from the DEM on read)"},
    {"DEM", K_TEXT, FIELD(dem), "", 0, 0, 0, 0, NULL, 0, A, LISTED, NULL,
     "Atlas files (.tsa) with SHADOWS=all: the DEM to recompute the near "
     "shadows from (default: the SOURCE_DEM the atlas records)"},
};


const int TSD_OPTION_COUNT = (int)(sizeof TSD_OPTION_ROWS / sizeof TSD_OPTION_ROWS[0]);


/* tsd_options.given has a bit per option */
_Static_assert(sizeof TSD_OPTION_ROWS / sizeof TSD_OPTION_ROWS[0] <= 64,
               "too many options for tsd_options.given");
/* select fields are enums written through int pointers */
_Static_assert(sizeof(tsd_method) == sizeof(int) && sizeof(tsd_output_type) == sizeof(int) &&
                   sizeof(tsd_sun_position) == sizeof(int) &&
                   sizeof(tsd_backend) == sizeof(int) &&
                   sizeof(tsd_horizon_method) == sizeof(int) &&
                   sizeof(tsd_progress_mode) == sizeof(int) &&
                   sizeof(tsd_env_method) == sizeof(int),
               "enum options are int-sized");

/* Writes a reading's meaning where one is asked for. */
static void say_meaning(char *meaning, size_t mn, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void say_meaning(char *meaning, size_t mn, const char *fmt, ...)
{
    if (!meaning || mn == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(meaning, mn, fmt, ap);
    va_end(ap);
}

/* DATETIME: the instant and its offset (the offset names a day product's
 * day), so that the basic and extended forms mean the same. */
READER(check_datetime)
{
    char norm[TSD_TEXT_MAX * 2];
    double t;
    int offset;
    ts_error err;
    tsd_datetime_normalise(v, norm, sizeof norm);
    if (ts_parse_iso8601(norm, &t, &offset, &err) != TS_OK)
        return (tsd_fail_core(msg, n, "DATETIME", &err), -1);
    say_meaning(meaning, mn, "%.17g %d", t, offset);
    return 0;
}

/* A date option's value, its name in the sentence. */
static int read_named_date(const char *name, const char *v, char *meaning, size_t mn,
                           char *msg, size_t n)
{
    int y, m, d;
    ts_error err;
    if (ts_parse_date(v, &y, &m, &d, &err) != TS_OK)
        return (tsd_fail_core(msg, n, name, &err), -1);
    say_meaning(meaning, mn, "%d-%d-%d", y, m, d);
    return 0;
}

READER(check_date)
{
    return read_named_date("DATE", v, meaning, mn, msg, n);
}

READER(check_start_date)
{
    return read_named_date("START_DATE", v, meaning, mn, msg, n);
}

READER(check_end_date)
{
    return read_named_date("END_DATE", v, meaning, mn, msg, n);
}

/* TIMEZONE: minutes east of UTC (-0500 and -05:00 alike). */
READER(check_timezone)
{
    int off;
    ts_error err;
    if (ts_parse_utc_offset(v, &off, &err) != TS_OK)
        return (tsd_fail_core(msg, n, "TIMEZONE", &err), -1);
    say_meaning(meaning, mn, "%d", off);
    return 0;
}

/* SKY: its kind and CIE type (cie9 and cie:9 alike). */
READER(check_sky)
{
    ts_sky_kind kind;
    int type;
    ts_error err;
    if (ts_sky_parse(v, &kind, &type, &err) != TS_OK) /* its sentence names SKY */
        return (tsd_fail_core(msg, n, NULL, &err), -1);
    say_meaning(meaning, mn, "%d:%d", (int)kind, type);
    return 0;
}

/* EXPOSURE: AUTO or the stops as a number (1 and 1.0 alike). */
READER(check_exposure)
{
    double stops;
    int autoexp = tsd_exposure_parse(v, &stops);
    if (autoexp < 0)
        return (tsd_fail(msg, n, TS_ERR_ARG,
                         "EXPOSURE must be AUTO or a number of stops between %g and %g, "
                         "got '%s'", -TSD_EXPOSURE_MAX, TSD_EXPOSURE_MAX, v),
                -1);
    if (autoexp)
        say_meaning(meaning, mn, "auto");
    else
        say_meaning(meaning, mn, "%.17g", stops);
    return 0;
}

int tsd_option_meaning(int id, const char *v, char *out, size_t n)
{
    char msg[256];
    if (id < 0 || id >= TSD_OPTION_COUNT || TSD_OPTION_ROWS[id].kind != K_TEXT ||
        !TSD_OPTION_ROWS[id].read || n == 0)
        return -1;
    out[0] = '\0';
    if (TSD_OPTION_ROWS[id].read(v, out, n, msg, sizeof msg) != 0 || !out[0])
        return -1;
    return 0;
}

/* TILE_SIZE: 0, or a chunk no smaller than TSD_TILE_MIN (its margin would
 * cost more than the chunk). */
READER(check_tile_size)
{
    (void)meaning, (void)mn; /* a number: compared as one */
    char *end;
    long t = strtol(v, &end, 10);
    if (*end == '\0' && t > 0 && t < TSD_TILE_MIN) {
        tsd_fail(msg, n, TS_ERR_ARG, "TILE_SIZE must be 0 (the whole DEM) or at least %d "
                 "cells, got %s", TSD_TILE_MIN, v);
        return -1;
    }
    return 0;
}

/* LIGHT_RADIUS: the open interval (0, 45), whose upper end the table's
 * inclusive bounds cannot say; one sentence for a value below, at or above
 * it (not a number: the kind's check says so). */
READER(check_light_radius)
{
    (void)meaning, (void)mn; /* a number: compared as one */
    double r;
    if (tsd_parse_decimal(v, &r) != 0 || (r > 0 && r < TS_LIGHT_RADIUS_MAX))
        return 0;
    tsd_fail(msg, n, TS_ERR_ARG, "LIGHT_RADIUS must be greater than 0 and less than %g "
             "degrees, got %s", TS_LIGHT_RADIUS_MAX, v);
    return -1;
}

