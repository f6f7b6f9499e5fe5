/*
 * tsd_source_stamp.h - what identifies the contents of the files a
 * product is made of (the DEM's file and ENV_MAP's), so that a product
 * computed after they changed on disk is refused, and statistics saved for
 * their former contents are not taken for theirs.
 */
#ifndef TSD_SOURCE_STAMP_H
#define TSD_SOURCE_STAMP_H

#include <string>

namespace tsd
{

/* A stamp of each file named (null or empty: left out): for a local file
 * its size, modification and change times to the nanosecond and inode
 * (what rewriting it in place, replacing it or regenerating it under the
 * same name changes); for other GDAL paths (/vsimem/, /vsicurl/...) the
 * size and modification time VSI gives; "missing" where it cannot be
 * read. Equal stamps: the files were not seen to change. */
std::string SourceStamp(const char *pszDEMFile, const char *pszEnvMap);

/* The sentence refusing to compute from pszDEM after its files changed on
 * disk since the dataset opened (nLevel: the overview level, 0 = full
 * resolution). */
std::string SourcesChangedError(const std::string &osDEM, int nLevel);

} // namespace tsd

#endif
