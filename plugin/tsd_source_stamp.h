/*
 * tsd_source_stamp.h - what identifies the contents of the files a
 * product is made of (the DEM's files, a VRT's sources and external
 * overviews among them, and ENV_MAP's), so that a product computed after
 * they changed on disk is refused, and statistics saved for their former
 * contents are not taken for theirs.
 */
#ifndef TSD_SOURCE_STAMP_H
#define TSD_SOURCE_STAMP_H

#include <string>
#include <vector>

namespace tsd
{

/* pszPath made absolute against the current directory where it names a
 * file by a relative name, plainly or inside /vsizip/, /vsigzip/ or
 * /vsitar/ (what a later chdir would lose: an overview level reopens the
 * DEM by it); anything else (a driver's prefix, /vsimem/, a URL) as it is. */
std::string AbsolutePath(const char *pszPath);

/* The files to stamp: the DEM's file list (GDALDataset::GetFileList, NULL
 * ended; NULL: none) but its .aux.xml files, which GDAL rewrites as it
 * reads, and ENV_MAP (null or empty: none), each made absolute against the
 * current directory, so that a later chdir does not lose them. */
std::vector<std::string> SourceFiles(char **papszDEMFiles, const char *pszEnvMap);

/* A short stamp of those files' contents: a 64-bit digest, in hex, of each
 * file's device, inode, size and modification time to the nanosecond (for
 * /vsi paths: size and modification time as VSI gives them; "missing"
 * where it cannot be read), with the count of files. What rewriting a file
 * in place, replacing it or regenerating it under the same name changes;
 * not what a chmod, a hard link or reading it changes. Equal stamps: the
 * files were not seen to change. Empty for no files. */
std::string SourceStamp(const std::vector<std::string> &aosFiles);

/* The sentence refusing to compute from pszDEM after its files (aosFiles,
 * SourceFiles') changed on disk since the dataset opened, or one of them
 * went (nLevel: the overview level, 0 = full resolution). */
std::string SourcesChangedError(const std::string &osDEM, int nLevel,
                                const std::vector<std::string> &aosFiles);

} // namespace tsd

#endif
