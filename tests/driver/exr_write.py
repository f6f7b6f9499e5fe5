"""A minimal OpenEXR writer for the tests (numpy only): one part, scanlines,
no compression, float R, G, B, and the `envmap` attribute (lat-long or cube)
when asked. Enough for maps OpenEXR's own tools read (exrheader, exrenvmap)
and the driver decodes; see the OpenEXR file layout (openexr.com,
"OpenEXR File Layout")."""
import struct

import numpy as np

ENVMAP = {"latlong": 0, "cube": 1}


def _attr(name, kind, payload):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) \
        + payload


def write_exr(path, rgb, envmap=None, names=("R", "G", "B")):
    """rgb: height x width x 3 floats, row 0 at the top (a lat-long map's
    zenith). envmap: None, "latlong" or "cube". names: the three planes'
    channel names (UTF-8), R, G, B by default."""
    rgb = np.ascontiguousarray(rgb, dtype="<f4")
    h, w = rgb.shape[:2]
    # channels are listed (and stored) in the order of their names' bytes
    order = sorted(range(3), key=lambda i: names[i].encode())
    chans = b""
    for i in order:
        chans += names[i].encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1)  # FLOAT
    chans += b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = b"".join([
        _attr("channels", "chlist", chans),
        _attr("compression", "compression", b"\0"),  # NO_COMPRESSION
        _attr("dataWindow", "box2i", box),
        _attr("displayWindow", "box2i", box),
        _attr("lineOrder", "lineOrder", b"\0"),  # INCREASING_Y
        _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        _attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ])
    if envmap is not None:
        header += _attr("envmap", "envmap", bytes([ENVMAP[envmap]]))
    head = struct.pack("<ii", 20000630, 2) + header + b"\0"
    line_bytes = w * 3 * 4
    first = len(head) + 8 * h
    offsets = [first + y * (8 + line_bytes) for y in range(h)]
    with open(path, "wb") as f:
        f.write(head)
        f.write(struct.pack("<%dQ" % h, *offsets))
        for y in range(h):
            f.write(struct.pack("<ii", y, line_bytes))
            for i in order:
                f.write(rgb[y, :, i].tobytes())
    return path


def write_black_zip_exr(path, w, h):
    """A lat-long map of w x h black HALF pixels, ZIP-compressed in blocks of
    16 scanlines: a few hundred KB that decode to 12 bytes a pixel (a
    security audit's 404 KB file of 11584 x 5792 took 877 MB at open)."""
    import zlib
    chans = b"".join(n + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1)  # HALF
                     for n in (b"B", b"G", b"R")) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = b"".join([
        _attr("channels", "chlist", chans),
        _attr("compression", "compression", b"\3"),  # ZIP, 16 lines a block
        _attr("dataWindow", "box2i", box),
        _attr("displayWindow", "box2i", box),
        _attr("lineOrder", "lineOrder", b"\0"),
        _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        _attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
        _attr("envmap", "envmap", bytes([ENVMAP["latlong"]])),
    ])
    head = struct.pack("<ii", 20000630, 2) + header + b"\0"
    blocks = (h + 15) // 16
    # zeros stay zeros through the predictor and the byte interleave
    full = zlib.compress(bytes(16 * w * 6), 9)
    last = zlib.compress(bytes((h - 16 * (blocks - 1)) * w * 6), 9)
    offsets, body, at = [], [], len(head) + 8 * blocks
    for i in range(blocks):
        data = last if i == blocks - 1 else full
        offsets.append(at)
        body.append(struct.pack("<ii", 16 * i, len(data)) + data)
        at += 8 + len(data)
    with open(path, "wb") as f:
        f.write(head + struct.pack("<%dQ" % blocks, *offsets) + b"".join(body))
    return path
