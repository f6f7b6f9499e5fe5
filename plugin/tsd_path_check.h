/*
 * tsd_path_check.h - names the driver refuses before GDAL opens them: a
 * pipe or a device (also inside /vsigzip/, /vsizip/, /vsitar/ or
 * /vsisubfile/), whose open waits for a writer for ever, and GDAL 3.6's
 * MEM::: names, which read any address of the process.
 */
#ifndef TSD_PATH_CHECK_H
#define TSD_PATH_CHECK_H

#include <string>

namespace tsd
{

/* The file of the operating system that pszPath would read and that is no
 * regular file (a pipe, a device, a socket), or "/vsistdin/" where it reads
 * the standard input; "" otherwise (a regular file, a folder, a URL, an
 * in-memory file, a driver's prefix, a name that does not exist). */
std::string NonRegularSource(const char *pszPath);

/* The sentence that refuses pszDEM as a DEM, or "" where it may be opened:
 * a MEM::: name (unless GDAL_MEM_ENABLE_OPEN=YES, as GDAL 3.10 asks), a
 * pipe or a device, and the standard input where the name comes from a
 * file (an atlas's SOURCE_DEM: bFromFile) rather than from the user.
 * pszWhat says what the name is ("the DEM", "the atlas's SOURCE_DEM"). */
std::string RefusedDEMName(const char *pszDEM, const char *pszWhat, bool bFromFile);

/* Whether a DEM's name is GDAL's for the standard input itself, with or
 * without its options (/vsistdin?buffer_limit=...), which the driver
 * copies into memory at open (a path that merely contains the word is a
 * file's). */
bool IsStdinName(const std::string &osName);

} // namespace tsd

#endif
