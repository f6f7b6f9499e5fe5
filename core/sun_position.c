/*
 * Solar Position Algorithm (SPA): Reda, I. and Andreas, A., "Solar Position
 * Algorithm for Solar Radiation Applications", NREL/TP-560-34302, 2004
 * (revised 2008). Implemented from the paper's equations (numbers in the
 * comments) and its tables A4.2 (Earth periodic terms, an abridgement of
 * VSOP87 as in Meeus, "Astronomical Algorithms", Appendix III) and A4.3
 * (periodic terms for the nutation, the IAU 1980 theory as in Meeus, table
 * 22.A). NREL's C code is not used.
 */
#include <math.h>
#include <stddef.h>

#include "status_internal.h"
#include "terrashade_sun.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)
#define RAD (180.0 / PI)

/* Sun's angular radius used with atmos_refraction (paper, A.2). */
#define SPA_SUN_RADIUS 0.26667

/* ------------------------------------------------- table A4.2: Earth */

/* One periodic term: A cos(B + C * JME) (eq. 9). */
typedef struct {
    double a, b, c;
} term;

#define COUNT(t) (sizeof(t) / sizeof((t)[0]))

static const term L0[] = {
    {175347046.0, 0.0, 0.0},
    {3341656.0, 4.6692568, 6283.07585},
    {34894.0, 4.6261, 12566.1517},
    {3497.0, 2.7441, 5753.3849},
    {3418.0, 2.8289, 3.5231},
    {3136.0, 3.6277, 77713.7715},
    {2676.0, 4.4181, 7860.4194},
    {2343.0, 6.1352, 3930.2097},
    {1324.0, 0.7425, 11506.7698},
    {1273.0, 2.0371, 529.691},
    {1199.0, 1.1096, 1577.3435},
    {990.0, 5.233, 5884.927},
    {902.0, 2.045, 26.298},
    {857.0, 3.508, 398.149},
    {780.0, 1.179, 5223.694},
    {753.0, 2.533, 5507.553},
    {505.0, 4.583, 18849.228},
    {492.0, 4.205, 775.523},
    {357.0, 2.92, 0.067},
    {317.0, 5.849, 11790.629},
    {284.0, 1.899, 796.298},
    {271.0, 0.315, 10977.079},
    {243.0, 0.345, 5486.778},
    {206.0, 4.806, 2544.314},
    {205.0, 1.869, 5573.143},
    {202.0, 2.458, 6069.777},
    {156.0, 0.833, 213.299},
    {132.0, 3.411, 2942.463},
    {126.0, 1.083, 20.775},
    {115.0, 0.645, 0.98},
    {103.0, 0.636, 4694.003},
    {102.0, 0.976, 15720.839},
    {102.0, 4.267, 7.114},
    {99.0, 6.21, 2146.17},
    {98.0, 0.68, 155.42},
    {86.0, 5.98, 161000.69},
    {85.0, 1.3, 6275.96},
    {85.0, 3.67, 71430.7},
    {80.0, 1.81, 17260.15},
    {79.0, 3.04, 12036.46},
    {75.0, 1.76, 5088.63},
    {74.0, 3.5, 3154.69},
    {74.0, 4.68, 801.82},
    {70.0, 0.83, 9437.76},
    {62.0, 3.98, 8827.39},
    {61.0, 1.82, 7084.9},
    {57.0, 2.78, 6286.6},
    {56.0, 4.39, 14143.5},
    {56.0, 3.47, 6279.55},
    {52.0, 0.19, 12139.55},
    {52.0, 1.33, 1748.02},
    {51.0, 0.28, 5856.48},
    {49.0, 0.49, 1194.45},
    {41.0, 5.37, 8429.24},
    {41.0, 2.4, 19651.05},
    {39.0, 6.17, 10447.39},
    {37.0, 6.04, 10213.29},
    {37.0, 2.57, 1059.38},
    {36.0, 1.71, 2352.87},
    {36.0, 1.78, 6812.77},
    {33.0, 0.59, 17789.85},
    {30.0, 0.44, 83996.85},
    {30.0, 2.74, 1349.87},
    {25.0, 3.16, 4690.48},
};

