"""terrashade.distributed: the run's inputs: the command line, parsed and
checked, and SOURCE, the TERRASHADE connection string (its options, its
DEM's path as the workers must read it, and the client's open)."""
import argparse
import os
import re

from osgeo import gdal

from terrashade import windows as W
from terrashade._distributed_report import SAID, Failure

PROG = "terrashade.distributed"
TILE_MIN, TILE_MAX = 16, 65536


def tile_size(text):
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError("must be a whole number, got %r" % text)
    if n < TILE_MIN or n > TILE_MAX or n % 16:
        raise argparse.ArgumentTypeError(
            "must be a multiple of 16 between %d and %d (GeoTIFF tiles are "
            "multiples of 16), got %d" % (TILE_MIN, TILE_MAX, n))
    return n


def positive(text):
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError("must be a whole number >= 1, got %r" % text)
    return n


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog=PROG, description="Compute a TERRASHADE product window by window "
        "on dask.distributed and write it as a tiled GeoTIFF or COG.")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an existing Dask scheduler (tcp://host:8786); every "
                       "worker must read the DEM by the same path and find the plugin")
    where.add_argument("--workers", type=positive, metavar="N",
                       help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--threads-per-worker", type=positive, default=1, metavar="N",
                   help="threads of each local worker (default 1)")
    p.add_argument("--tile-size", type=tile_size, default=1024, metavar="N",
                   help="window size in cells, a multiple of 16 (default 1024)")
    p.add_argument("-oo", dest="open_options", action="append", default=[],
                   metavar="KEY=VALUE", help="an open option of the driver (repeatable)")
    p.add_argument("--format", choices=["GTiff", "COG"],
                   help="output format (default: COG for *.cog.tif, else GTiff)")
    p.add_argument("-co", dest="creation_options", action="append", default=[],
                   metavar="NAME=VALUE", help="a creation option of the output driver")
    p.add_argument("--timeout", type=positive, default=10, metavar="SECONDS",
                   help="how long to try to reach --scheduler, to wait for its answer "
                   "during the run, and to wait for a worker when the cluster has none "
                   "(default 10)")
    p.add_argument("-q", "--quiet", action="store_true",
                   help="no progress bar and no summary line")
    p.add_argument("source", metavar="SOURCE", help="TERRASHADE:[KEY=VALUE,...:]dem.tif")
    p.add_argument("dest", metavar="DEST", help="output .tif (GeoTIFF) or .cog.tif (COG)")
    args = p.parse_args(argv)
    for oo in args.open_options:
        if not re.match(r"^[A-Za-z_]\w*=", oo):
            p.error("-oo takes KEY=VALUE, got %r" % oo)
    return args


# The driver's inline option segment (plugin/tsd_connstr.c): KEY=VALUE items,
# an ASCII identifier as KEY with blanks allowed around it, up to the first ':'.
_ITEM = r" *[A-Za-z_][A-Za-z0-9_]* *=[^,:]*"
INLINE = re.compile(r"^(%s(?:,%s)*):" % (_ITEM, _ITEM))


def split_source(source):
    """SOURCE's inline option segment with its ':' ("" if none) and the DEM."""
    rest = source[len("TERRASHADE:"):]
    m = INLINE.match(rest)
    return (rest[:m.end()], rest[m.end():]) if m else ("", rest)


def given_keys(source, open_options):
    """Upper-case names of the options given inline in SOURCE or by -oo."""
    inline = split_source(source)[0]
    items = list(open_options) + (inline[:-1].split(",") if inline else [])
    return {item.split("=", 1)[0].strip().upper() for item in items}


ARCHIVES = ("/vsizip/", "/vsigzip/", "/vsitar/")


def _archive_split(path):
    """(prefix, rest, braced) of a /vsizip/, /vsigzip/ or /vsitar/ path:
    braced where the archive's name is in braces (/vsizip/{a.zip}/dem.tif;
    not /vsigzip/'s, which has no such form); None for any other path."""
    prefix = next((a for a in ARCHIVES if path.startswith(a)), "")
    if not prefix:
        return None
    rest = path[len(prefix):]
    return prefix, rest, prefix != "/vsigzip/" and rest.startswith("{") and "}" in rest


def archive_of(path):
    """(prefix, archive, rest) where path reads inside an archive file here
    (/vsizip/, /vsigzip/, /vsitar/; its name in braces, or the longest
    leading part that is a file), path == prefix + archive + rest; None
    where it names none."""
    split = _archive_split(path)
    if split is None:
        return None
    prefix, rest, braced = split
    if braced:
        name, after = rest[1:].split("}", 1)
        return (prefix + "{", name, "}" + after) if name and os.path.isfile(name) else None
    cut = [i for i in range(len(rest), 0, -1)
           if (i == len(rest) or rest[i] == "/") and os.path.isfile(rest[:i])]
    return (prefix, rest[:cut[0]], rest[cut[0]:]) if cut else None


