/*
 * tsd_entry_state.h - the calling thread's state as the driver needs it,
 * while the driver runs: the "C" locale and a quiet floating-point
 * environment.
 *
 * The locale: the driver reads numbers with strtod and writes them with
 * snprintf, and compares names with strcasecmp; all three follow the
 * process's locale, which QGIS (Qt) and scripts that call setlocale set
 * to the user's: under de_DE "0.2666" read as 0 (cast shadows became
 * nodata without a word), numbers were written with commas into metadata
 * and atlas files, and under tr_TR "directions" did not match
 * "DIRECTIONS".
 *
 * The floating-point environment: the core computes with NaN and
 * infinities as values (voids, rays leaving the DEM; built with
 * -fno-trapping-math) and rounds to nearest. A host that enabled traps
 * (feenableexcept: a numerical code, a debugger's setting) got SIGFPE in
 * the core's first division by zero, and another rounding mode would
 * change the bits. While the driver runs, traps are off and rounding is
 * to nearest; the thread's own environment, its exception flags too, is
 * put back when the driver returns.
 *
 * Every entry point of the driver (GDAL's callbacks and the datasets' and
 * bands' overrides) holds one EntryState, as GDAL's own drivers hold
 * CPLThreadLocaleC; the core's threads take their creator's locale
 * (core/parallel.c) and, as threads do, its floating-point environment.
 */
#ifndef TSD_ENTRY_STATE_H
#define TSD_ENTRY_STATE_H

#include <fenv.h>
#include <locale.h>

namespace tsd
{

/* The calling thread in the "C" locale, with floating-point traps off and
 * rounding to nearest, until the object goes (the thread's own state, not
 * the process's; nests). */
class EntryState
{
  public:
    EntryState();
    ~EntryState();
    EntryState(const EntryState &) = delete;
    EntryState &operator=(const EntryState &) = delete;

  private:
    locale_t m_old; /* the thread's locale before; (locale_t)0: unchanged */
    fenv_t m_fenv;  /* the thread's floating-point environment before */
    bool m_bFenv;   /* m_fenv was saved (and traps turned off) */
};

} // namespace tsd

#endif