static const term L1[] = {
    {628331966747.0, 0.0, 0.0},
    {206059.0, 2.678235, 6283.07585},
    {4303.0, 2.6351, 12566.1517},
    {425.0, 1.59, 3.523},
    {119.0, 5.796, 26.298},
    {109.0, 2.966, 1577.344},
    {93.0, 2.59, 18849.23},
    {72.0, 1.14, 529.69},
    {68.0, 1.87, 398.15},
    {67.0, 4.41, 5507.55},
    {59.0, 2.89, 5223.69},
    {56.0, 2.17, 155.42},
    {45.0, 0.4, 796.3},
    {36.0, 0.47, 775.52},
    {29.0, 2.65, 7.11},
    {21.0, 5.34, 0.98},
    {19.0, 1.85, 5486.78},
    {19.0, 4.97, 213.3},
    {17.0, 2.99, 6275.96},
    {16.0, 0.03, 2544.31},
    {16.0, 1.43, 2146.17},
    {15.0, 1.21, 10977.08},
    {12.0, 2.83, 1748.02},
    {12.0, 3.26, 5088.63},
    {12.0, 5.27, 1194.45},
    {12.0, 2.08, 4694.0},
    {11.0, 0.77, 553.57},
    {10.0, 1.3, 6286.6},
    {10.0, 4.24, 1349.87},
    {9.0, 2.7, 242.73},
    {9.0, 5.64, 951.72},
    {8.0, 5.3, 2352.87},
    {6.0, 2.65, 9437.76},
    {6.0, 4.67, 4690.48},
};

static const term L2[] = {
    {52919.0, 0.0, 0.0},
    {8720.0, 1.0721, 6283.0758},
    {309.0, 0.867, 12566.152},
    {27.0, 0.05, 3.52},
    {16.0, 5.19, 26.3},
    {16.0, 3.68, 155.42},
    {10.0, 0.76, 18849.23},
    {9.0, 2.06, 77713.77},
    {7.0, 0.83, 775.52},
    {5.0, 4.66, 1577.34},
    {4.0, 1.03, 7.11},
    {4.0, 3.44, 5573.14},
    {3.0, 5.14, 796.3},
    {3.0, 6.05, 5507.55},
    {3.0, 1.19, 242.73},
    {3.0, 6.12, 529.69},
    {3.0, 0.31, 398.15},
    {3.0, 2.28, 553.57},
    {2.0, 4.38, 5223.69},
    {2.0, 3.75, 0.98},
};

static const term L3[] = {
    {289.0, 5.844, 6283.076},
    {35.0, 0.0, 0.0},
    {17.0, 5.49, 12566.15},
    {3.0, 5.2, 155.42},
    {1.0, 4.72, 3.52},
    {1.0, 5.3, 18849.23},
    {1.0, 5.97, 242.73},
};

static const term L4[] = {
    {114.0, 3.142, 0.0},
    {8.0, 4.13, 6283.08},
    {1.0, 3.84, 12566.15},
};

static const term L5[] = {
    {1.0, 3.14, 0.0},
};

static const term B0[] = {
    {280.0, 3.199, 84334.662},
    {102.0, 5.422, 5507.553},
    {80.0, 3.88, 5223.69},
    {44.0, 3.7, 2352.87},
    {32.0, 4.0, 1577.34},
};

static const term B1[] = {
    {9.0, 3.9, 5507.55},
    {6.0, 1.73, 5223.69},
};

