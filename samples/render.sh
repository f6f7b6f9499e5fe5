#!/bin/sh
# render.sh - the README's pictures of jacksboro.tif, through gdal_translate
# and the TERRASHADE plugin, next to plain gdaldem hillshade.
#
#   samples/render.sh [OUTDIR]          (default: samples/out)
#
# The plugin is taken from $BUILDDIR/plugin/.libs (BUILDDIR defaults to the
# current directory, so run it from the build tree after make), else from
# wherever GDAL finds it (GDAL_DRIVER_PATH, or the installed plugin).
# Reads only jacksboro.tif and envmaps/*.exr beside this script.
set -eu

HERE=$(cd "$(dirname "$0")" && pwd)
DEM="$HERE/jacksboro.tif"
MAPS="$HERE/envmaps"
OUT=${1:-$HERE/out}
BUILDDIR=${BUILDDIR:-$(pwd)}
if [ -f "$BUILDDIR/plugin/.libs/gdal_TERRASHADE.so" ]; then
    GDAL_DRIVER_PATH="$BUILDDIR/plugin/.libs"
    export GDAL_DRIVER_PATH
fi
if ! gdalinfo --formats | grep -q TERRASHADE; then
    echo "render.sh: GDAL cannot find the TERRASHADE driver; build it (make)" \
         "and run from the build directory, or set GDAL_DRIVER_PATH" >&2
    exit 1
fi
# PNGs only: no .aux.xml beside them, none beside the DEM
GDAL_PAM_ENABLED=NO
export GDAL_PAM_ENABLED
mkdir -p "$OUT"

run() {
    echo "\$ $*"
    "$@"
}

# 1. plain gdaldem hillshade, sun at 315 deg / 20 deg (degrees need a scale)
run gdaldem hillshade -q -az 315 -alt 20 -s 111120 -compute_edges -of PNG \
    "$DEM" "$OUT/hillshade_gdaldem.png"

# 2. the same sun with cast shadows, a little sky light in the shadows
run gdal_translate -q -of PNG \
    -oo SUN_AZIMUTH=315 -oo SUN_ELEVATION=20 -oo SKY_WEIGHT=0.25 \
    "TERRASHADE:$DEM" "$OUT/shade_terrashade.png"

# 3. shadow at low sun: visible fraction of the sun's disk, 0..1 -> 0..255
run gdal_translate -q -of PNG -ot Byte -scale 0 1 0 255 -a_nodata none \
    "TERRASHADE:PRODUCT=shadow,SUN_AZIMUTH=135,SUN_ELEVATION=5:$DEM" \
    "$OUT/shadow_low_sun.png"

# 4. sky-view factor, 32 directions, 0.88..1 stretched to 0..255
run gdal_translate -q -of PNG -ot Byte -scale 0.88 1 0 255 -a_nodata none \
    -oo PRODUCT=svf -oo DIRECTIONS=32 \
    "TERRASHADE:$DEM" "$OUT/svf.png"

# 5. a horizon band: 8 directions from 0, band 4 = azimuth 135, -5..25 deg
run gdal_translate -q -of PNG -ot Byte -b 4 -scale -5 25 0 255 -a_nodata none \
    "TERRASHADE:PRODUCT=horizon,DIRECTIONS=8:$DEM" "$OUT/horizon_135.png"

# 6. hours of sun on the winter solstice (local day at -05:00, 10-minute
#    steps), coloured: dark blue 0 h, through green, to yellow at 9.7 h (the
#    day length on open ground)
run gdal_translate -q -oo PRODUCT=sunhours -oo DATE=2026-12-21 -oo TIMEZONE=-05:00 \
    -oo STEP_MINUTES=10 "TERRASHADE:$DEM" "$OUT/sunhours_winter.tif"
cat > "$OUT/sunhours.ramp" <<'RAMP'
0    20  20  80
3    40  80 160
6    60 160 120
8.5 200 210  60
9.7 255 240 120
nv    0   0   0
RAMP
run gdaldem color-relief -q -of PNG "$OUT/sunhours_winter.tif" "$OUT/sunhours.ramp" \
    "$OUT/sunhours_winter.png"
rm -f "$OUT/sunhours_winter.tif" "$OUT/sunhours.ramp"

# 7. environment light (docs/envlight.md), 32 directions, Byte: the automatic
#    exposure (the brightest unshadowed surface -> 255) and the sRGB curve.
#    Under the two HDR maps, the CIE standard overcast sky, the CIE clear sky
#    with the sun of 8 am on the summer solstice (local time -05:00), and the
#    uniform sky (the sky product's light) to compare with.
envlight() {
    name=$1
    shift
    run gdal_translate -q -of PNG -oo PRODUCT=envlight -oo DIRECTIONS=32 \
        -oo OUTPUT_TYPE=Byte "$@" "TERRASHADE:$DEM" "$OUT/envlight_$name.png"
}
envlight sunset -oo ENV_MAP="$MAPS/sunset.exr"
envlight forest -oo ENV_MAP="$MAPS/forest.exr"
envlight overcast -oo SKY=overcast
envlight clear_8am -oo SKY=clear -oo DATETIME=2026-06-21T08:00:00-05:00
envlight uniform -oo SKY=uniform

# 8. shade: the sun and a CIE clear sky at 8 am on the solstice, one command
run gdal_translate -q -of PNG -oo DATETIME=2026-06-21T08:00:00-05:00 -oo SKY=clear \
    -oo SKY_WEIGHT=0.4 -oo DIRECTIONS=32 "TERRASHADE:$DEM" "$OUT/shade_clear_sky_8am.png"

echo "wrote:"
ls -l "$OUT"/*.png
