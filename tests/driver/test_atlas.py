"""The far-shadow atlas through GDAL (issue 5, item 4).

- PRODUCT=farshadow: one binary band per sun position of the day (denser
  near dawn and dusk), each with its time and sun, far shadows only;
- gdal_translate -of TERRASHADE writes it as an atlas (*.tsa: 8 x 8 tile
  dictionary + index maps + LZMA, docs/atlas-format.md), and GDAL reads the
  file back, recognised by its magic, identical to the uncompressed result:
  pixels, nodata, band metadata, dataset metadata, georeferencing;
- SHADOWS=all recomputes the near shadows on read and gives the full
  shadows;
- bits per cell per day on jacksboro; bad sources and damaged files give
  clear errors.
"""
import datetime
import os
import shutil
import struct
import sys
import unittest
import zlib

import tsdriver as T
from tsdriver import gdal, np

DAY = {"PRODUCT": "farshadow", "DATE": "2026-12-21", "TIMEZONE": "-05:00",
       "FAR_THRESHOLD": 24, "ATLAS_STEPS": 32}


def oo(d):
    return ["%s=%s" % kv for kv in d.items()]


def forge(data, text=None, step=None, version=None):
    """An atlas rewritten as a hostile or careless writer would, with valid
    CRCs (docs/atlas-format.md): another metadata text (str), step record
    `step` = (k, field offset, struct format, value), or version."""
    h = bytearray(data[:168])
    n = struct.unpack_from("<I", h, 24)[0]
    so, to, tn, do, dn, io, inn = struct.unpack_from("<7Q", h, 104)
    steps = bytearray(data[so:so + 40 * n])
    old_text = data[to:to + tn]
    new_text = old_text if text is None else text.encode()
    if step is not None:
        k, at, fmt, value = step
        struct.pack_into(fmt, steps, 40 * k + at, value)
    if version is not None:
        struct.pack_into("<I", h, 8, version)
    rest = data[do:do + dn] + data[io:io + inn]
    to = 168 + len(steps)
    do = to + len(new_text)
    struct.pack_into("<7Q", h, 104, 168, to, len(new_text), do, dn, do + dn, inn)
    struct.pack_into("<I", h, 160, zlib.crc32(bytes(h[:160])))
    struct.pack_into("<I", h, 164, zlib.crc32(new_text, zlib.crc32(bytes(steps))))
    return bytes(h) + bytes(steps) + new_text + rest


def gap(data, k):
    """The atlas with k garbage bytes after its header, its sections'
    offsets moved past them and its header's CRC made again."""
    import struct
    import zlib
    head = bytearray(data[:168])
    for off in (104, 112, 128, 144):  # steps, text, dictionary, index offsets
        struct.pack_into("<Q", head, off, struct.unpack_from("<Q", head, off)[0] + k)
    struct.pack_into("<I", head, 160, zlib.crc32(bytes(head[:160])))
    return bytes(head) + bytes([0x5A] * k) + data[168:]


def band_metadata(ds):
    return [(ds.GetRasterBand(b).GetDescription(), ds.GetRasterBand(b).GetMetadata())
            for b in range(1, ds.RasterCount + 1)]


