/*
 * tsd_options_light.h - checks of the light's options (LIGHT_RADIUS,
 * METHOD=shadowmap with SHADOWMAP_SCALE and PCF_KERNEL) against the
 * product and the other options. Called by tsd_options_check.
 */
#ifndef TSD_OPTIONS_LIGHT_H
#define TSD_OPTIONS_LIGHT_H

#include <stddef.h>

#include "tsd_options.h"

/** 0, or -1 with a sentence in msg when the light's options make no sense
 * together or for the product. */
int tsd_options_check_light(const tsd_options *o, char *msg, size_t n);

#endif
