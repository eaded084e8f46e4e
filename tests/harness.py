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

import os
import shutil
import struct
import subprocess
import sys

SKIP = 77
# What the sanitizers (the ASan/UBSan build) print: a test that sees one has found a fault even
# when the exit status is the expected one.
SANITIZER_MARKERS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:", "UndefinedBehaviorSanitizer")


def fail(message):
    """Ends the test as failed, with MESSAGE."""
    sys.exit(f"FAIL: {message}")


def skip(reason):
    """Ends the test as skipped (ctest's SKIP_RETURN_CODE 77), saying why."""
    print(f"SKIPPED: {reason}")
    sys.exit(SKIP)


def run(command, expect=0, timeout=600, text=True, **kwargs):
    """Runs COMMAND (a list) with its output captured (as text unless TEXT is false); fails the
    test if it runs past TIMEOUT seconds or, unless EXPECT is None, exits with any status but
    EXPECT. Returns the CompletedProcess. KWARGS go to subprocess.run (cwd, env, input, stdin,
    errors; stdout or stderr replace the capture of that stream)."""
    kwargs.setdefault("stdout", subprocess.PIPE)
    kwargs.setdefault("stderr", subprocess.PIPE)
    try:
        result = subprocess.run(command, text=text, timeout=timeout, **kwargs)
    except subprocess.TimeoutExpired:
        fail(f"{' '.join(map(str, command))} ran past {timeout} s")
    if expect is not None and result.returncode != expect:
        fail(f"{' '.join(map(str, command))} exited {result.returncode}, expected {expect}\n"
             f"{_tail(result.stdout, 2000)}{_tail(result.stderr)}")
    return result


def _tail(stream, size=3000):
    """The last SIZE characters (None: all) of a captured stream, as text."""
    if stream is None:
        return ""
    if isinstance(stream, bytes):
        stream = stream.decode("utf-8", "replace")
    return stream if size is None else stream[-size:]


def fresh_folder(path):
    """Empties PATH, a test's own work folder, and makes it again (with its parents): nothing a
    previous run left there can be read as this run's output. Returns PATH."""
    shutil.rmtree(path, ignore_errors=True)
    os.makedirs(path)
    return path


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

    def fail(self, message):
        """Records a failed check without ending the test."""
        self.check(False, message)

    def require(self, condition, problem):
        """Records PROBLEM (a sentence saying what went wrong) as a failed check unless
        CONDITION holds; a check that holds prints nothing."""
        if not condition:
            self.fail(problem)
        return bool(condition)

    def run(self, command, expect=0, timeout=600, **kwargs):
        """harness.run, but an exit status other than EXPECT is recorded as a failed check and
        the test goes on (EXPECT None: any status); the CompletedProcess is returned either way."""
        result = run(command, expect=None, timeout=timeout, **kwargs)
        if expect is not None and result.returncode != expect:
            self.fail(f"{' '.join(map(str, command))} exited {result.returncode}, expected {expect}\n"
                      f"{_tail(result.stderr)}")
        return result

    def refused(self, what, command, fragments, expect=2, timeout=600, **kwargs):
        """Runs COMMAND, which must refuse: a failed check unless it exits with EXPECT and its
        standard error holds every one of FRAGMENTS. Returns the CompletedProcess."""
        result = run(command, expect=None, timeout=timeout, **kwargs)
        stderr = _tail(result.stderr, None)
        self.require(result.returncode == expect, f"{what}: exit {result.returncode}, expected {expect}\n{stderr}")
        for fragment in fragments:
            self.require(fragment in stderr, f"{what}: the message does not say '{fragment}': {stderr!r}")
        return result

    def finish(self, passed=None):
        """Ends the test: failed (exit 1) if any check failed, else passed (exit 0), then printing
        PASSED (a line saying what passed) if given."""
        if self.messages:
            print(f"{len(self.messages)} problem(s)")
            sys.exit(1)
        if passed:
            print(passed)
        sys.exit(0)


def read_pixels(path, with_names=False):
    """The pixels of any image file OpenImageIO reads, as a height x width x channels float
    array (and the channel names, WITH_NAMES); fails the test if it cannot be opened. For images
    that are only compared with each other or with a closed form; read_exr reads Whitted's EXR
    files without a library."""
    import OpenImageIO as oiio

    image = oiio.ImageInput.open(str(path))
    if image is None:
        fail(f"OpenImageIO cannot open {path}: {oiio.geterror()}")
    names = list(image.spec().channelnames)
    pixels = image.read_image(format="float")
    image.close()
    return (pixels, names) if with_names else pixels


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
