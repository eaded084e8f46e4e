#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Renders one scene under every Embree instruction set this CPU can run, with 1 and 2 threads,
and fails unless every image is bit-identical to the one Embree's own choice gives.

    isa_identical.py WHITTED SCENE OUT_DIR [--two-threads-only]

--two-threads-only (the sanitizer build, where each render is ten times slower): each
instruction set with 2 threads only, which still runs every packet width and the threaded path.

Embree runs different code for each instruction set (SSE2 ... AVX-512: 4-, 8- or 16-wide
packets, with or without FMA), and a CPU runs only the widest it has unless told otherwise; so
forcing each one with WHITTED_EMBREE_ISA is the only way one machine can test the paths users'
CPUs take (docs/building.md). An instruction set the CPU lacks is reported as not run, by
name, from Whitted's own message; at least two variants must run, or the test fails.

"Bit-identical" is checked on the bytes: the images are uncompressed EXR, whose scan lines are
stored last in the file, one (y, size, pixels) chunk per row; those chunks are compared byte
for byte (the header before them holds the render time, which differs).
"""

import os
import struct
import subprocess
import sys

ISAS = ["sse2", "sse4.2", "avx", "avx2", "avx512"]
UNSUPPORTED = "this CPU cannot run Embree's"


def render(whitted, scene, out, isa, threads):
    env = dict(os.environ)
    env.pop("WHITTED_EMBREE_ISA", None)
    if isa:
        env["WHITTED_EMBREE_ISA"] = isa
    cmd = [whitted, "render", "-q", scene, "-o", out, "--threads", str(threads), "--exr-compression", "none"]
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)


def exr_size(path):
    """Width and height from the header's dataWindow (box2i: xmin ymin xmax ymax)."""
    data = open(path, "rb").read()
    key = b"dataWindow\0box2i\0"
    at = data.find(key)
    if at < 0:
        raise ValueError(f"{path}: no dataWindow attribute")
    at += len(key) + 4  # attribute size
    xmin, ymin, xmax, ymax = struct.unpack_from("<4i", data, at)
    return xmax - xmin + 1, ymax - ymin + 1, ymin


def scanlines(path):
    """The rows of an uncompressed 3-channel float EXR, as the bytes of its chunks, checked."""
    width, height, ymin = exr_size(path)
    data = open(path, "rb").read()
    row = 3 * 4 * width
    chunk = 8 + row
    start = len(data) - height * chunk
    if start <= 0:
        raise ValueError(f"{path}: too short for {width}x{height} uncompressed float RGB")
    for i in range(height):
        y, size = struct.unpack_from("<2i", data, start + i * chunk)
        if y != ymin + i or size != row:
            raise ValueError(f"{path}: row {i} is not an uncompressed float RGB scan line (y {y}, size {size})")
    return data[start:], width, height


def first_difference(a, b, width):
    chunk = 8 + 12 * width
    for i in range(min(len(a), len(b))):
        if a[i] != b[i]:
            row, offset = divmod(i, chunk)
            # EXR stores each row channel by channel, in channel-name order: B, G, R.
            channel, x = divmod(max(offset - 8, 0) // 4, width)
            return f"first at pixel ({x}, {row}), channel {'BGR'[channel]}"
    return "different lengths"


def main():
    if len(sys.argv) not in (4, 5) or (len(sys.argv) == 5 and sys.argv[4] != "--two-threads-only"):
        print(__doc__, file=sys.stderr)
        return 2
    whitted, scene, out_dir = sys.argv[1:4]
    thread_counts = (2,) if len(sys.argv) == 5 else (1, 2)
    os.makedirs(out_dir, exist_ok=True)
    name = os.path.splitext(os.path.basename(scene))[0]

    base_path = os.path.join(out_dir, f"{name}.native.t2.exr")
    result = render(whitted, scene, base_path, "", 2)
    if result.returncode != 0:
        print(f"FAIL: native render exited {result.returncode}:\n{result.stderr}", file=sys.stderr)
        return 1
    base, width, height = scanlines(base_path)

    ran, skipped, failures = ["native t2"], [], []
    variants = [("", t) for t in thread_counts if t != 2] + [(isa, t) for isa in ISAS for t in thread_counts]
    for isa, threads in variants:
        label = f"{isa or 'native'} t{threads}"
        path = os.path.join(out_dir, f"{name}.{isa or 'native'}.t{threads}.exr")
        result = render(whitted, scene, path, isa, threads)
        if result.returncode == 2 and UNSUPPORTED in result.stderr:
            if isa not in skipped:
                skipped.append(isa)
            continue
        if result.returncode != 0:
            failures.append(f"{label}: exited {result.returncode}: {result.stderr.strip()[-600:]}")
            continue
        pixels, _, _ = scanlines(path)
        ran.append(label)
        if pixels != base:
            failures.append(f"{label}: pixels differ from native t2 ({first_difference(pixels, base, width)})")

    print(f"{name} ({width}x{height}): ran {', '.join(ran)}")
    if skipped:
        print(f"not run, this CPU lacks them: {', '.join(skipped)}")
    for failure in failures:
        print(f"FAIL: {failure}", file=sys.stderr)
    if len(ran) < 3:
        print("FAIL: fewer than two variants besides the base ran; nothing was compared", file=sys.stderr)
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