static const term R0[] = {
    {100013989.0, 0.0, 0.0},
    {1670700.0, 3.0984635, 6283.07585},
    {13956.0, 3.05525, 12566.1517},
    {3084.0, 5.1985, 77713.7715},
    {1628.0, 1.1739, 5753.3849},
    {1576.0, 2.8469, 7860.4194},
    {925.0, 5.453, 11506.77},
    {542.0, 4.564, 3930.21},
    {472.0, 3.661, 5884.927},
    {346.0, 0.964, 5507.553},
    {329.0, 5.9, 5223.694},
    {307.0, 0.299, 5573.143},
    {243.0, 4.273, 11790.629},
    {212.0, 5.847, 1577.344},
    {186.0, 5.022, 10977.079},
    {175.0, 3.012, 18849.228},
    {110.0, 5.055, 5486.778},
    {98.0, 0.89, 6069.78},
    {86.0, 5.69, 15720.84},
    {86.0, 1.27, 161000.69},
    {65.0, 0.27, 17260.15},
    {63.0, 0.92, 529.69},
    {57.0, 2.01, 83996.85},
    {56.0, 5.24, 71430.7},
    {49.0, 3.25, 2544.31},
    {47.0, 2.58, 775.52},
    {45.0, 5.54, 9437.76},
    {43.0, 6.01, 6275.96},
    {39.0, 5.36, 4694.0},
    {38.0, 2.39, 8827.39},
    {37.0, 0.83, 19651.05},
    {37.0, 4.9, 12139.55},
    {36.0, 1.67, 12036.46},
    {35.0, 1.84, 2942.46},
    {33.0, 0.24, 7084.9},
    {32.0, 0.18, 5088.63},
    {32.0, 1.78, 398.15},
    {28.0, 1.21, 6286.6},
    {28.0, 1.9, 6279.55},
    {26.0, 4.59, 10447.39},
};

static const term R1[] = {
    {103019.0, 1.10749, 6283.07585},
    {1721.0, 1.0644, 12566.1517},
    {702.0, 3.142, 0.0},
    {32.0, 1.02, 18849.23},
    {31.0, 2.84, 5507.55},
    {25.0, 1.32, 5223.69},
    {18.0, 1.42, 1577.34},
    {10.0, 5.91, 10977.08},
    {9.0, 1.42, 6275.96},
    {9.0, 0.27, 5486.78},
};

static const term R2[] = {
    {4359.0, 5.7846, 6283.0758},
    {124.0, 5.579, 12566.152},
    {12.0, 3.14, 0.0},
    {9.0, 3.63, 77713.77},
    {6.0, 1.87, 5573.14},
    {3.0, 5.47, 18849.23},
};

static const term R3[] = {
    {145.0, 4.273, 6283.076},
    {7.0, 3.92, 12566.15},
};

static const term R4[] = {
    {4.0, 2.56, 6283.08},
};

typedef struct {
    const term *t;
    size_t n;
} series;

#define SERIES(t) {t, COUNT(t)}

static const series L_SERIES[] = {SERIES(L0), SERIES(L1), SERIES(L2),
                                  SERIES(L3), SERIES(L4), SERIES(L5)};
static const series B_SERIES[] = {SERIES(B0), SERIES(B1)};
static const series R_SERIES[] = {SERIES(R0), SERIES(R1), SERIES(R2),
                                  SERIES(R3), SERIES(R4)};

/* Eq. 9-11: Xi = sum A cos(B + C JME); X = (X0 + X1 JME + X2 JME^2 + ...)
 * / 10^8, in radians for L and B, in AU for R. Smallest terms first. */
static double earth_series(const series *s, size_t count, double jme)
{
    double total = 0.0;
    for (size_t k = count; k-- > 0;) {
        double sum = 0.0;
        for (size_t i = s[k].n; i-- > 0;)
            sum += s[k].t[i].a * cos(s[k].t[i].b + s[k].t[i].c * jme);
        total = total * jme + sum; /* Horner over the powers of JME */
    }
    return total / 1e8;
}

/* ---------------------------------------- table A4.3: nutation terms */

