#!/usr/bin/python3
"""shadow_methods.py - docs/methods.md's shadow table, measured in one run.

    /usr/bin/python3 bench/shadow_methods.py ROUGH_TIF FBM_TIF WORKDIR [REPEATS]

Run by bench/shadow_methods_bench.sh, which makes ROUGH_TIF (the 4096^2
fractal of driver_bench.sh, very rough) and FBM_TIF (the same seed as fBm of
Hurst exponent 0.8, like real relief) and points GDAL at the plugin. For every shadow
method (METHOD=exact, shm, shadowmap, sh, and sh with HORIZON_METHOD=pyramid)
it prints
  - on jacksboro, lux_elev and both fractals, at the suns 135/10 and 315/30:
    the agreement of PRODUCT=shadow with the exact method's (lit where the
    visible fraction is at least 0.5, over the cells valid in both) and the
    mean |shadow - exact|;
  - on the rough fractal (driver_bench.sh's DEM): the time of PRODUCT=shade (the default sun) through
    gdal_translate with BACKEND=c and BACKEND=opencl (best wall time of
    REPEATS whole processes, with that run's CPU time and peak resident
    memory), beside gdaldem hillshade's in the same run;
then the whole as the markdown table of docs/methods.md.
"""
import os
import subprocess
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "tests", "data")
SUNS = [(135, 10), (315, 30)]
# (label, open options)
METHODS = [
    ("exact", {}),
    ("shm", {"METHOD": "shm"}),
    ("shadowmap", {"METHOD": "shadowmap"}),
    ("sh", {"METHOD": "sh"}),
    ("sh, pyramid horizons", {"METHOD": "sh", "HORIZON_METHOD": "pyramid"}),
]


def shadow(path, sun, opts):
    oo = ["PRODUCT=shadow", "SUN_AZIMUTH=%g" % sun[0], "SUN_ELEVATION=%g" % sun[1]]
    oo += ["%s=%s" % kv for kv in opts.items()]
    ds = gdal.OpenEx("TERRASHADE:" + path, open_options=oo)
    band = ds.GetRasterBand(1)
    a = band.ReadAsArray().astype(np.float64)
    nodata = band.GetNoDataValue()
    if nodata is not None and not np.isnan(nodata):
        a[a == nodata] = np.nan
    ds = None
    return a


def agreement(dems):
    """{(dem, sun, method): (agreement %, mean |d|)}"""
    out = {}
    for dem, path in dems:
        for sun in SUNS:
            ref = shadow(path, sun, {})
            for label, opts in METHODS:
                a = ref if not opts else shadow(path, sun, opts)
                v = np.isfinite(a) & np.isfinite(ref)
                agree = 100.0 * ((a[v] >= 0.5) == (ref[v] >= 0.5)).mean()
                mad = np.abs(a[v] - ref[v]).mean()
                out[(dem, sun, label)] = (agree, mad)
                print("   %-10s sun %3d/%2d  %-21s agreement %7.3f %%, mean |d| %.4f"
                      % (dem, sun[0], sun[1], label, agree, mad), flush=True)
    return out


def one_run(cmd, work):
    """(wall s, CPU s, peak RSS MiB) of one whole process"""
    tf = os.path.join(work, "time.txt")
    subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", "-o", tf] + cmd, check=True,
                   stdout=subprocess.DEVNULL)
    wall, user, sys_, kb = open(tf).read().split()[-4:]
    return float(wall), float(user) + float(sys_), float(kb) / 1024


def best_of(cmd, work, repeats):
    runs = []
    for _ in range(repeats):
        out = os.path.join(work, "out.tif")
        if os.path.exists(out):
            os.remove(out)
        runs.append(one_run(cmd, work))
    return min(runs)


