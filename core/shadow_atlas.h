/*
 * shadow_atlas.h - far shadows over a day and their compact storage
 * (Chajdas, Reichl, Dick & Westermann 2015, "High-Quality Shadows for
 * Streaming Terrain Rendering").
 *
 *  - ts_far_horizon: the horizon cast by terrain at least `threshold_m`
 *    metres away only (the sweep of ts_horizon_sweep, with each line's
 *    convex hull holding only the samples that far behind the cell).
 *  - ts_far_shadow: the binary far-shadow map of one sun position.
 *  - the atlas: a day's binary maps, each cut into 8 x 8 tiles; every
 *    distinct 64-bit tile is stored once in a dictionary and each map
 *    becomes an index map into it; dictionary and index maps are each
 *    compressed with LZMA (xz). The file format is docs/atlas-format.md.
 *
 * Binary planes are bytes: 0 = lit, 1 = in shadow, TS_ATLAS_NODATA =
 * nodata. No GDAL, no global state.
 */
#ifndef TS_SHADOW_ATLAS_H
#define TS_SHADOW_ATLAS_H

#include <stddef.h>
#include <stdint.h>

#include "terrashade.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Value of a nodata cell in a binary plane. */
#define TS_ATLAS_NODATA 255
/** Side of the tiles of the dictionary. */
#define TS_ATLAS_TILE 8
/** Version of the file format written and read (2: the step table and
 * the metadata text under a CRC-32; version 1 files are refused). */
#define TS_ATLAS_VERSION 2
/** Size of the fixed header (versions 1 and 2), bytes. */
#define TS_ATLAS_HEADER_SIZE 168
/** Size of one step record, bytes. */
#define TS_ATLAS_STEP_SIZE 40

/* ------------------------------------------------------------ far field */

/**
 * Far-field horizon toward `azimuth` (degrees): like ts_horizon_sweep,
 * but only terrain at a distance of at least `threshold_m` metres (> 0)
 * along the sweep line counts. `out` width*height signed angles in
 * degrees, -90 where no such terrain exists, NaN for nodata. Earth
 * curvature as opts says; opts->max_distance must be 0. O(cells log n).
 */
ts_status ts_far_horizon(const ts_grid *grid, double azimuth, double threshold_m,
                         const ts_horizon_opts *opts, float *out, ts_error *err);

/**
 * The far field of ts_far_horizon as slopes (tangents of the angles, with
 * the curvature term; -inf where no far terrain exists, NaN for nodata)
 * seen by observers standing `dz` metres above each cell (dz < 0: below).
 * Two heights give a cell's far field as a function of the observer's
 * height: the windowed driver places its full-resolution cells on a
 * coarse grid's far field so (plugin/tsd_window_far.c).
 */
ts_status ts_far_slope_raised(const ts_grid *grid, double azimuth, double threshold_m,
                              double dz, const ts_horizon_opts *opts, float *out,
                              ts_error *err);

/**
 * Binary far-shadow map of a point sun at (azimuth, elevation): 1 where
 * ts_far_horizon is above `elevation`, 0 where not, TS_ATLAS_NODATA for
 * nodata. `out` width*height bytes.
 */
ts_status ts_far_shadow(const ts_grid *grid, double azimuth, double elevation,
                        double threshold_m, const ts_horizon_opts *opts,
                        uint8_t *out, ts_error *err);

/* ---------------------------------------------------------------- atlas */

/** What an atlas says about one of its maps (NaN where unknown). */
typedef struct {
    double unix_time;      /**< the instant, Unix seconds */
    double azimuth;        /**< sun's true azimuth, degrees */
    double grid_azimuth;   /**< sun's azimuth in the grid, degrees */
    double elevation;      /**< sun's apparent elevation, degrees */
    int32_t utc_offset_minutes; /**< offset of the local time written */
} ts_atlas_step;

/** What an atlas says about itself. */
typedef struct {
    int width, height, steps;
    int threshold_cells;      /**< far threshold in cells (0 = unknown) */
    double threshold_m;       /**< far threshold in metres (NaN = unknown) */
    int has_geotransform;
    double geotransform[6];   /**< GDAL's, of the maps as stored */
    int has_nodata;           /**< some cells are TS_ATLAS_NODATA */
    uint32_t dictionary_tiles;/**< distinct tiles */
    int index_bytes;          /**< 2 or 4 */
    const char *metadata;     /**< "KEY=VALUE\n" lines (UTF-8), never NULL */
    size_t dictionary_bytes;  /**< compressed sizes in the file */
    size_t index_bytes_total;
    size_t file_bytes;
} ts_atlas_info;