/* Multipliers Y0..Y4 of X0..X4 (eq. 20-21) and the coefficients a, b (for
 * delta psi, 0.0001 arc seconds) and c, d (for delta epsilon). */
typedef struct {
    signed char y[5];
    double a, b, c, d;
} nutation_term;

static const nutation_term NUTATION[] = {
    {{0, 0, 0, 0, 1}, -171996.0, -174.2, 92025.0, 8.9},
    {{-2, 0, 0, 2, 2}, -13187.0, -1.6, 5736.0, -3.1},
    {{0, 0, 0, 2, 2}, -2274.0, -0.2, 977.0, -0.5},
    {{0, 0, 0, 0, 2}, 2062.0, 0.2, -895.0, 0.5},
    {{0, 1, 0, 0, 0}, 1426.0, -3.4, 54.0, -0.1},
    {{0, 0, 1, 0, 0}, 712.0, 0.1, -7.0, 0.0},
    {{-2, 1, 0, 2, 2}, -517.0, 1.2, 224.0, -0.6},
    {{0, 0, 0, 2, 1}, -386.0, -0.4, 200.0, 0.0},
    {{0, 0, 1, 2, 2}, -301.0, 0.0, 129.0, -0.1},
    {{-2, -1, 0, 2, 2}, 217.0, -0.5, -95.0, 0.3},
    {{-2, 0, 1, 0, 0}, -158.0, 0.0, 0.0, 0.0},
    {{-2, 0, 0, 2, 1}, 129.0, 0.1, -70.0, 0.0},
    {{0, 0, -1, 2, 2}, 123.0, 0.0, -53.0, 0.0},
    {{2, 0, 0, 0, 0}, 63.0, 0.0, 0.0, 0.0},
    {{0, 0, 1, 0, 1}, 63.0, 0.1, -33.0, 0.0},
    {{2, 0, -1, 2, 2}, -59.0, 0.0, 26.0, 0.0},
    {{0, 0, -1, 0, 1}, -58.0, -0.1, 32.0, 0.0},
    {{0, 0, 1, 2, 1}, -51.0, 0.0, 27.0, 0.0},
    {{-2, 0, 2, 0, 0}, 48.0, 0.0, 0.0, 0.0},
    {{0, 0, -2, 2, 1}, 46.0, 0.0, -24.0, 0.0},
    {{2, 0, 0, 2, 2}, -38.0, 0.0, 16.0, 0.0},
    {{0, 0, 2, 2, 2}, -31.0, 0.0, 13.0, 0.0},
    {{0, 0, 2, 0, 0}, 29.0, 0.0, 0.0, 0.0},
    {{-2, 0, 1, 2, 2}, 29.0, 0.0, -12.0, 0.0},
    {{0, 0, 0, 2, 0}, 26.0, 0.0, 0.0, 0.0},
    {{-2, 0, 0, 2, 0}, -22.0, 0.0, 0.0, 0.0},
    {{0, 0, -1, 2, 1}, 21.0, 0.0, -10.0, 0.0},
    {{0, 2, 0, 0, 0}, 17.0, -0.1, 0.0, 0.0},
    {{2, 0, -1, 0, 1}, 16.0, 0.0, -8.0, 0.0},
    {{-2, 2, 0, 2, 2}, -16.0, 0.1, 7.0, 0.0},
    {{0, 1, 0, 0, 1}, -15.0, 0.0, 9.0, 0.0},
    {{-2, 0, 1, 0, 1}, -13.0, 0.0, 7.0, 0.0},
    {{0, -1, 0, 0, 1}, -12.0, 0.0, 6.0, 0.0},
    {{0, 0, 2, -2, 0}, 11.0, 0.0, 0.0, 0.0},
    {{2, 0, -1, 2, 1}, -10.0, 0.0, 5.0, 0.0},
    {{2, 0, 1, 2, 2}, -8.0, 0.0, 3.0, 0.0},
    {{0, 1, 0, 2, 2}, 7.0, 0.0, -3.0, 0.0},
    {{-2, 1, 1, 0, 0}, -7.0, 0.0, 0.0, 0.0},
    {{0, -1, 0, 2, 2}, -7.0, 0.0, 3.0, 0.0},
    {{2, 0, 0, 2, 1}, -7.0, 0.0, 3.0, 0.0},
    {{2, 0, 1, 0, 0}, 6.0, 0.0, 0.0, 0.0},
    {{-2, 0, 2, 2, 2}, 6.0, 0.0, -3.0, 0.0},
    {{-2, 0, 1, 2, 1}, 6.0, 0.0, -3.0, 0.0},
    {{2, 0, -2, 0, 1}, -6.0, 0.0, 3.0, 0.0},
    {{2, 0, 0, 0, 1}, -6.0, 0.0, 3.0, 0.0},
    {{0, -1, 1, 0, 0}, 5.0, 0.0, 0.0, 0.0},
    {{-2, -1, 0, 2, 1}, -5.0, 0.0, 3.0, 0.0},
    {{-2, 0, 0, 0, 1}, -5.0, 0.0, 3.0, 0.0},
    {{0, 0, 2, 2, 1}, -5.0, 0.0, 3.0, 0.0},
    {{-2, 0, 2, 0, 1}, 4.0, 0.0, 0.0, 0.0},
    {{-2, 1, 0, 2, 1}, 4.0, 0.0, 0.0, 0.0},
    {{0, 0, 1, -2, 0}, 4.0, 0.0, 0.0, 0.0},
    {{-1, 0, 1, 0, 0}, -4.0, 0.0, 0.0, 0.0},
    {{-2, 1, 0, 0, 0}, -4.0, 0.0, 0.0, 0.0},
    {{1, 0, 0, 0, 0}, -4.0, 0.0, 0.0, 0.0},
    {{0, 0, 1, 2, 0}, 3.0, 0.0, 0.0, 0.0},
    {{0, 0, -2, 2, 2}, -3.0, 0.0, 0.0, 0.0},
    {{-1, -1, 1, 0, 0}, -3.0, 0.0, 0.0, 0.0},
    {{0, 1, 1, 0, 0}, -3.0, 0.0, 0.0, 0.0},
    {{0, -1, 1, 2, 2}, -3.0, 0.0, 0.0, 0.0},
    {{2, -1, -1, 2, 2}, -3.0, 0.0, 0.0, 0.0},
    {{0, 0, 3, 2, 2}, -3.0, 0.0, 0.0, 0.0},
    {{2, -1, 0, 2, 2}, -3.0, 0.0, 0.0, 0.0},
};

