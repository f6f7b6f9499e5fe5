#!/bin/sh
# Makes sunset_cube128.exr, the cube-face copy of sunset.exr that
# tests/check_env_map.c compares with the lat-long original, with OpenEXR's
# own converter (Debian package openexr): faces of 128 x 128 pixels, its
# default filter (radius 1, 5 x 5 samples), tiled, half, ZIP.
set -eu
cd "$(dirname "$0")"
exrenvmap -c -w 128 sunset.exr sunset_cube128.exr
