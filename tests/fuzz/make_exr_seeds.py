"""Write the seed corpus of fuzz_exr: small, valid, uncompressed OpenEXR
environment maps (lat-long and cube faces, FLOAT and HALF channels), and a
few damaged copies; with OpenEXR's exrenvmap (openexr-tools, optional),
also a tiled ZIP lat-long map and a tiled PIZ cube map converted from them. Written by hand from the OpenEXR file layout (magic,
version, header attributes, offset table, scanline chunks), so no OpenEXR
Python binding is needed. The first byte of every seed is the rotation byte
fuzz_exr reads before the file itself.

    python3 tests/fuzz/make_exr_seeds.py tests/fuzz/corpus/fuzz_exr
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile

HALF, FLOAT = 1, 2


def attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr(width, height, envmap, ptype):
    chans = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1)
                     for c in "BGR") + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (attr("channels", "chlist", chans) +
              attr("compression", "compression", b"\0") +
              attr("dataWindow", "box2i", box) +
              attr("displayWindow", "box2i", box) +
              attr("envmap", "envmap", bytes([envmap])) +
              attr("lineOrder", "lineOrder", b"\0") +
              attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    head = struct.pack("<I", 20000630) + struct.pack("<I", 2) + header
    fmt = "<%de" % width if ptype == HALF else "<%df" % width
    chunks = []
    for y in range(height):
        data = b""
        for c in range(3):  # B, G, R: a gradient per colour, brighter up top
            data += struct.pack(fmt, *[(1.0 + c + x * 0.25) * (height - y) / height
                                       for x in range(width)])
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(head) + 8 * height
    table = b""
    for ch in chunks:
        table += struct.pack("<Q", offset)
        offset += len(ch)
    return head + table + b"".join(chunks)


def main(out):
    os.makedirs(out, exist_ok=True)
    seeds = {
        "valid_latlong_8x4_float.exr": exr(8, 4, 0, FLOAT),
        "valid_latlong_16x8_half.exr": exr(16, 8, 0, HALF),
        "valid_cube_2x12_float.exr": exr(2, 12, 1, FLOAT),
        "valid_latlong_1x1_half.exr": exr(1, 1, 0, HALF),
    }
    good = seeds["valid_latlong_8x4_float.exr"]
    seeds["edge_truncated.exr"] = good[:len(good) // 2]
    seeds["edge_wrong_magic.exr"] = b"\x77" + good[1:]
    bad = bytearray(good)
    bad[len(good) - 5] = 0xff  # a NaN-ish float in the last chunk
    bad[len(good) - 6] = 0xff
    seeds["edge_flipped_pixels.exr"] = bytes(bad)
    if shutil.which("exrenvmap"):
        with tempfile.TemporaryDirectory() as tmp:
            for name, src, args in [
                    ("valid_latlong_8x4_tiled_zip.exr", "valid_cube_2x12_float.exr",
                     ["-l", "-w", "8", "-z", "zip"]),
                    ("valid_cube_4x24_tiled_piz.exr", "valid_latlong_8x4_float.exr",
                     ["-c", "-w", "4", "-z", "piz"])]:
                i, o = os.path.join(tmp, "in.exr"), os.path.join(tmp, name)
                with open(i, "wb") as f:
                    f.write(seeds[src])
                subprocess.run(["exrenvmap"] + args + [i, o], check=True)
                with open(o, "rb") as f:
                    seeds[name] = f.read()
    for name, data in seeds.items():
        rotation = bytes([len(name) % 256])
        with open(os.path.join(out, name), "wb") as f:
            f.write(rotation + data)


if __name__ == "__main__":
    main(sys.argv[1])
