#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Renders one scene under every Embree instruction set this CPU can run, with 1 and 2 threads,
and fails unless every image is bit-identical to the one Embree's own choice gives.

    isa_identical.py WHITTED SCENE OUT_DIR [--two-threads-only] [--povray-rule]

--two-threads-only (the sanitizer build, where each render is ten times slower): each
instruction set with 2 threads only, which still runs every packet width and the threaded path.
--povray-rule: also under `render.intersection: povray`, the rule `whitted check` renders
with (each instruction set with 2 threads against the native render under that rule), so that
with pov.SCENE, which checks the native image against POV-Ray, every instruction set is
checked against POV-Ray under the rule the cross-check uses.

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
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fail, read_exr_header, run  # noqa: E402  (tests/harness.py)

ISAS = ["sse2", "sse4.2", "avx", "avx2", "avx512"]
UNSUPPORTED = "this CPU cannot run Embree's"


def render(whitted, scene, out, isa, threads, rule):
    env = dict(os.environ)
    env.pop("WHITTED_EMBREE_ISA", None)
    if isa:
        env["WHITTED_EMBREE_ISA"] = isa
    cmd = [whitted, "render", "-q", scene, "-o", out, "--threads", str(threads), "--exr-compression", "none"]
    if rule == "povray":  # else the scene's own render.intersection
        cmd += ["--intersection", "povray"]
    return run(cmd, expect=None, timeout=120, env=env)


def scanlines(path):
    """The rows of an uncompressed 3-channel float EXR, as the bytes of its chunks, checked."""
    data = open(path, "rb").read()
    attributes, _ = read_exr_header(data, path)
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attributes["dataWindow"][1])
    width, height = xmax - xmin + 1, ymax - ymin + 1
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
    options = sys.argv[4:]
    if len(sys.argv) < 4 or any(o not in ("--two-threads-only", "--povray-rule") for o in options):
        print(__doc__, file=sys.stderr)
        return 2
    whitted, scene, out_dir = sys.argv[1:4]
    thread_counts = (2,) if "--two-threads-only" in options else (1, 2)
    os.makedirs(out_dir, exist_ok=True)
    name = os.path.splitext(os.path.basename(scene))[0]
    failures = Failures()
    # The scene's own rule with every variant; POV-Ray's with 2 threads (the rules differ in how a
    # hit is decided, not in how the tiles are shared among threads, which the first covers).
    rules = [("scene", thread_counts)] + ([("povray", (2,))] if "--povray-rule" in options else [])
    for rule, counts in rules:
        base_path = os.path.join(out_dir, f"{name}.{rule}.native.t2.exr")
        result = render(whitted, scene, base_path, "", 2, rule)
        if result.returncode != 0:
            fail(f"native render ({rule} rule) exited {result.returncode}:\n{result.stderr}")
        base, width, height = scanlines(base_path)

        ran, skipped = ["native t2"], []
        variants = [("", t) for t in counts if t != 2] + [(isa, t) for isa in ISAS for t in counts]
        for isa, threads in variants:
            label = f"{rule} rule, {isa or 'native'} t{threads}"
            path = os.path.join(out_dir, f"{name}.{rule}.{isa or 'native'}.t{threads}.exr")
            result = render(whitted, scene, path, isa, threads, rule)
            if result.returncode == 2 and UNSUPPORTED in result.stderr:
                if isa not in skipped:
                    skipped.append(isa)
                continue
            if not failures.require(result.returncode == 0,
                                    f"{label}: exited {result.returncode}: {result.stderr.strip()[-600:]}"):
                continue
            pixels, _, _ = scanlines(path)
            ran.append(f"{isa or 'native'} t{threads}")
            failures.require(pixels == base,
                             f"{label}: pixels differ from native t2 ({first_difference(pixels, base, width)})")

        print(f"{name} ({width}x{height}), {rule} rule: ran {', '.join(ran)}")
        if skipped:
            print(f"not run, this CPU lacks them: {', '.join(skipped)}")
        failures.require(len(ran) >= 3, f"{rule} rule: fewer than two variants besides the base ran; "
                                        "nothing was compared")
    failures.finish()


if __name__ == "__main__":
    sys.exit(main())
