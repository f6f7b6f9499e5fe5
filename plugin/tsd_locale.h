/*
 * tsd_locale.h - the "C" locale on the calling thread while the driver
 * runs. The driver reads numbers with strtod and writes them with
 * snprintf, and compares names with strcasecmp; all three follow the
 * process's locale, which QGIS (Qt) and scripts that call setlocale set
 * to the user's: under de_DE "0.2666" read as 0 (cast shadows became
 * nodata without a word), numbers were written with commas into metadata
 * and atlas files, and under tr_TR "directions" did not match
 * "DIRECTIONS". Every entry point of the driver (GDAL's callbacks and the
 * datasets' and bands' overrides) holds one CLocale, as GDAL's own drivers
 * hold CPLThreadLocaleC; the core's threads take their creator's locale
 * (core/parallel.c).
 */
#ifndef TSD_LOCALE_H
#define TSD_LOCALE_H

#include <locale.h>

namespace tsd
{

/* The calling thread in the "C" locale until the object goes (uselocale:
 * the thread's own, not the process's; nests). */
class CLocale
{
  public:
    CLocale();
    ~CLocale();
    CLocale(const CLocale &) = delete;
    CLocale &operator=(const CLocale &) = delete;

  private:
    locale_t m_old; /* the thread's locale before; (locale_t)0: unchanged */
};

} // namespace tsd

#endif
