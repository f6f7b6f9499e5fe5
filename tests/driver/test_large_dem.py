"""A DEM far larger than the process may use (issue 10 item 5,
docs/windows.md): VRT mosaics of one 512 x 512 tile repeated (no disk
cost), with overviews as large DEMs have them, read under an address-space
limit (prlimit --as) of the process's own start-up size plus 1 GiB:

- a 512 x 512 window of shade on a 65 536^2 DEM (16 GiB of float heights)
  comes back in seconds, equal to the same window computed whole on a small
  mosaic of the same tile;
- gdal_translate writes the whole shade of a 16 384^2 DEM (1 GiB of float
  heights), with its progress bar.
"""
import os
import shutil
import subprocess
import time
import unittest

import tsdriver as T
from tsdriver import gdal, np, osr

TILE = 512
GT0 = (500000.0, 10.0, 0.0, 5000000.0, 0.0, -10.0)
GIB = 1 << 30
# a cheap product: shade at a high sun needs no far field (docs/windows.md)
SHADE = {"PRODUCT": "shade", "SUN_ELEVATION": 60, "SUN_AZIMUTH": 135,
         "BACKEND": "c", "THREADS": 2}
# glibc reserves 64 MiB of address space per thread arena
LEAN = {"MALLOC_ARENA_MAX": "2", "GDAL_CACHEMAX": "64"}


def srs_wkt():
    s = osr.SpatialReference()
    s.ImportFromEPSG(32632)
    return s.ExportToWkt()


def mosaic(path, size, tile_path, tile, overview=None):
    """A size x size VRT of tile_path (tile x tile) repeated."""
    k = size // tile
    esc = srs_wkt().replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;")
    parts = ['<VRTDataset rasterXSize="%d" rasterYSize="%d"><SRS>%s</SRS>' % (size, size, esc),
             "<GeoTransform>%s</GeoTransform>" % ", ".join(
                 repr(v * (1 if i in (0, 3) else TILE / tile)) for i, v in enumerate(GT0)),
             '<VRTRasterBand dataType="Float32" band="1">']
    if overview:
        parts.append('<Overview><SourceFilename relativeToVRT="1">%s</SourceFilename>'
                     "<SourceBand>1</SourceBand></Overview>" % os.path.basename(overview))
    src = os.path.basename(tile_path)
    for j in range(k):
        for i in range(k):
            parts.append('<SimpleSource><SourceFilename relativeToVRT="1" shared="1">%s'
                         "</SourceFilename><SourceBand>1</SourceBand>"
                         '<SrcRect xOff="0" yOff="0" xSize="%d" ySize="%d"/>'
                         '<DstRect xOff="%d" yOff="%d" xSize="%d" ySize="%d"/></SimpleSource>'
                         % (src, tile, tile, i * tile, j * tile, tile, tile))
    parts.append("</VRTRasterBand></VRTDataset>")
    with open(path, "w") as f:
        f.write("".join(parts))
    return path


def start_size():
    """Address space (VmPeak) of gdal_translate once GDAL and the plugin are
    loaded: it waits there for /vsistdin/."""
    p = subprocess.Popen(["gdal_translate", "-q", "/vsistdin/", "/vsimem/x.tif"],
                         stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, env=T.env(**LEAN))
    peak, last = 0, -1
    try:
        for _ in range(100):
            time.sleep(0.1)
            with open("/proc/%d/status" % p.pid) as f:
                for line in f:
                    if line.startswith("VmPeak:"):
                        peak = int(line.split()[1]) * 1024
            if peak == last:
                break
            last = peak
    finally:
        p.kill()
        p.wait()
        p.stdin.close()
    return peak


class LargeDEM(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir().__enter__()
        t = os.path.join(cls.tmp, "tile.tif")
        T.write_tif(t, T.fractal_dem(TILE, seed=3, relief=300.0), GT0, 32632)
        for factor in (8, 32):  # the tile's overviews, as gdaladdo -r average makes them
            gdal.Translate(os.path.join(cls.tmp, "tile_%d.tif" % factor), t,
                           width=TILE // factor, height=TILE // factor, resampleAlg="average")
        cls.tile = t
        cls.limit = start_size() + GIB
        print("address-space limit: %.0f MiB (gdal_translate's start-up size + 1 GiB)"
              % (cls.limit / 2 ** 20))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def big(self, size, factor):
        """A size^2 mosaic with its overview mosaic at 1/factor."""
        d = self.tmp
        ovr = mosaic(os.path.join(d, "ovr_%d.vrt" % size), size // factor,
                     os.path.join(d, "tile_%d.tif" % factor), TILE // factor)
        return mosaic(os.path.join(d, "dem_%d.vrt" % size), size, self.tile, TILE, ovr)

    def limited(self, args):
        t0 = time.monotonic()
        p = T.run(["prlimit", "--as=%d" % self.limit, "--"] + args, **LEAN)
        return p, time.monotonic() - t0

    def test_window_of_65536(self):
        dem = self.big(65536, 32)
        out = os.path.join(self.tmp, "w.tif")
        x0 = 30000
        opts = dict(SHADE, TILE_SIZE=512, NEAR_DISTANCE=2000, OUTPUT_TYPE="Float32")
        p, sec = self.limited(["gdal_translate", "-q", "-srcwin", x0, x0, 512, 512]
                              + T.oo_args(opts) + [T.conn(dem), out])
        print("512 x 512 window of shade on a 65536^2 DEM: %.1f s" % sec)
        self.assertLess(sec, 60)
        win = T.read(out, 1)
        # the same window of the periodic DEM, computed whole on a small mosaic
        small = mosaic(os.path.join(self.tmp, "small.vrt"), 4 * TILE, self.tile, TILE)
        whole = T.read(T.translate(small, os.path.join(self.tmp, "s.tif"),
                                   dict(SHADE, TILE_SIZE=0, OUTPUT_TYPE="Float32")), 1)
        o = TILE + x0 % TILE
        ref = whole[o:o + 512, o:o + 512]
        agree = np.mean(np.abs(win - ref) <= 1e-3)
        print("agreement with the whole computation: %.4f %%" % (100 * agree))
        self.assertGreaterEqual(agree, 0.999)

    def test_translate_16384(self):
        dem = self.big(16384, 8)
        out = os.path.join(self.tmp, "all.tif")
        p, sec = self.limited(["gdal_translate", "-co", "COMPRESS=DEFLATE", "-co", "TILED=YES"]
                              + T.oo_args(dict(SHADE, TILE_SIZE=2048, NEAR_DISTANCE=300))
                              + [T.conn(dem), out])
        print("gdal_translate of shade on a 16384^2 DEM (1 GiB of heights): %.1f s" % sec)
        self.assertIn("100 - done", p.stdout)
        ds = gdal.Open(out)
        self.assertEqual((ds.RasterXSize, ds.RasterYSize), (16384, 16384))
        # away from the edges the shade repeats with the tile's period (but for
        # the sub-cell placement of the sweep lines, which differs by period)
        a = ds.GetRasterBand(1).ReadAsArray(4096, 4096, 1024, 1024).astype(int)
        self.assertGreaterEqual(np.mean(np.abs(a[:512] - a[512:]) <= 1), 0.999)
        self.assertGreater(np.count_nonzero(a), 0.99 * a.size)


if __name__ == "__main__":
    unittest.main(verbosity=2)
