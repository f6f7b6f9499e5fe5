#!/usr/bin/python3
"""Draws envlight_conventions.png (docs/envlight.md): where a lat-long map and
a cube-face map point on the terrain at ENV_ROTATION=0. Needs numpy and PIL.

    /usr/bin/python3 docs/img/envlight_conventions.py   # writes beside itself
"""
import os

import numpy as np
from PIL import Image, ImageDraw, ImageFont

W, H = 720, 360          # the lat-long panel
PAD, CUBE = 60, 56       # margins, cube face size
FONT = ImageFont.load_default()


def sky_colours(h):
    """Blue above the horizon, brown below, darker towards the poles."""
    lat = 90 - 180 * np.arange(h) / (h - 1)
    sky = np.array([110, 160, 230]) * (0.55 + 0.45 * np.cos(np.radians(lat)))[:, None]
    ground = np.array([150, 120, 80]) * (0.55 + 0.45 * np.cos(np.radians(lat)))[:, None]
    return np.where((lat >= 0)[:, None], sky, ground).astype(np.uint8)


def main():
    img = Image.new("RGB", (W + 3 * PAD + CUBE + 120, H + 2 * PAD), "white")
    rows = sky_colours(H)
    img.paste(Image.fromarray(np.repeat(rows[:, None, :], W, axis=1)), (PAD, PAD))
    d = ImageDraw.Draw(img)
    d.rectangle([PAD, PAD, PAD + W, PAD + H], outline="black")
    # columns: azimuth 360 i / (w - 1) - 180 at ENV_ROTATION=0
    for frac, name, az in ((0, "S", "-180"), (0.25, "W", "-90"), (0.5, "N", "0"),
                           (0.75, "E", "90"), (1, "S", "180")):
        x = PAD + frac * W
        d.line([x, PAD, x, PAD + H], fill="black" if frac in (0, 1) else (60, 60, 60))
        d.text((x - 4, PAD + H + 6), name, fill="black", font=FONT)
        d.text((x - 10, PAD + H + 20), "az " + az if frac == 0.5 else az, fill="black",
               font=FONT)
    d.text((PAD + 0.25 * W + 6, PAD + H // 2 - 14), "map +X", fill="black", font=FONT)
    d.text((PAD + 0.5 * W + 6, PAD + H // 2 - 14), "map +Z (centre column)", fill="black",
           font=FONT)
    d.line([PAD, PAD + H // 2, PAD + W, PAD + H // 2], fill="white")
    for y, name in ((PAD, "zenith (row 0, +90)"), (PAD + H // 2, "horizon (0)"),
                    (PAD + H, "nadir (last row, -90)")):
        d.text((PAD + W + 8, y - 5), name, fill="black", font=FONT)
    d.text((PAD, 12), "lat-long map (2:1), ENV_ROTATION=0: the centre column is grid north, "
           "east to its right; ENV_ROTATION=t turns the sky clockwise by t", fill="black",
           font=FONT)
    d.text((PAD, 28), "column i at azimuth 360 i/(w-1) - 180, row j at elevation "
           "90 - 180 j/(h-1) (pixel centres on the poles and at +-180)", fill="black",
           font=FONT)
    # cube faces stacked top to bottom
    x0 = PAD + W + 150
    faces = [("+X", "west"), ("-X", "east"), ("+Y", "up"), ("-Y", "down"), ("+Z", "north"),
             ("-Z", "south")]
    top = PAD + (H - 6 * CUBE) // 2
    d.text((x0 - 10, top - 30), "cube map (1:6)", fill="black", font=FONT)
    for k, (face, where) in enumerate(faces):
        y = top + k * CUBE
        d.rectangle([x0, y, x0 + CUBE, y + CUBE], outline="black",
                    fill=(200, 215, 240) if where != "down" else (210, 190, 160))
        d.text((x0 + 8, y + CUBE // 2 - 12), face, fill="black", font=FONT)
        d.text((x0 + 8, y + CUBE // 2 + 2), where, fill="black", font=FONT)
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "envlight_conventions.png")
    img.save(out)
    print("wrote", out)


if __name__ == "__main__":
    main()