typedef struct ts_atlas_writer ts_atlas_writer;

/** Start an atlas of width x height maps (both >= 1). */
ts_status ts_atlas_writer_new(int width, int height, ts_atlas_writer **out,
                              ts_error *err);

/**
 * Add one map: width*height bytes with row stride `stride`, values 0, 1
 * or TS_ATLAS_NODATA (the same nodata cells in every map). `step` (may be
 * NULL) describes it. The tiles are looked up in the dictionary at once;
 * the map itself is not kept.
 */
ts_status ts_atlas_writer_add(ts_atlas_writer *w, const uint8_t *plane,
                              ptrdiff_t stride, const ts_atlas_step *step,
                              ts_error *err);

/**
 * Finish: compress and lay out the file. `info` gives the georeferencing,
 * threshold and metadata text (its width, height, steps and sizes are
 * ignored; metadata may be NULL). *bytes (free with free()) receives the
 * whole file, *size its length.
 */
ts_status ts_atlas_writer_finish(ts_atlas_writer *w, const ts_atlas_info *info,
                                 uint8_t **bytes, size_t *size, ts_error *err);

/** Free a writer, finished or not (NULL: nothing). */
void ts_atlas_writer_free(ts_atlas_writer *w);

/**
 * Check a step table of n maps: each time NaN (none) or an instant between
 * the years -2000 and 6000, every map with a time or none, times
 * increasing and within one day (less than 24 h from the first to the
 * last), azimuths NaN or 0..360, elevations NaN or -90..90, UTC offsets
 * within +/-23:59. `what` begins the message ("the atlas's step table is
 * invalid"). The writer and the reader both apply it.
 */
ts_status ts_atlas_check_steps(const ts_atlas_step *steps, int n, const char *what,
                               ts_error *err);

/** 1 if the first n bytes start like an atlas file (the magic). */
int ts_atlas_identify(const uint8_t *head, size_t n);

typedef struct ts_atlas ts_atlas;

/**
 * Read an atlas file from memory (the bytes are copied where needed; the
 * caller may free them afterwards). Checks the magic, version (1 is
 * refused: recreate the atlas), the header's CRC, the CRC of the step table
 * and metadata text, the steps (ts_atlas_check_steps), sizes and every
 * index; a damaged, truncated or forged file is an error that says what is
 * wrong.
 */
ts_status ts_atlas_open(const uint8_t *bytes, size_t size, ts_atlas **out,
                        ts_error *err);

/**
 * The checks of ts_atlas_open that need only the header, for a reader that
 * has not read the file yet: `head` holds its first head_n bytes (at least
 * TS_ATLAS_HEADER_SIZE, or the whole file when it is shorter), file_size is
 * its size. The magic, version, header size, header CRC and the sections'
 * offsets and sizes are checked, with ts_atlas_open's messages; TS_OK means
 * the header says the file holds exactly file_size bytes, so a file with
 * bytes beyond its last section, or a truncated one, is refused before it
 * is read (rather than read whole first).
 */
ts_status ts_atlas_check_header(const uint8_t *head, size_t head_n, uint64_t file_size,
                                ts_error *err);

/** The atlas's header (size, steps, georeferencing, metadata text); owned
 * by the atlas, valid until ts_atlas_free. */
const ts_atlas_info *ts_atlas_get_info(const ts_atlas *a);

/** The record of map `step` (0-based), or NULL. */
const ts_atlas_step *ts_atlas_get_step(const ts_atlas *a, int step);

/**
 * Decode the window (x0, y0, w, h) of map `step` into out (row stride
 * `stride` bytes): 0, 1 or TS_ATLAS_NODATA.
 */
ts_status ts_atlas_read(const ts_atlas *a, int step, int x0, int y0, int w,
                        int h, uint8_t *out, ptrdiff_t stride, ts_error *err);

/** Free an opened atlas (NULL: nothing). */
void ts_atlas_free(ts_atlas *a);

#ifdef __cplusplus
}
#endif

#endif /* TS_SHADOW_ATLAS_H */
