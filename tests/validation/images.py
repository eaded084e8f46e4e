# SPDX-License-Identifier: MIT
"""Test images with known pixels, written without any imaging library: 16-bit PNGs (what
POV-Ray writes) and float PFMs, which OpenImageIO's oiiotool turns into EXRs (what Whitted
writes). Pixels are addressed as (x, y, channel), column from the left, row from the top."""

import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import run  # noqa: E402  (tests/harness.py)


def _chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def png16(path, width, height, codes, overrides=None, channels=3):
    """A 16-bit PNG (RGB, or RGBA with alpha 65535) whose every pixel is `codes` (one per colour
    channel) except `overrides` {(x, y, channel): code}."""
    overrides = overrides or {}
    rows = []
    for y in range(height):
        row = bytearray(b"\x00")  # filter: none
        for x in range(width):
            for c in range(channels):
                value = codes[c] if c < 3 else 65535
                row += struct.pack(">H", overrides.get((x, y, c), value))
        rows.append(bytes(row))
    colour_type = 2 if channels == 3 else 6
    data = (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, colour_type, 0, 0, 0))
            + _chunk(b"IDAT", zlib.compress(b"".join(rows))) + _chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


def png_claiming(path, width, height):
    """A well-formed PNG of a few bytes whose header claims width x height (16-bit RGB)."""
    data = (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 2, 0, 0, 0))
            + _chunk(b"IDAT", zlib.compress(b"")) + _chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


def pfm(path, width, height, value, overrides=None, channels=3):
    """A float PFM (RGB, or grey with channels=1) of `value` except `overrides`; the values
    may be float("nan") or float("inf")."""
    overrides = overrides or {}
    header = b"PF\n" if channels == 3 else b"Pf\n"
    values = []
    for y in reversed(range(height)):  # PFM stores the bottom row first
        for x in range(width):
            for c in range(channels):
                values.append(overrides.get((x, y, c), value))
    with open(path, "wb") as f:
        f.write(header + b"%d %d\n-1.0\n" % (width, height) + struct.pack("<%df" % len(values), *values))


def exr(oiiotool, path, width, height, value, overrides=None, channels=3):
    """A float EXR: written as a PFM and converted by oiiotool (NaN and Inf survive)."""
    if not oiiotool or oiiotool.endswith("NOTFOUND") or not os.path.exists(oiiotool):
        raise SystemExit("oiiotool (OpenImageIO's tool; Debian: openimageio-tools) is needed and was not found")
    source = path + ".pfm"
    pfm(source, width, height, value, overrides, channels)
    run([oiiotool, source, "-d", "float", "-o", path])
    os.remove(source)