/* ------------------------------------------------------------ helpers */

/* An angle in degrees brought into [0, 360). */
static double limit_degrees(double deg)
{
    double r = fmod(deg, 360.0);
    if (r < 0.0)
        r += 360.0;
    if (r >= 360.0) /* -1e-20 + 360 rounds to 360 */
        r = 0.0;
    return r;
}

/* a + b T + c T^2 + T^3 / d: the nutation arguments' polynomials. */
static double poly3(double a, double b, double c, double d, double t)
{
    return a + t * (b + t * (c + t / d));
}

/* ------------------------------------------------------------ input */

void ts_sun_input_default(ts_sun_input *in)
{
    if (!in)
        return;
    in->jd = NAN;
    in->longitude = 0.0;
    in->latitude = 0.0;
    in->elevation = 0.0;
    in->pressure = 1013.25;
    in->temperature = 15.0;
    in->delta_t = TS_SUN_DEFAULT_DELTA_T;
    in->atmos_refraction = TS_SUN_DEFAULT_ATMOS_REFRACTION;
}

ts_status ts_sun_input_validate(const ts_sun_input *in, ts_error *err)
{
    if (!in)
        return ts_fail(err, TS_ERR_ARG, "The sun position input must not be NULL.");
    struct {
        const char *name;
        double v;
    } fields[] = {
        {"longitude", in->longitude},     {"latitude", in->latitude},
        {"elevation", in->elevation},     {"pressure", in->pressure},
        {"temperature", in->temperature}, {"delta_t", in->delta_t},
        {"atmos_refraction", in->atmos_refraction},
    };
    if (!isfinite(in->jd))
        return ts_fail(err, TS_ERR_ARG,
                       "The date and time of the sun position are not set (Julian "
                       "day %g): set jd, e.g. with ts_julian_day.",
                       in->jd);
    for (size_t i = 0; i < COUNT(fields); i++)
        if (!isfinite(fields[i].v))
            return ts_fail(err, TS_ERR_ARG, "The sun position's %s must be a finite "
                           "number, got %g.", fields[i].name, fields[i].v);
    /* The paper's range of validity: years -2000 to 6000. */
    double jd_min = (double)ts_days_from_civil(-2000, 1, 1) + TS_JD_UNIX_EPOCH;
    double jd_max = (double)ts_days_from_civil(6001, 1, 1) + TS_JD_UNIX_EPOCH;
    if (in->jd < jd_min || in->jd >= jd_max)
        return ts_fail(err, TS_ERR_ARG,
                       "The date (Julian day %.6f) must lie between the years -2000 "
                       "and 6000, where the solar position algorithm is valid.",
                       in->jd);
    if (in->longitude < -180.0 || in->longitude > 180.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Longitude must be between -180 and 180 degrees (east "
                       "positive), got %g.", in->longitude);
    if (in->latitude < -90.0 || in->latitude > 90.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Latitude must be between -90 and 90 degrees, got %g.",
                       in->latitude);
    if (in->elevation < -6500000.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Elevation must be at least -6500000 m (the centre of the "
                       "Earth), got %g m.", in->elevation);
    if (!(in->pressure > 0.0 && in->pressure <= 5000.0))
        return ts_fail(err, TS_ERR_ARG,
                       "Pressure must be greater than 0 and at most 5000 hPa (mbar), "
                       "got %g.", in->pressure);
    if (!(in->temperature > -273.0 && in->temperature <= 6000.0))
        return ts_fail(err, TS_ERR_ARG,
                       "Temperature must be above -273 and at most 6000 degrees "
                       "Celsius, got %g.", in->temperature);
    if (fabs(in->delta_t) > 8000.0)
        return ts_fail(err, TS_ERR_ARG,
                       "delta_t (TT - UT) must be between -8000 and 8000 seconds, "
                       "got %g (it is about 69 s in the 2020s).", in->delta_t);
    if (fabs(in->atmos_refraction) > 5.0)
        return ts_fail(err, TS_ERR_ARG,
                       "Atmospheric refraction at sunrise and sunset must be between "
                       "-5 and 5 degrees, got %g (the usual value is 0.5667).",
                       in->atmos_refraction);
    return ts_ok(err);
}

/* ------------------------------------------------------------ the SPA */

double ts_sun_refraction(double e0, const ts_sun_input *in)
{
    double de = 0.0;
    if (e0 >= -(SPA_SUN_RADIUS + in->atmos_refraction))
        de = in->pressure / 1010.0 * 283.0 / (273.0 + in->temperature) * 1.02 /
             (60.0 * tan((e0 + 10.3 / (e0 + 5.11)) * DEG)); /* eq. 42 */
    return isfinite(de) ? de : 0.0; /* e0 = -5.11 exactly, reachable with a large
                                     * atmos_refraction */
}

ts_status ts_sun_position_detail(const ts_sun_input *in, ts_sun_output *out,
                                 ts_sun_detail *detail, ts_error *err)
{
    if (!out)
        return ts_fail(err, TS_ERR_ARG, "The sun position output must not be NULL.");
    ts_status st = ts_sun_input_validate(in, err);
    if (st != TS_OK)
        return st;

    ts_sun_detail d;

    /* 3.1 Time scales. */
    d.jd = in->jd;
    d.jde = d.jd + in->delta_t / 86400.0;          /* eq. 5 */
    d.jc = (d.jd - 2451545.0) / 36525.0;           /* eq. 6 */
    d.jce = (d.jde - 2451545.0) / 36525.0;         /* eq. 7 */
    d.jme = d.jce / 10.0;                          /* eq. 8 */

    /* 3.2 Earth heliocentric longitude, latitude and radius vector. */
    d.L = limit_degrees(earth_series(L_SERIES, COUNT(L_SERIES), d.jme) * RAD); /* eq. 9-12 */
    d.B = earth_series(B_SERIES, COUNT(B_SERIES), d.jme) * RAD;
    d.R = earth_series(R_SERIES, COUNT(R_SERIES), d.jme);

    /* 3.3 Geocentric longitude and latitude. */
    d.theta = limit_degrees(d.L + 180.0);          /* eq. 13 */
    d.beta = -d.B;                                 /* eq. 14 */

    /* 3.4 Nutation in longitude and obliquity. */
    double t = d.jce;
    d.x[0] = poly3(297.85036, 445267.111480, -0.0019142, 189474.0, t);  /* eq. 15 */
    d.x[1] = poly3(357.52772, 35999.050340, -0.0001603, -300000.0, t);  /* eq. 16 */
    d.x[2] = poly3(134.96298, 477198.867398, 0.0086972, 56250.0, t);    /* eq. 17 */
    d.x[3] = poly3(93.27191, 483202.017538, -0.0036825, 327270.0, t);   /* eq. 18 */
    d.x[4] = poly3(125.04452, -1934.136261, 0.0020708, 450000.0, t);    /* eq. 19 */
    double sum_psi = 0.0, sum_eps = 0.0;
    for (size_t i = COUNT(NUTATION); i-- > 0;) {
        const nutation_term *n = &NUTATION[i];
        double arg = 0.0;
        for (int j = 0; j < 5; j++)
            arg += d.x[j] * n->y[j];
        arg *= DEG;
        sum_psi += (n->a + n->b * t) * sin(arg);   /* eq. 20 */
        sum_eps += (n->c + n->d * t) * cos(arg);   /* eq. 21 */
    }
    d.delta_psi = sum_psi / 36000000.0;            /* eq. 22 */
    d.delta_epsilon = sum_eps / 36000000.0;        /* eq. 23 */

    /* 3.5 True obliquity of the ecliptic. */
    double u = d.jme / 10.0;
    static const double eps_poly[] = {84381.448, -4680.93, -1.55, 1999.25, -51.38,
                                      -249.67,   -39.05,   7.12,  27.87,   5.79,
                                      2.45};
    double e0 = 0.0;
    for (size_t k = COUNT(eps_poly); k-- > 0;)
        e0 = e0 * u + eps_poly[k];                 /* eq. 24, arc seconds */
    d.epsilon0 = e0;
    d.epsilon = e0 / 3600.0 + d.delta_epsilon;     /* eq. 25 */

    /* 3.6-3.7 Aberration and apparent sun longitude. */
    d.delta_tau = -20.4898 / (3600.0 * d.R);       /* eq. 26 */
    d.lambda = d.theta + d.delta_psi + d.delta_tau; /* eq. 27 */

    /* 3.8 Apparent sidereal time at Greenwich. */
    d.nu0 = limit_degrees(280.46061837 + 360.98564736629 * (d.jd - 2451545.0) +
                          d.jc * d.jc * (0.000387933 - d.jc / 38710000.0)); /* eq. 28 */
    d.nu = d.nu0 + d.delta_psi * cos(d.epsilon * DEG); /* eq. 29 */

    /* 3.9-3.10 Geocentric right ascension and declination. */
    double lam = d.lambda * DEG, eps = d.epsilon * DEG, bet = d.beta * DEG;
    d.alpha = limit_degrees(
        atan2(sin(lam) * cos(eps) - tan(bet) * sin(eps), cos(lam)) * RAD); /* eq. 30 */
    d.delta = asin(sin(bet) * cos(eps) + cos(bet) * sin(eps) * sin(lam)) * RAD; /* eq. 31 */

    /* 3.11 Observer local hour angle. */
    d.H = limit_degrees(d.nu + in->longitude - d.alpha); /* eq. 32 */

    /* 3.12 Topocentric right ascension and declination (parallax). */
    d.xi = 8.794 / (3600.0 * d.R);                 /* eq. 33 */
    double phi = in->latitude * DEG;
    double uu = atan(0.99664719 * tan(phi));       /* eq. 34 */
    double x = cos(uu) + in->elevation / 6378140.0 * cos(phi);           /* eq. 35 */
    double y = 0.99664719 * sin(uu) + in->elevation / 6378140.0 * sin(phi); /* eq. 36 */
    double xi = d.xi * DEG, h = d.H * DEG, dec = d.delta * DEG;
    double denom = cos(dec) - x * sin(xi) * cos(h);
    double dalpha = atan2(-x * sin(xi) * sin(h), denom); /* eq. 37 */
    d.delta_alpha = dalpha * RAD;
    d.alpha_prime = d.alpha + d.delta_alpha;       /* eq. 38 */
    double dec_p = atan2((sin(dec) - y * sin(xi)) * cos(dalpha), denom); /* eq. 39 */
    d.delta_prime = dec_p * RAD;

    /* 3.13 Topocentric local hour angle. */
    d.H_prime = d.H - d.delta_alpha;               /* eq. 40 */
    double hp = d.H_prime * DEG;

    /* 3.14 Topocentric zenith angle. */
    double s_e0 = sin(phi) * sin(dec_p) + cos(phi) * cos(dec_p) * cos(hp);
    if (s_e0 > 1.0)
        s_e0 = 1.0;
    if (s_e0 < -1.0)
        s_e0 = -1.0;
    d.e0 = asin(s_e0) * RAD;                       /* eq. 41 */
    d.delta_e = ts_sun_refraction(d.e0, in);
    d.e = d.e0 + d.delta_e;                        /* eq. 43 */
    /* eq. 42 holds for the air at the Earth's surface; far outside it (a
     * temperature near -273 C, a large atmos_refraction) its tangent can
     * blow up: no sun leaves [-90, 90] */
    if (!(d.e >= -90.0 && d.e <= 90.0))
        return ts_fail(err, TS_ERR_ARG,
                       "The refracted sun elevation would be %g degrees, outside -90 "
                       "to 90: the refraction model does not hold for pressure %g hPa, "
                       "temperature %g degrees Celsius and atmos_refraction %g (it "
                       "holds for the air at the Earth's surface, about 300 to 1100 "
                       "hPa and -90 to 60 degrees Celsius).",
                       d.e, in->pressure, in->temperature, in->atmos_refraction);
    d.zenith = 90.0 - d.e;                         /* eq. 44 */

    /* 3.15 Topocentric azimuth. */
    d.gamma = limit_degrees(
        atan2(sin(hp), cos(hp) * sin(phi) - tan(dec_p) * cos(phi)) * RAD); /* eq. 45 */
    d.phi = limit_degrees(d.gamma + 180.0);        /* eq. 46 */

    out->zenith = d.zenith;
    out->azimuth = d.phi;
    out->elevation = d.e;
    if (detail)
        *detail = d;
    return ts_ok(err);
}

ts_status ts_sun_position(const ts_sun_input *in, ts_sun_output *out,
                          ts_error *err)
{
    return ts_sun_position_detail(in, out, NULL, err);
}