class Atlas(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = T.TempDir()
        cls.dir = cls.tmp.__enter__()
        cls.tsa = os.path.join(cls.dir, "jacksboro.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + sum(
            (["-oo", o] for o in oo(DAY)), []) + [T.conn(T.JACKSBORO), cls.tsa])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.__exit__(None, None, None)

    def test_farshadow_product(self):
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=oo(DAY))
        self.assertEqual(ds.RasterCount, 32)
        self.assertAlmostEqual(float(ds.GetMetadataItem("FAR_THRESHOLD_M")),
                               24 * float(ds.GetMetadataItem("CELL_SIZE_X_NORTH")), places=3)
        times, share = [], []
        for b in range(1, 33):
            rb = ds.GetRasterBand(b)
            self.assertEqual(rb.DataType, gdal.GDT_Byte)
            self.assertEqual(rb.GetNoDataValue(), 255)
            m = rb.GetMetadata()
            self.assertEqual(rb.GetDescription(), m["TIME"])
            self.assertTrue(m["TIME"].startswith("2026-12-21T") and m["TIME"].endswith("-05:00"))
            self.assertGreater(float(m["SUN_ELEVATION"]), -0.3)
            times.append(float(m["UNIX_TIME"]))
            a = rb.ReadAsArray()
            self.assertTrue(set(np.unique(a)) <= {0, 1})
            share.append(a.mean())
        gaps = np.diff(times) / 60
        print("farshadow: %d maps %s .. %s; gaps %.1f min at dawn, %.1f at noon; in far "
              "shadow: %.1f%% at dawn, %.1f%% at noon" % (
                  len(times), ds.GetRasterBand(1).GetDescription(),
                  ds.GetRasterBand(32).GetDescription(), gaps[0], gaps[15],
                  100 * share[0], 100 * share[16]))
        self.assertTrue(np.all(gaps > 0))
        self.assertLess(gaps[0], 0.5 * gaps[15])
        self.assertGreater(share[0], share[16])

    def test_far_shadows_are_shadows(self):
        """A cell in far shadow is in shadow: against the exact shadow of the
        same sun (PRODUCT=shadow at the band's instant)."""
        ds = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=oo(DAY))
        for b in (1, 8, 16, 32):
            far = ds.GetRasterBand(b).ReadAsArray() == 1
            t = float(ds.GetRasterBand(b).GetMetadataItem("UNIX_TIME"))
            dt = datetime.datetime.fromtimestamp(t, datetime.timezone.utc)
            iso = dt.strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"
            full = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": "shadow", "DATETIME": iso}) < 0.5
            inside = full[far].mean() if far.any() else 1.0
            print("band %2d (%s): %.2f%% far shadow, %.2f%% shadow; %.3f%% of far shadow "
                  "lies in shadow" % (b, iso, 100 * far.mean(), 100 * full.mean(),
                                      100 * inside))
            self.assertGreater(inside, 0.99)

    def test_round_trip_is_identical(self):
        """The atlas reads back as the uncompressed product: pixels, nodata,
        band descriptions and metadata, dataset metadata, georeferencing."""
        src = gdal.OpenEx(T.conn(T.JACKSBORO), open_options=oo(DAY))
        ds = gdal.Open(self.tsa)
        self.assertEqual(ds.GetDriver().ShortName, "TERRASHADE")
        self.assertEqual(gdal.IdentifyDriver(self.tsa).ShortName, "TERRASHADE")
        self.assertEqual(ds.RasterCount, src.RasterCount)
        for b in range(1, ds.RasterCount + 1):
            np.testing.assert_array_equal(ds.GetRasterBand(b).ReadAsArray(),
                                          src.GetRasterBand(b).ReadAsArray())
            self.assertEqual(ds.GetRasterBand(b).GetNoDataValue(), 255)
            self.assertEqual(ds.GetRasterBand(b).DataType, gdal.GDT_Byte)
        self.assertEqual(band_metadata(ds), band_metadata(src))
        self.assertEqual(ds.GetMetadata(), src.GetMetadata())
        self.assertEqual(ds.GetGeoTransform(), src.GetGeoTransform())
        self.assertTrue(ds.GetSpatialRef().IsSame(src.GetSpatialRef()))
        size = os.path.getsize(self.tsa)
        raw = src.RasterXSize * src.RasterYSize
        print("jacksboro atlas, FAR_THRESHOLD=24, 32 maps: %d bytes = %.4f bits per cell "
              "per day (%.1f x smaller than one bit per cell per map)"
              % (size, size * 8.0 / raw, raw * 32 / 8.0 / size))
        # any window, any order
        a = ds.GetRasterBand(7).ReadAsArray(100, 50, 123, 77)
        np.testing.assert_array_equal(a, src.GetRasterBand(7).ReadAsArray(100, 50, 123, 77))

    def test_round_trip_through_geotiff_and_python(self):
        tif = os.path.join(self.dir, "far.tif")
        T.translate(T.JACKSBORO, tif, DAY)
        tsa = os.path.join(self.dir, "from_tif.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE", tif, tsa])
        np.testing.assert_array_equal(T.read(tsa), T.read(tif))
        self.assertEqual(band_metadata(gdal.Open(tsa))[5][1]["TIME"],
                         band_metadata(gdal.Open(tif))[5][1]["TIME"])
        py = os.path.join(self.dir, "python.tsa")
        out = gdal.GetDriverByName("TERRASHADE").CreateCopy(py, gdal.Open(tif))
        self.assertIsNotNone(out)
        out = None
        np.testing.assert_array_equal(T.read(py), T.read(tif))

    def test_nodata_round_trip(self):
        """lux_elev has nodata outside Luxembourg: 255 in every map, kept."""
        d = dict(DAY, FAR_THRESHOLD=4, ATLAS_STEPS=12)
        tsa = os.path.join(self.dir, "lux.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + sum(
            (["-oo", o] for o in oo(d)), []) + [T.conn(T.LUX), tsa])
        src = gdal.OpenEx(T.conn(T.LUX), open_options=oo(d))
        ds = gdal.Open(tsa)
        for b in range(1, 13):
            a = ds.GetRasterBand(b).ReadAsArray()
            np.testing.assert_array_equal(a, src.GetRasterBand(b).ReadAsArray())
        print("lux: %.1f%% nodata, %.1f%% far shadow in map 1"
              % (100 * np.mean(a == 255), 100 * np.mean(
                  ds.GetRasterBand(1).ReadAsArray() == 1)))
        self.assertGreater(np.mean(a == 255), 0.2)

    def test_default_threshold_bits_per_cell(self):
        """The defaults (512 cells, 158 maps): jacksboro is smaller than the
        threshold, so its maps are empty; the atlas costs almost nothing."""
        d = {"PRODUCT": "farshadow", "DATE": "2026-06-21", "TIMEZONE": "-04:00"}
        tsa = os.path.join(self.dir, "default.tsa")
        T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + sum(
            (["-oo", o] for o in oo(d)), []) + [T.conn(T.JACKSBORO), tsa])
        ds = gdal.Open(tsa)
        self.assertEqual(ds.RasterCount, 158)
        bits = os.path.getsize(tsa) * 8.0 / (ds.RasterXSize * ds.RasterYSize)
        print("jacksboro atlas with the defaults (FAR_THRESHOLD=512, 158 maps): %d bytes "
              "= %.4f bits per cell per day" % (os.path.getsize(tsa), bits))
        self.assertLessEqual(bits, 3.0)

    def test_shadows_all_recomputes_the_near_shadows(self):
        """SHADOWS=all: far shadows from the atlas OR near shadows recomputed
        from the DEM (horizon within the threshold above the sun) = the full
        shadow of the same sun."""
        far = gdal.Open(self.tsa)
        ds = gdal.OpenEx(self.tsa, open_options=["SHADOWS=all"])
        for b in (1, 16, 32):
            f = far.GetRasterBand(b).ReadAsArray()
            a = ds.GetRasterBand(b).ReadAsArray()
            self.assertTrue(np.all(a >= f))
            t = float(ds.GetRasterBand(b).GetMetadataItem("UNIX_TIME"))
            iso = datetime.datetime.fromtimestamp(t, datetime.timezone.utc).strftime(
                "%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"
            full = T.read(T.conn(T.JACKSBORO), 1, {"PRODUCT": "shadow", "DATETIME": iso}) < 0.5
            agree = np.mean((a == 1) == full)
            print("band %2d: far %.2f%%, far | near %.2f%%, full shadow %.2f%%, agree %.3f%%"
                  % (b, 100 * np.mean(f == 1), 100 * np.mean(a == 1), 100 * full.mean(),
                     100 * agree))
            self.assertGreater(agree, 0.995)
        # the DEM can be named when the atlas's SOURCE_DEM is gone
        named = gdal.OpenEx(self.tsa, open_options=["SHADOWS=all", "DEM=" + T.JACKSBORO])
        self.assertEqual(named.GetRasterBand(1).Checksum(), ds.GetRasterBand(1).Checksum())

    def test_bad_sources_and_damaged_files(self):
        out = os.path.join(self.dir, "bad.tsa")
        p = T.run(["gdal_translate", "-of", "TERRASHADE", T.JACKSBORO, out], ok=False)
        print(p.stderr.strip().splitlines()[-1])
        self.assertIn("the source is not a far-shadow product", p.stderr)
        self.assertIn("PRODUCT is missing", p.stderr)
        self.assertFalse(os.path.exists(out))
        # a far-shadow product whose values were changed
        tif = os.path.join(self.dir, "edited.tif")
        T.run(["gdal_translate", "-q", self.tsa, tif])
        ds = gdal.Open(tif, gdal.GA_Update)
        ds.GetRasterBand(3).WriteArray(np.full((2, 2), 7, np.uint8), 10, 20)
        ds = None
        p = T.run(["gdal_translate", "-of", "TERRASHADE", tif, out], ok=False)
        self.assertIn("band 3 holds the value 7 at column 10, row 20", p.stderr)
        self.assertIn("binary maps", p.stderr)
        self.assertFalse(os.path.exists(out))
        with open(self.tsa, "rb") as f:
            data = f.read()
        cases = [("truncated", data[:len(data) // 2], "truncated"),
                 ("header", data[:20] + bytes([data[20] ^ 1]) + data[21:], "damaged"),
                 ("index", data[:-40] + bytes([data[-40] ^ 0x20]) + data[-39:], "damaged"),
                 ("version", data[:8] + bytes([9]) + data[9:], "version 9"),
                 # bytes after the last section, under no checksum, were read
                 ("appended", data + bytes(100), "100 bytes follow its last section"),
                 # 128 bytes between the header and the first section, the
                 # offsets moved and the header's CRC made again: no checksum
                 ("gap", gap(data, 128), "gaps or overlaps between them")]
        for name, blob, text in cases:
            with self.subTest(name):
                path = os.path.join(self.dir, name + ".tsa")
                with open(path, "wb") as f:
                    f.write(blob)
                p = T.run(["gdalinfo", path], ok=False)
                print("%-9s -> %s" % (name, [l for l in p.stderr.splitlines()
                                             if "TERRASHADE" in l][0]))
                self.assertIn(text, p.stderr)
                # a file that does not read: CPLE_FileIO (docs/driver.md, Errors)
                self.assertIn("ERROR 3: TERRASHADE", p.stderr)
        for opts, text in ((["SHADOWS=near"], "SHADOWS must be one of far, all"),
                           (["PRODUCT=shade"], "an atlas takes the open options")):
            with self.assertRaises(RuntimeError) as e:
                gdal.OpenEx(self.tsa, open_options=opts)
            self.assertIn(text, str(e.exception))
        with self.assertRaises(RuntimeError) as e:
            gdal.Open(self.tsa, gdal.GA_Update)
        self.assertIn("read-only", str(e.exception))

    def test_sparse_file_refused_before_it_is_read(self):
        """An atlas was read whole into memory (any size below 1 TiB) before
        its header was checked: a 3 GB file of a header and a hole cost 3 GB
        of memory, a /vsicurl/ one its whole download. Now the header is
        checked against the file's size first, and nothing more is read."""
        with open(self.tsa, "rb") as f:
            data = f.read()
        # the child's peak RSS as VmHWM: its ru_maxrss starts from this
        # process's, which Linux carries across fork and exec
        child = ("import sys\n"
                 "from osgeo import gdal\n"
                 "gdal.UseExceptions()\n"
                 "try:\n"
                 "    gdal.Open(sys.argv[1])\n"
                 "    print('opened')\n"
                 "except RuntimeError as e:\n"
                 "    print(e)\n"
                 "print('peak_kb', [l.split()[1] for l in open('/proc/self/status')\n"
                 "                    if l.startswith('VmHWM:')][0])\n")
        size = 3 << 30
        for name, blob in (("header and a hole", data[:168]),
                           ("atlas and a hole", data)):
            with self.subTest(name):
                path = os.path.join(self.dir, "sparse.tsa")
                with open(path, "wb") as f:
                    f.write(blob)
                    f.truncate(size)
                p = T.run([sys.executable, "-c", child, path])
                os.remove(path)
                rss_mb = int(p.stdout.split("peak_kb")[1]) // 1024
                print("%-17s -> %s (peak RSS %d MB)" % (name, p.stdout.splitlines()[0],
                                                      rss_mb))
                # (the header says the file ends where the atlas does)
                self.assertIn("%d bytes follow its last section" % (size - len(data)),
                              p.stdout)
                self.assertLess(rss_mb, 200)

    def write(self, name, blob):
        path = os.path.join(self.dir, name)
        with open(path, "wb") as f:
            f.write(blob)
        return path

    def refused(self, path, sentence, options=()):
        with self.assertRaises(RuntimeError) as e:
            ds = gdal.OpenEx(path, open_options=list(options))
            ds.GetRasterBand(1).ReadAsArray()
        print("%-18s -> %s" % (os.path.basename(path), e.exception))
        self.assertIn(sentence, str(e.exception))
        return str(e.exception)

    def test_writes_and_deletes_only_its_own_files(self):
        """A failed write removed whatever the path named (as root /dev/full
        itself, a symlink, a write-protected file of another user): now a
        path that is not a regular file is refused and left as it is, and
        only a file this write opened is removed, the reason said. A damaged
        atlas, which did not open, could be neither deleted nor renamed."""
        d = os.path.join(self.dir, "own")
        os.mkdir(d)
        # (a pipe hangs in GDAL's own look at the destination, as for GTiff)
        folder, link = os.path.join(d, "folder.tsa"), os.path.join(d, "link.tsa")
        os.mkdir(folder)
        os.symlink(os.path.join(d, "missing", "x.tsa"), link)
        for path, text in ((folder, "it exists and is not a regular file"),
                           (link, "No such file or directory")):
            p = T.run(["gdal_translate", "-q", "-of", "TERRASHADE", self.tsa, path], ok=False)
            self.assertIn("cannot write the atlas '%s': %s" % (path, text), p.stderr)
            self.assertTrue(os.path.lexists(path), path)
        self.assertTrue(os.path.islink(link))
        # a damaged atlas (its header's CRC) is deleted and renamed as a file
        with open(self.tsa, "rb") as f:
            data = bytearray(f.read())
        data[20] ^= 0xFF
        drv = gdal.GetDriverByName("TERRASHADE")
        for op in ("rename", "delete"):
            bad = os.path.join(d, "bad_%s.tsa" % op)
            with open(bad, "wb") as f:
                f.write(data)
            with open(bad + ".aux.xml", "w") as f:
                f.write("<PAMDataset/>")
            if op == "delete":
                self.assertEqual(drv.Delete(bad), gdal.CE_None)
                self.assertFalse(os.path.exists(bad) or os.path.exists(bad + ".aux.xml"))
            else:
                new = os.path.join(d, "renamed.tsa")
                self.assertEqual(drv.Rename(new, bad), gdal.CE_None)
                self.assertTrue(os.path.exists(new) and os.path.exists(new + ".aux.xml"))
                self.assertFalse(os.path.exists(bad))
        # a file that is no atlas is not touched
        plain = os.path.join(d, "plain.tsa")
        with open(plain, "w") as f:
            f.write("my notes")
        with self.assertRaises(RuntimeError):
            drv.Delete(plain)
        self.assertTrue(os.path.exists(plain))

    def test_metadata_validated_like_options(self):
        """Each value of the metadata text goes through the option table; the
        message gives the real cause."""
        with open(self.tsa, "rb") as f:
            data = f.read()
        text = gdal.Open(self.tsa).GetMetadata()
        lines = ["%s=%s" % kv for kv in text.items()]

        def with_item(key, value):
            return "\n".join([l for l in lines if not l.startswith(key + "=")]
                             + ["%s=%s" % (key, value)]) + "\n"
        cases = [
            ("Z_FACTOR", "nan", "Z_FACTOR must be AUTO or a number, got 'nan'"),
            ("Z_FACTOR", "-1", "Z_FACTOR must be greater than 0 and at most 1e+06, got -1"),
            ("BAND", "0", "BAND must be between 1 and 65536, got 0"),
            ("CURVATURE", "maybe", "CURVATURE must be YES or NO, got 'maybe'"),
            ("THREADS", "abc", "THREADS must be a whole number, got 'abc'"),
            ("REFRACTION", "7", "REFRACTION must be between 0 and 1, got 7"),
            ("PRODUCT", "shade", "PRODUCT must be farshadow, got 'shade'"),
            ("ATLAS_STEPS", "5", "ATLAS_STEPS=5, but there are 32 map(s)"),
            ("DATE", "2026-13-45", "DATE: "),
            ("UTC_OFFSET_MINUTES", "abc", "UTC_OFFSET_MINUTES must be a whole number"),
            ("FAR_THRESHOLD_M", "-3", "FAR_THRESHOLD_M must be a distance in metres"),
            ("SRS_WKT", "not a crs", "SRS_WKT is not a CRS GDAL can read"),
        ]
        for key, value, sentence in cases:
            with self.subTest(key=key, value=value):
                path = self.write("meta_%s.tsa" % key.lower(), forge(data, with_item(key, value)))
                msg = self.refused(path, "atlas metadata: " + sentence)
                self.assertNotIn("does not match", msg)
        # no PRODUCT at all
        path = self.write("noproduct.tsa", forge(
            data, "\n".join(l for l in lines if not l.startswith("PRODUCT=")) + "\n"))
        self.refused(path, "atlas metadata: PRODUCT is missing")
        # BAND=99 is a valid option, but not of this DEM: said so, not a size mismatch
        path = self.write("band99.tsa", forge(data, with_item("BAND", "99")))
        forged, kept = gdal.Open(path), gdal.Open(self.tsa)
        self.assertEqual(forged.GetRasterBand(1).Checksum(), kept.GetRasterBand(1).Checksum())
        forged = kept = None
        self.refused(path, "SHADOWS=all: the atlas's metadata says BAND=99, but the DEM '%s' "
                     "has 1 band(s)" % T.JACKSBORO, ["SHADOWS=all"])
        # the text changed without its CRC
        bad = bytearray(data)
        at = data.index(b"CURVATURE=YES") + len("CURVATURE=")
        bad[at:at + 3] = b"NO\n"
        self.refused(self.write("nocrc.tsa", bytes(bad)),
                     "step table or metadata text is damaged (CRC32 mismatch)")

    def test_step_table_validated(self):
        with open(self.tsa, "rb") as f:
            data = f.read()
        cases = [
            ("time_garbage", (4, 0, "<d", -9.2e18), "map 5's time, -9.2e+18 Unix seconds, "
             "is not an instant between the years -2000 and 6000"),
            ("time_back", (4, 0, "<d", 1.7e9), "map 5's time (1700000000.000) is not after"),
            ("time_nan", (0, 0, "<d", float("nan")), "map 2 has a time but map 1 has none: "
             "either every map has one or none has"),
            ("elevation", (2, 24, "<d", 123.0), "map 3's sun elevation (123) lies outside"),
            ("offset", (1, 32, "<i", 99999), "map 2's offset from UTC (99999 minutes)"),
        ]
        for name, step, sentence in cases:
            with self.subTest(name):
                path = self.write("step_%s.tsa" % name, forge(data, step=step))
                self.refused(path, "the atlas's step table is invalid: " + sentence)
        # every time missing: allowed by the format, not by a far-shadow atlas
        blob = data
        for k in range(32):
            blob = forge(blob, step=(k, 0, "<d", float("nan")))
        self.refused(self.write("step_none.tsa", blob),
                     "atlas step table: map 1 has no time, but every map of "
                     "PRODUCT=farshadow has one")

    def test_version_1_is_refused(self):
        with open(self.tsa, "rb") as f:
            data = f.read()
        msg = self.refused(self.write("v1.tsa", forge(data, version=1)),
                           "format version 1, whose metadata and step table carry no "
                           "checksum")
        self.assertIn("recreate the atlas", msg)

    def test_atlas_as_its_own_dem(self):
        self.refused(self.tsa, "SHADOWS=all: the DEM '%s' is a far-shadow atlas (.tsa), not "
                     "a DEM" % self.tsa, ["SHADOWS=all", "DEM=" + self.tsa])
        with open(self.tsa, "rb") as f:
            data = f.read()
        text = ["%s=%s" % kv for kv in gdal.Open(self.tsa).GetMetadata().items()
                if kv[0] != "SOURCE_DEM"] + ["SOURCE_DEM=" + self.tsa]
        path = self.write("self.tsa", forge(data, "\n".join(text) + "\n"))
        self.refused(path, "(the atlas's SOURCE_DEM) is a far-shadow atlas (.tsa), not a DEM",
                     ["SHADOWS=all"])

    def test_relative_source_dem_is_the_atlas_folders(self):
        """An atlas written from a relative DEM records it relative to the
        atlas's folder, and reads it from there: opened from another folder,
        where a file of the DEM's name held other terrain, SHADOWS=all read
        that one without a word (session 46)."""
        here = os.getcwd()
        work = os.path.join(self.dir, "rel")
        os.makedirs(os.path.join(work, "atlases"), exist_ok=True)
        os.makedirs(os.path.join(work, "elsewhere"), exist_ok=True)
        shutil.copy(T.JACKSBORO, os.path.join(work, "dem.tif"))
        # a decoy of the same name and size, flat, where the reader runs
        T.run(["gdal_translate", "-q", "-scale", "0", "5000", "0", "0", "-ot", "Float32",
               T.JACKSBORO, os.path.join(work, "elsewhere", "dem.tif")])
        try:
            os.chdir(work)
            T.run(["gdal_translate", "-q", "-of", "TERRASHADE"] + sum(
                (["-oo", o] for o in oo(DAY)), []) + ["TERRASHADE:dem.tif",
                                                       os.path.join("atlases", "day.tsa")])
            with open("atlases/day.tsa", "rb") as f:  # the metadata text as stored
                self.assertIn(b"\nSOURCE_DEM=../dem.tif\n", f.read())
            # as opened: where that is from here, so that a copy elsewhere finds it
            self.assertEqual(gdal.Open("atlases/day.tsa").GetMetadataItem("SOURCE_DEM"),
                             os.path.realpath("dem.tif"))
            os.chdir(os.path.join(work, "elsewhere"))
            ds = gdal.OpenEx("../atlases/day.tsa", open_options=["SHADOWS=all"])
            got = ds.GetRasterBand(16).ReadAsArray()
            ds = None
        finally:
            os.chdir(here)
        ref = gdal.OpenEx(self.tsa, open_options=["SHADOWS=all"])  # (kept while read)
        np.testing.assert_array_equal(got, ref.GetRasterBand(16).ReadAsArray())

    def test_shadows_all_dem_checked_at_open(self):
        """SHADOWS=all checks its DEM when the atlas opens (a QGIS layer
        opened, then failed block by block): there, of the atlas's size, on
        the same ground and in the same CRS; DEM= only with SHADOWS=all; a
        copy of far and near shadows is no atlas source."""
        moved = os.path.join(self.dir, "moved.tif")
        T.run(["gdal_translate", "-q", "-a_ullr", "-84", "36.5", "-83.6", "36.2",
               T.JACKSBORO, moved])
        other_crs = os.path.join(self.dir, "other_crs.tif")
        T.run(["gdal_translate", "-q", "-a_srs", "EPSG:4269", T.JACKSBORO, other_crs])
        for options, sentence in (
                (["SHADOWS=all", "DEM=" + moved], "does not lie where the atlas does"),
                (["SHADOWS=all", "DEM=" + other_crs], "is in another CRS"),
                (["SHADOWS=all", "DEM=/nonexistent/dem.tif"],
                 "SHADOWS=all cannot open the DEM '/nonexistent/dem.tif'"),
                (["DEM=" + T.JACKSBORO], "DEM applies with SHADOWS=all only")):
            with self.subTest(options=options):
                with self.assertRaises(RuntimeError) as e:
                    gdal.OpenEx(self.tsa, open_options=options)
                print("%-40s -> %s" % (options[-1][-24:], e.exception))
                self.assertIn(sentence, str(e.exception))
        all_tif = os.path.join(self.dir, "all.tif")
        T.run(["gdal_translate", "-q", "-oo", "SHADOWS=all", self.tsa, all_tif])
        self.assertEqual(gdal.Open(all_tif).GetMetadataItem("SHADOWS"), "all")
        p = T.run(["gdal_translate", "-of", "TERRASHADE", all_tif,
                   os.path.join(self.dir, "from_all.tsa")], ok=False)
        self.assertIn("the source holds far and near shadows", p.stderr)

    def test_gdaladdo_and_a_threshold_longer_than_the_dem(self):
        """gdaladdo on an atlas gets a TERRASHADE sentence (GDAL's own said
        'BuildOverviews() not supported'); a FAR_THRESHOLD as long as the
        DEM's longer side (the default 512 on jacksboro) warns that the maps
        are empty, as all 158 of a day's were, without a word."""
        p = T.run(["gdaladdo", self.tsa, "2"], ok=False)
        self.assertIn("TERRASHADE: %s: a far-shadow atlas is read-only" % self.tsa, p.stderr)
        day = dict(DAY)
        day.pop("FAR_THRESHOLD", None)
        p = T.run(["gdalinfo"] + sum((["-oo", o] for o in oo(day)), []) + [T.conn(T.JACKSBORO)])
        self.assertIn("FAR_THRESHOLD=512 cells is as long as the DEM's longer side (403 x 344 "
                      "cells) or longer", p.stderr)
        p = T.run(["gdalinfo"] + sum((["-oo", o] for o in oo(DAY)), []) + [T.conn(T.JACKSBORO)])
        self.assertNotIn("FAR_THRESHOLD", p.stderr)

    def test_atlas_is_no_dem_of_a_product(self):
        """TERRASHADE:day.tsa computed a product from the atlas's 0/1 maps
        as heights; refused, as DEM=day.tsa is."""
        for conn in (T.conn(self.tsa), "TERRASHADE:PRODUCT=svf:" + self.tsa):
            with self.subTest(conn=conn):
                with self.assertRaises(RuntimeError) as e:
                    gdal.OpenEx(conn, gdal.OF_RASTER)
                self.assertIn("is a far-shadow atlas (.tsa), not a DEM", str(e.exception))

    def test_shadows_all_refuses_what_are_not_heights(self):
        """SHADOWS=all reads its DEM as a product's open does: a complex or
        signed-byte band is refused (it was read silently: the real part
        alone, or -8 m as 248 m)."""
        for name, args, sentence in (
                ("complex.tif", ["-ot", "CFloat32"], "is complex (CFloat32), not heights"),
                ("sbyte.tif", ["-ot", "Byte", "-scale", "0", "1100", "0", "255",
                               "-co", "PIXELTYPE=SIGNEDBYTE"], "holds signed bytes")):
            with self.subTest(dem=name):
                dem = os.path.join(self.dir, name)
                T.run(["gdal_translate", "-q"] + args + [T.JACKSBORO, dem])
                self.refused(self.tsa, "SHADOWS=all: band 1 of '%s' %s" % (dem, sentence),
                             ["SHADOWS=all", "DEM=" + dem])

    def test_shadows_all_refuses_a_product_as_its_dem(self):
        """DEM= a product, live or written to a file: its shading was taken
        as the near shadows' heights, with exit 0 (session 54's review)."""
        shade = os.path.join(self.dir, "shade_as_dem.tif")
        T.run(["gdal_translate", "-q", T.conn(T.JACKSBORO), shade])
        for dem, sentence in (
                (shade, "the DEM '%s' is a written TERRASHADE product (PRODUCT=shade of %s"
                 % (shade, T.JACKSBORO)),
                (T.conn(T.JACKSBORO), "the DEM '%s' is a TERRASHADE product, not a DEM"
                 % T.conn(T.JACKSBORO))):
            with self.subTest(dem=dem):
                with self.assertRaises(RuntimeError) as e:
                    gdal.OpenEx(self.tsa, open_options=["SHADOWS=all", "DEM=" + dem])
                self.assertIn(sentence, str(e.exception))

    def test_createcopy_refuses_other_sources(self):
        out = os.path.join(self.dir, "refused.tsa")
        # complex bands
        cpx = os.path.join(self.dir, "complex.tif")
        ds = gdal.GetDriverByName("GTiff").Create(cpx, 16, 16, 1, gdal.GDT_CFloat32)
        ds.SetMetadata(gdal.Open(self.tsa).GetMetadata())
        ds = None
        p = T.run(["gdal_translate", "-of", "TERRASHADE", cpx, out], ok=False)
        self.assertIn("band 1 of the source is complex (CFloat32)", p.stderr)
        # a far-shadow product cut to fewer bands: not what its metadata says
        p = T.run(["gdal_translate", "-of", "TERRASHADE", "-b", "1", self.tsa, out], ok=False)
        self.assertIn("the source is not a far-shadow product", p.stderr)
        self.assertIn("ATLAS_STEPS=32, but there are 1 map(s)", p.stderr)
        # another product of the DEM
        p = T.run(["gdal_translate", "-of", "TERRASHADE", "-oo", "PRODUCT=shadow",
                   T.conn(T.JACKSBORO), out], ok=False)
        self.assertIn("PRODUCT must be farshadow, got 'shadow'", p.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main(verbosity=2)
