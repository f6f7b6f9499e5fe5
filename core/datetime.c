/* Dates and times: proleptic Gregorian calendar arithmetic, Julian days and
 * ISO 8601 parsing. Self-contained: no timegm, no locale, no time zone
 * database (an ISO 8601 string must carry its own UTC offset). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "status_internal.h"
#include "terrashade_sun.h"

#define SECONDS_PER_DAY 86400.0
#define MAX_YEAR 1000000

int ts_is_leap_year(long long year)
{
    return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
}

int ts_days_in_month(long long year, int month)
{
    static const int days[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    if (month < 1 || month > 12)
        return 0;
    return days[month - 1] + (month == 2 && ts_is_leap_year(year));
}

/* Count days in 400-year eras of 146097 days, with the year starting on
 * March 1 so that the leap day is the last day of a year. */
long long ts_days_from_civil(long long year, int month, int day)
{
    long long y = year - (month <= 2);
    long long era = (y >= 0 ? y : y - 399) / 400;
    long long yoe = y - era * 400;                                 /* [0, 399] */
    long long mp = month > 2 ? month - 3 : month + 9;              /* March = 0 */
    long long doy = (153 * mp + 2) / 5 + day - 1;                  /* [0, 365] */
    long long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;         /* [0, 146096] */
    return era * 146097 + doe - 719468; /* 719468: 0000-03-01 to 1970-01-01 */
}

/* Check the fields of a date and time; message without a trailing period. */
static ts_status check_fields(long long year, int month, int day, int hour,
                              int minute, double second, char *what,
                              size_t what_size)
{
    if (year < -MAX_YEAR || year > MAX_YEAR) {
        snprintf(what, what_size, "year %lld is not between %d and %d", year,
                 -MAX_YEAR, MAX_YEAR);
        return TS_ERR_ARG;
    }
    if (month < 1 || month > 12) {
        snprintf(what, what_size, "month %d is not between 1 and 12", month);
        return TS_ERR_ARG;
    }
    int dim = ts_days_in_month(year, month);
    if (day < 1 || day > dim) {
        if (month == 2 && day == 29)
            snprintf(what, what_size, "%lld is not a leap year, February has 28 days",
                     year);
        else
            snprintf(what, what_size, "day %d is not between 1 and %d (days in month %d)",
                     day, dim, month);
        return TS_ERR_ARG;
    }
    if (hour < 0 || hour > 23) {
        snprintf(what, what_size, "hour %d is not between 0 and 23", hour);
        return TS_ERR_ARG;
    }
    if (minute < 0 || minute > 59) {
        snprintf(what, what_size, "minute %d is not between 0 and 59", minute);
        return TS_ERR_ARG;
    }
    if (!(second >= 0.0 && second < 61.0)) {
        snprintf(what, what_size, "second %g is not in [0, 60] (60 only for a leap second)",
                 second);
        return TS_ERR_ARG;
    }
    return TS_OK;
}

/* Seconds from the Unix epoch; fields already checked. */
static double unix_from_fields(long long year, int month, int day, int hour,
                               int minute, double second)
{
    long long days = ts_days_from_civil(year, month, day);
    return (double)(days * 86400LL + hour * 3600LL + minute * 60LL) + second;
}

ts_status ts_julian_day(int year, int month, int day, int hour, int minute,
                        double second, double *jd, ts_error *err)
{
    char what[160];
    if (!jd)
        return ts_fail(err, TS_ERR_ARG, "ts_julian_day: jd must not be NULL");
    if (check_fields(year, month, day, hour, minute, second, what, sizeof what))
        return ts_fail(err, TS_ERR_ARG, "Invalid date or time: %s.", what);
    /* Whole days and the time of day apart, so that a large day count does
     * not eat the fraction's precision (eq. 4, Gregorian branch). */
    long long days = ts_days_from_civil(year, month, day);
    double sod = hour * 3600.0 + minute * 60.0 + second;
    *jd = ((double)days + TS_JD_UNIX_EPOCH) + sod / SECONDS_PER_DAY;
    return ts_ok(err);
}

double ts_julian_day_from_unix(double unix_seconds)
{
    return TS_JD_UNIX_EPOCH + unix_seconds / SECONDS_PER_DAY;
}

double ts_unix_from_julian_day(double jd)
{
    return (jd - TS_JD_UNIX_EPOCH) * SECONDS_PER_DAY;
}

/* ------------------------------------------------------------ ISO 8601 */

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* Exactly n digits at *p; advances *p. Returns 0 if not there. */
static int read_digits(const char **p, int n, int *value)
{
    int v = 0;
    for (int i = 0; i < n; i++) {
        if (!is_digit((*p)[i]))
            return 0;
        v = v * 10 + ((*p)[i] - '0');
    }
    *p += n;
    *value = v;
    return 1;
}

#define ISO_FORM "YYYY-MM-DDThh:mm:ss followed by Z or an offset such as +02:00"

