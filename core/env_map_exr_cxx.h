/* Decoding an EXR file's pixels through OpenEXR's C++ library, for the
 * compressions this version of OpenEXRCore cannot decode (DWAA and DWAB
 * before OpenEXR 3.2: "not yet implemented in C"). */
#ifndef TS_ENV_MAP_EXR_CXX_H
#define TS_ENV_MAP_EXR_CXX_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Reads up to size bytes at offset into buf; the count read, -1 on error. */
typedef int64_t (*env_read_at_fn)(void *user, void *buf, uint64_t size, uint64_t offset);

/* Decode the first part of the file of file_size bytes read through
 * read_at into rgb (width x height pixels, three floats each, as
 * env_map_exr.c lays them out): channels R, G, B, or Y into all three when
 * grey. 0 on success; -1 with a sentence in msg otherwise. */
int env_exr_decode_cxx(env_read_at_fn read_at, void *user, uint64_t file_size, const char *name,
                       int grey, int width, int height, float *rgb, char *msg, size_t msg_size);

#ifdef __cplusplus
}
#endif

#endif
