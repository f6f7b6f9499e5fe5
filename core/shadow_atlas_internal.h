/* What the atlas's writer (shadow_atlas.c) and reader (shadow_atlas_read.c)
 * share: the file's magic. */
#ifndef TS_SHADOW_ATLAS_INTERNAL_H
#define TS_SHADOW_ATLAS_INTERNAL_H

/** The first 8 bytes of every atlas file: \x89TSATLAS. */
#define TS_ATLAS_MAGIC "\x89TSATLAS"

#endif
