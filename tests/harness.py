# SPDX-License-Identifier: MIT
"""The one harness of the script tiers (tests/*/*.py): how a test runs a program, fails, skips
and reads Whitted's images back. A tier's script adds the folder above it to sys.path and
imports this module:

    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import harness

Exit statuses follow ctest: 0 passed, 77 skipped (SKIP_RETURN_CODE, with the reason printed),
anything else failed. Images are read here, byte by byte, rather than through Whitted's own
code, so a test's reference never depends on the code under test.
"""

import struct
import subprocess
import sys

SKIP = 77


def fail(message):
    """Ends the test as failed, with MESSAGE."""
    sys.exit(f"FAIL: {message}")


def skip(reason):
    """Ends the test as skipped (ctest's SKIP_RETURN_CODE 77), saying why."""
    print(f"SKIPPED: {reason}")
    sys.exit(SKIP)


def run(command, expect=0, timeout=600, **kwargs):
    """Runs COMMAND (a list) with its output captured as text; fails the test unless it exits
    with EXPECT. Returns the CompletedProcess. KWARGS go to subprocess.run (cwd, env, input)."""
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, **kwargs)
    except subprocess.TimeoutExpired:
        fail(f"{' '.join(map(str, command))} ran past {timeout} s")
    if result.returncode != expect:
        fail(f"{' '.join(map(str, command))} exited {result.returncode}, expected {expect}\n"
             f"{result.stderr[-3000:]}")
    return result


class Failures:
    """Collects failed checks so that one run reports all of them: each check prints its verdict
    ("ok" or "FAIL" and the message), and finish() ends the test, failed if any check did."""

    def __init__(self):
        self.messages = []

    def check(self, condition, message):
        print(("ok    " if condition else "FAIL  ") + message)
        if not condition:
            self.messages.append(message)
        return bool(condition)

    def finish(self):
        if self.messages:
            print(f"{len(self.messages)} problem(s)")
            sys.exit(1)
        sys.exit(0)


def read_exr_header(data, path="image"):
    """(attributes, offset of the line offset table) of an OpenEXR file's bytes: each attribute
    as name -> (type, raw bytes)."""
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    pos, attributes = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        name, kind = data[pos:name_end].decode(), data[name_end + 1:type_end].decode()
        size = struct.unpack_from("<i", data, type_end + 1)[0]
        attributes[name] = (kind, data[type_end + 5:type_end + 5 + size])
        pos = type_end + 5 + size
    return attributes, pos + 1


def read_exr(path):
    """(width, height, rows from the top, each a list of (r, g, b)) of an uncompressed scanline
    OpenEXR file of 32-bit float R, G, B channels, the kind `whitted render -o x.exr` writes by
    default. The floats are exactly those Whitted wrote."""
    with open(path, "rb") as f:
        data = f.read()
    attributes, pos = read_exr_header(data, path)
    if attributes["compression"][1][0] != 0:
        raise ValueError(f"{path}: compressed; the tests read uncompressed files")
    x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    channels, chlist = [], attributes["channels"][1]
    at = 0
    while chlist[at] != 0:
        end = chlist.index(b"\0", at)
        channels.append((chlist[at:end].decode(), struct.unpack_from("<i", chlist, end + 1)[0]))
        at = end + 1 + 16
    if [c for c, _ in channels] != ["B", "G", "R"] or any(t != 2 for _, t in channels):
        raise ValueError(f"{path}: channels {channels}, expected float B, G, R")
    offsets = struct.unpack_from(f"<{height}Q", data, pos)
    rows = []
    for y in range(height):
        line_y, size = struct.unpack_from("<2i", data, offsets[y])
        if line_y != y0 + y or size != 12 * width:
            raise ValueError(f"{path}: not an uncompressed float RGB EXR (row {y})")
        block = offsets[y] + 8  # the scanline's y and byte count come first
        b = struct.unpack_from(f"<{width}f", data, block)
        g = struct.unpack_from(f"<{width}f", data, block + 4 * width)
        r = struct.unpack_from(f"<{width}f", data, block + 8 * width)
        rows.append([(r[x], g[x], b[x]) for x in range(width)])
    return width, height, rows