def local_file(name):
    """The file here that name reads: itself, or its archive (a DEST onto
    dem.zip replaced the archive of /vsizip/dem.zip/dem.tif); None for
    another virtual file system's or a name that is no file."""
    split = _archive_split(name)
    if split is not None:  # /vsitar//vsigzip/dem.tar.gz/...: the outer file
        _, rest, braced = split
        inner = rest[1:].split("}", 1)[0] if braced else rest
        if inner.startswith(ARCHIVES):
            return local_file(inner)
    parts = archive_of(name)
    if parts is not None:
        return parts[1]
    return name if name and not name.startswith("/vsi") and os.path.exists(name) else None


def absolute_path(text):
    """text (a name, quoted or not) made absolute if it is a relative path
    that exists here, plainly or inside /vsizip/, /vsigzip/ or /vsitar/
    (the archive's path; as the driver does for its overview levels); None
    if it is not one."""
    quoted = len(text) > 1 and text[0] == text[-1] == '"'
    path = text[1:-1] if quoted else text
    if path.startswith(ARCHIVES):
        parts = archive_of(path)
        if parts is None or os.path.isabs(parts[1]):
            return None
        path = parts[0] + os.path.abspath(parts[1]) + parts[2]
        return '"%s"' % path if quoted else path
    if not path or os.path.isabs(path) or path.startswith("/vsi") or not os.path.exists(path):
        return None
    path = os.path.abspath(path)
    return '"%s"' % path if quoted else path


def absolute_source(source):
    """SOURCE with a relative DEM path that exists here made absolute: each
    worker would resolve it in its own working directory (an existing
    cluster's workers do not share the client's), and read another file of
    that name, or none. Also the file inside another driver's name
    (GTIFF_DIR:1:dem.tif, NETCDF:"dem.nc":z, GPKG:dem.gpkg:table): the
    first part between its ':' that is a relative path existing here, but
    not the driver's name nor a number, nor what follows the file (a file or
    folder named GTIFF_DIR, 1 or z here is not what those parts mean)."""
    head, dem = split_source(source)
    whole = absolute_path(dem)
    if whole is not None:
        return "TERRASHADE:" + head + whole
    if os.path.exists(dem):  # (an absolute or virtual path, or nothing to do)
        return source
    parts = dem.split(":")
    fixed, found = parts[:1], False
    for p in parts[1:]:  # the file: the first part that is one (not what follows it)
        whole = None if found or p.isdigit() else absolute_path(p)
        found = found or whole is not None
        fixed.append(whole or p)
    if len(parts) < 2 or fixed == parts:
        return source
    return "TERRASHADE:" + head + ":".join(fixed)


def absolute_env_map(source, open_options):
    """(SOURCE, open options) with a relative ENV_MAP that exists here made
    absolute, inline or given by -oo: as the DEM, each worker read it in its
    own working directory, another map of that name (the pixels a forest's
    under the client's sunset's metadata), or none. An inline one moves to
    the open options: its absolute path may hold the ':' or ',' that end an
    inline value."""
    def whole(item):
        key, sep, value = item.partition("=")
        if key.strip().upper() != "ENV_MAP" or not sep:
            return None
        path = absolute_path(value.strip())
        return None if path is None else "ENV_MAP=" + path.strip('"')
    options = [whole(i) or i for i in open_options]
    head, dem = split_source(source)
    if head:
        items = head[:-1].split(",")
        moved = [whole(i) for i in items]
        kept = [i for i, m in zip(items, moved) if m is None]
        options += [m for m in moved if m is not None]
        source = "TERRASHADE:" + (",".join(kept) + ":" if kept else "") + dem
    return source, options


def open_source(source, open_options):
    if not source.upper().startswith("TERRASHADE:"):
        raise Failure("SOURCE must be a TERRASHADE connection string "
                      "(TERRASHADE:[KEY=VALUE,...:]dem.tif), got %r" % source)
    if gdal.GetDriverByName("TERRASHADE") is None:
        raise Failure(W.no_driver("on this machine", os.environ.get("GDAL_DRIVER_PATH", "")))
    said = W.Warnings()
    gdal.PushErrorHandler(said)
    try:
        return gdal.OpenEx(source, gdal.OF_RASTER | gdal.OF_READONLY,
                           open_options=open_options)
    except RuntimeError as e:
        raise Failure("cannot open %s: %s" % (source, e))
    finally:
        gdal.PopErrorHandler()
        SAID.say(said.messages)