ts_status ts_parse_iso8601(const char *s, double *unix_seconds,
                           int *offset_minutes, ts_error *err)
{
    if (!s)
        return ts_fail(err, TS_ERR_ARG, "ts_parse_iso8601: the string must not be NULL");
    if (!unix_seconds)
        return ts_fail(err, TS_ERR_ARG, "ts_parse_iso8601: unix_seconds must not be NULL");

    const char *p = s;
    int year, month, day, hour, minute, isec = 0;
    double second = 0.0;
    char what[160];

#define BAD(...)                                                                   \
    do {                                                                           \
        snprintf(what, sizeof what, __VA_ARGS__);                                  \
        return ts_fail(err, TS_ERR_ARG,                                            \
                       "Cannot read '%.64s' as an ISO 8601 date and time: %s.", s, \
                       what);                                                      \
    } while (0)

    /* Date: YYYY-MM-DD */
    if (!read_digits(&p, 4, &year) || *p != '-')
        BAD("expected " ISO_FORM);
    p++;
    if (!read_digits(&p, 2, &month) || *p != '-')
        BAD("expected " ISO_FORM);
    p++;
    if (!read_digits(&p, 2, &day))
        BAD("expected " ISO_FORM);
    if (*p == '\0')
        BAD("a time of day and an offset such as +02:00 or Z are required");
    if (*p != 'T' && *p != 't' && *p != ' ')
        BAD("expected 'T' between the date and the time");
    p++;

    /* Time: hh:mm[:ss[.fff]] */
    if (!read_digits(&p, 2, &hour) || *p != ':')
        BAD("expected the time as hh:mm or hh:mm:ss");
    p++;
    if (!read_digits(&p, 2, &minute))
        BAD("expected the time as hh:mm or hh:mm:ss");
    if (*p == ':') {
        p++;
        if (!read_digits(&p, 2, &isec))
            BAD("expected two digits of seconds after '%02d:%02d:'", hour, minute);
        second = isec;
        if (*p == '.' || *p == ',') {
            p++;
            if (!is_digit(*p))
                BAD("expected digits after the decimal point of the seconds");
            double scale = 0.1;
            while (is_digit(*p)) {
                second += (*p - '0') * scale; /* digits past 1e-17 add nothing */
                scale *= 0.1;
                p++;
            }
        }
    }

    /* Offset: Z | +hh:mm | +hhmm | +hh */
    int offset = 0;
    if (*p == '\0')
        BAD("an offset from UTC is required: add Z for UTC or an offset such as "
            "+02:00 (local time alone does not name an instant)");
    if (*p == 'Z' || *p == 'z') {
        p++;
    } else if (*p == '+' || *p == '-') {
        int sign = *p == '-' ? -1 : 1, oh, om = 0;
        p++;
        if (!read_digits(&p, 2, &oh))
            BAD("expected the offset as +hh:mm, +hhmm or +hh");
        if (*p == ':') {
            p++;
            if (!read_digits(&p, 2, &om))
                BAD("expected the offset as +hh:mm, +hhmm or +hh");
        } else if (is_digit(*p)) {
            if (!read_digits(&p, 2, &om))
                BAD("expected the offset as +hh:mm, +hhmm or +hh");
        }
        if (oh > 23 || om > 59)
            BAD("offset %c%02d:%02d is out of range", sign < 0 ? '-' : '+', oh, om);
        offset = sign * (oh * 60 + om);
    } else {
        BAD("unexpected '%c' where the offset (Z or +hh:mm) should be", *p);
    }
    if (*p != '\0')
        BAD("unexpected text '%.16s' after the offset", p);

    /* Leap second: only 23:59:60 UTC, read as the last instant of its
     * minute (POSIX time does not count it; read as the next minute's first
     * second it moved a day product to the next day). The fraction's nines
     * may sum to the next second (61.0 after a leap second's 60): checked
     * within its second, and kept there below. */
    if (check_fields(year, month, day, hour, minute, fmin(second, isec + 0.5), what,
                     sizeof what))
        return ts_fail(err, TS_ERR_ARG,
                       "Cannot read '%.64s' as an ISO 8601 date and time: %s.", s, what);
    if (isec == 60) {
        const int utc = ((hour * 60 + minute - offset) % 1440 + 1440) % 1440;
        if (utc != 23 * 60 + 59)
            BAD("second 60 is a leap second, which only ends a UTC day (23:59:60Z), and "
                "%02d:%02d here is %02d:%02d UTC", hour, minute, utc / 60, utc % 60);
    }
#undef BAD

    /* The whole seconds, then the fraction, kept within its second: a leap
     * second is its minute's last instant (read as the next minute's first
     * second, it moved a day product to the next day), and .9999999999 past
     * what a double holds at this time stays short of the next second */
    const int whole = isec == 60 ? 59 : isec;
    const double base = unix_from_fields(year, month, day, hour, minute, whole) - offset * 60.0;
    double t = base + (isec == 60 ? 1.0 : second - isec);
    if (t >= base + 1.0)
        t = nextafter(base + 1.0, -INFINITY);
    *unix_seconds = t;
    if (offset_minutes)
        *offset_minutes = offset;
    return ts_ok(err);
}
