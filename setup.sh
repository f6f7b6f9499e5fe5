#!/usr/bin/env bash
# One command from a fresh Debian 12 checkout to rendered sample pictures:
# installs the Debian packages (as root, or through sudo), builds the core,
# the GDAL plugin and the tests, and renders samples/out/*.png from the real
# DEM in samples/ through gdal_translate.
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES="build-essential autoconf automake libtool pkg-config check valgrind
  libgdal-dev gdal-bin python3-gdal python3-numpy libproj-dev liblzma-dev
  libopenexr-dev openexr ocl-icd-opencl-dev opencl-headers pocl-opencl-icd
  qgis python3-qgis qgis-providers xauth clang
  python3-dask python3-distributed python3-rasterio python3-rioxarray
  qemu-user locales grass-core saga"

missing=$(dpkg-query -W -f='${db:Status-Abbrev} ${Package}\n' $PACKAGES 2>/dev/null |
          awk '$1 != "ii" {print $2}'; for p in $PACKAGES; do
          dpkg-query -W "$p" >/dev/null 2>&1 || echo "$p"; done)
if [ -n "$missing" ]; then
  SUDO=""
  [ "$(id -u)" = 0 ] || SUDO=sudo
  echo "setup: installing $(echo $missing | tr '\n' ' ')"
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
fi

[ -x configure ] || autoreconf -fi
[ -f Makefile ] || ./configure
make -j"$(nproc)"
bash samples/render.sh
echo "setup: done; pictures in samples/out/, run the tests with: make check"
