"""terrashade.distributed: DEST, the output file: its format and tiles, the
partial file written first, and its rename into place."""
import contextlib
import os
import socket
import uuid

from osgeo import gdal

from terrashade._distributed_report import Failure

SIDE_FILES = (".aux.xml", ".ovr", ".msk")  # GDAL's beside a GeoTIFF


def output_format(args):
    if args.format:
        return args.format
    low = args.dest.lower()
    if low.endswith((".cog.tif", ".cog.tiff")):
        return "COG"
    if low.endswith((".tif", ".tiff")):
        return "GTiff"
    raise Failure("cannot tell the format of %s from its name: end it in .tif "
                  "(GeoTIFF) or .cog.tif (COG), or give --format GTiff|COG" % args.dest)


def block_size(tile):
    """The tiled GeoTIFF's internal tile size (DEST, or the one a COG is
    copied from): the window size up to 512, else the largest power of two
    up to 512 that divides it, so that every window covers whole tiles."""
    if tile <= 512:
        return tile
    b = 512
    while tile % b:
        b //= 2
    return b


def create_like(src, path, block, creation_options):
    """A tiled GeoTIFF at path with src's size, bands, types, nodata,
    georeferencing and metadata (what gdal_translate would copy)."""
    # the user's first: GDAL takes the first of a name given twice
    opts = list(creation_options) + ["TILED=YES", "BLOCKXSIZE=%d" % block,
                                     "BLOCKYSIZE=%d" % block, "BIGTIFF=IF_SAFER"]
    b1 = src.GetRasterBand(1)
    try:
        out = gdal.GetDriverByName("GTiff").Create(
            path, src.RasterXSize, src.RasterYSize, src.RasterCount, b1.DataType, opts)
    except RuntimeError as e:
        raise Failure("cannot write %s: %s" % (path, e))
    gt = src.GetGeoTransform(can_return_null=True)
    if gt is not None:  # else none, not the default, whose rows run south to north
        out.SetGeoTransform(gt)
    if src.GetProjection():
        out.SetProjection(src.GetProjection())
    out.SetMetadata(src.GetMetadata())
    for i in range(1, src.RasterCount + 1):
        s, d = src.GetRasterBand(i), out.GetRasterBand(i)
        d.SetDescription(s.GetDescription())
        d.SetColorInterpretation(s.GetColorInterpretation())
        d.SetMetadata(s.GetMetadata())
        if s.GetNoDataValue() is not None:
            d.SetNoDataValue(s.GetNoDataValue())
        if s.GetUnitType():
            d.SetUnitType(s.GetUnitType())
        if s.GetOffset() not in (None, 0.0):
            d.SetOffset(s.GetOffset())
        if s.GetScale() not in (None, 1.0):
            d.SetScale(s.GetScale())
    return out


# (device, inode) of the file finish() renames to DEST, once it is about to
RENAMED = []


def partial_names(dest):
    """The run's own partial files: the GeoTIFF its windows are written
    into, and the file renamed to DEST (the same, or its COG copy). Named by
    the machine, the process and a random part, so that two runs writing
    one DEST at once never share a file (they shared DEST.partial: the one
    still running wrote into the file the other had renamed to DEST, and
    left garbage there), also runs on other hosts or in containers, whose
    process numbers repeat. Another run's partial is never removed: that it
    is stale cannot be told from here (a run killed with SIGKILL leaves its
    own behind, to delete by hand)."""
    host = "".join(c if c.isalnum() or c in "-_" else "_" for c in socket.gethostname())
    tag = ".%s-%d-%s" % (host or "host", os.getpid(), uuid.uuid4().hex[:8])
    return dest + tag + ".tiles.partial", dest + tag + ".partial"


def finish(partial, fmt, dest, creation_options, cog_partial):
    """partial (closed GeoTIFF) -> dest, in fmt, by rename (a COG through
    its copy cog_partial)."""
    final = partial
    if fmt == "COG":
        final = cog_partial
        # The COG driver's own tiles (BLOCKSIZE 512, as gdal_translate -of COG),
        # not the windows': a copy need not match them, and a COG's tiles are
        # what its readers fetch, a request each (GDAL warns below 128).
        try:
            gdal.Translate(final, partial, format="COG",
                           creationOptions=list(creation_options))
        except RuntimeError as e:
            raise Failure("cannot write %s: %s" % (final, e))
        remove(partial)
    st = os.stat(final)
    RENAMED[:] = [(st.st_dev, st.st_ino)]  # an interrupt from here on: written()
    os.replace(final, dest)
    # An older DEST's side files described the old product and would be read
    # back for the new one (statistics, histograms, overviews, mask), as
    # gdal_translate's overwrite deletes them; once DEST is the new one, so
    # that a failed rename leaves the old DEST whole, side files too.
    for side in SIDE_FILES:
        with contextlib.suppress(FileNotFoundError):
            os.remove(dest + side)
    if os.path.exists(final + ".aux.xml"):
        os.replace(final + ".aux.xml", dest + ".aux.xml")


def remove(path):
    """path and its .aux.xml, our own files, if there are: a directory by
    that name, or any other cleanup failure, must not hide why the run
    failed."""
    for p in (path, path + ".aux.xml"):
        with contextlib.suppress(OSError):
            os.remove(p)


def written(dest):
    """Whether DEST is the file finish() renamed to it: an interrupt may
    come between any two steps, the rename's own included."""
    if not RENAMED:
        return False
    try:
        st = os.stat(dest)
    except OSError:
        return False
    return (st.st_dev, st.st_ino) == RENAMED[0]