def opencl_runs(path):
    """Whether BACKEND=opencl runs on OpenCL here (the driver falls back to C,
    with a warning, where it cannot): the metadata item BACKEND says."""
    ds = gdal.OpenEx("TERRASHADE:" + path, open_options=["BACKEND=opencl"])
    ds.GetRasterBand(1).Checksum()
    ran = (ds.GetMetadataItem("BACKEND") or "").lower()
    ds = None
    return ran.startswith("opencl")


def timing(fractal, work, repeats):
    """({(method, backend): (wall, cpu, rss)}, gdaldem's (wall, cpu, rss))"""
    out = os.path.join(work, "out.tif")
    backends = ["c"]
    if opencl_runs(os.path.join(DATA, "jacksboro.tif")):
        backends.append("opencl")
    else:
        print("   BACKEND=opencl falls back to C here (no OpenCL device): not timed")
    cmd = ["gdaldem", "hillshade", "-q", fractal, out]
    print("$ " + " ".join(cmd))
    ref = best_of(cmd, work, repeats)
    print("   gdaldem hillshade: %.3f s (CPU %.2f s, %.0f MiB)" % ref, flush=True)
    times = {}
    for backend in backends:
        for label, opts in METHODS:
            cmd = ["gdal_translate", "-q", "-oo", "BACKEND=" + backend]
            for kv in opts.items():
                cmd += ["-oo", "%s=%s" % kv]
            cmd += ["TERRASHADE:" + fractal, out]
            print("$ " + " ".join(cmd), flush=True)
            try:
                times[(label, backend)] = t = best_of(cmd, work, repeats)
            except subprocess.CalledProcessError as e:
                # e.g. no OpenCL platform on this machine: say so, time the rest
                times[(label, backend)] = None
                print("   failed (exit status %d): not timed" % e.returncode, flush=True)
                continue
            print("   %.3f s (CPU %.2f s, %.0f MiB), %.2fx gdaldem" % (t + (t[0] / ref[0],)),
                  flush=True)
    return times, ref


def table(agree, times, ref, size):
    print("\n| method | DEM | agreement at 135°/10° (mean \\|d\\|) | at 315°/30° | shade, "
          "rough %d², C | OpenCL (PoCL) | peak memory (C) |" % size)
    print("|---|---|---|---|---|---|---|")
    dems = ["jacksboro", "lux_elev", "fBm", "rough"]
    for label, _ in METHODS:
        for i, dem in enumerate(dems):
            cells = ["%.2f %% (%.3f)" % agree[(dem, sun, label)] for sun in SUNS]
            if i == 0:
                c, cl = times[(label, "c")], times.get((label, "opencl"))
                tail = ["%.2f s (%.1fx gdaldem)" % (c[0], c[0] / ref[0]) if c else "failed",
                        "%.2f s" % cl[0] if cl else "failed",
                        "%.0f MiB" % c[2] if c else ""]
            else:
                tail = ["", "", ""]
            print("| %s | %s | %s |" % (label if i == 0 else "", dem,
                                       " | ".join(cells + tail)))
    print("\ngdaldem hillshade on the same fractal: %.3f s, %.0f MiB" % (ref[0], ref[2]))


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: shadow_methods.py ROUGH_TIF FBM_TIF WORKDIR [REPEATS]")
    fractal, fbm, work = sys.argv[1], sys.argv[2], sys.argv[3]
    repeats = int(sys.argv[4]) if len(sys.argv) > 4 else 2
    dems = [("jacksboro", os.path.join(DATA, "jacksboro.tif")),
            ("lux_elev", os.path.join(DATA, "lux_elev.tif")),
            ("fBm", fbm), ("rough", fractal)]
    print("== shadow agreement with METHOD=exact (PRODUCT=shadow, lit where >= 0.5)")
    agree = agreement(dems)
    print("== shade on the rough fractal, best wall time of %d, CPU and peak RSS of that run"
          % repeats)
    times, ref = timing(fractal, work, repeats)
    ds = gdal.Open(fractal)
    size = ds.RasterXSize
    ds = None
    table(agree, times, ref, size)


if __name__ == "__main__":
    main()
