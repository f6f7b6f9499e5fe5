#!/bin/sh
# Make (once) a Python venv with rvt-py, the Relief Visualization Toolbox
# (https://github.com/EarthObservation/RVT_py), for tests/driver/test_rvt.py,
# and print its python. Usage: tests/rvt-venv.sh DIR
#
# The venv sees the system site packages (/usr/bin/python3's numpy, scipy
# and osgeo); rvt-py is installed without its dependencies, because pip
# would otherwise pull a numpy 2 into the venv that the system's osgeo
# cannot import. rvt.vis needs only numpy and scipy.
set -e
RVT_VERSION=2.2.3
dir=${1:?usage: rvt-venv.sh DIR}
py="$dir/bin/python"
if [ -x "$py" ] && "$py" -c "import rvt.vis" 2>/dev/null; then
    echo "$py"
    exit 0
fi
rm -rf "$dir"
/usr/bin/python3 -m venv --system-site-packages "$dir" >&2 ||
    { echo "rvt-venv.sh: cannot make a venv in $dir (is python3-venv installed?)" >&2; exit 1; }
"$py" -m pip install --quiet --disable-pip-version-check --no-deps "rvt-py==$RVT_VERSION" >&2 ||
    { echo "rvt-venv.sh: pip cannot install rvt-py==$RVT_VERSION from PyPI (offline?)" >&2; exit 1; }
"$py" -c "import rvt.vis" >&2 ||
    { echo "rvt-venv.sh: rvt-py==$RVT_VERSION is installed but rvt.vis does not import" >&2; exit 1; }
echo "$py"
