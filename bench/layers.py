#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""What render layers cost, and that a render without them is unchanged: times, interleaved in
one run, BASE (a Whitted built before layers existed, e.g. from the previous commit) and NEW
rendering each scene to EXR without layers, and NEW with `--layers all`; whole process, median
of N runs. Also checks that BASE's and NEW's images without layers are bit-identical.

    bench/layers.py BASE_WHITTED NEW_WHITTED OUT_DIR [--runs N] [--threads T] [--scenes a.yaml,b.yaml]

Scenes default to the anchor scenes of bench/generate.py (spheres, torus100k) at 1280x960.
Numbers are wall time on a machine that may be shared: say so next to them."""
import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import OpenImageIO as oiio


def timed(cmd):
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def beauty(path):
    image = oiio.ImageInput.open(str(path))
    spec = image.spec()
    pixels = image.read_image(format="float")
    image.close()
    index = [spec.channelnames.index(c) for c in "RGB"]
    return pixels[:, :, index].astype(np.float32)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("base")
    ap.add_argument("new")
    ap.add_argument("out")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--scenes", default="")
    args = ap.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if args.scenes:
        scenes = [Path(s).resolve() for s in args.scenes.split(",")]
    else:
        here = Path(__file__).resolve().parent
        subprocess.run([sys.executable, str(here / "generate.py"), str(out)], check=True, stdout=subprocess.DEVNULL)
        os.sync()
        scenes = [out / "spheres.yaml", out / "torus100k.yaml"]
    print(f"{'scene':<28} {'base (s)':>9} {'new (s)':>9} {'new --layers all (s)':>21}  base == new bit for bit")
    for scene in scenes:
        name = scene.stem
        variants = {
            "base": [args.base, "render", str(scene), "-q", "-t", str(args.threads), "-o", str(out / f"{name}.base.exr")],
            "new": [args.new, "render", str(scene), "-q", "-t", str(args.threads), "-o", str(out / f"{name}.new.exr")],
            "layers": [args.new, "render", str(scene), "-q", "-t", str(args.threads), "--layers", "all", "-o",
                       str(out / f"{name}.layers.exr")],
        }
        for cmd in variants.values():
            timed(cmd)  # warm the page cache
        times = {k: [] for k in variants}
        for _ in range(args.runs):
            for key, cmd in variants.items():
                times[key].append(timed(cmd))
        same = np.array_equal(beauty(out / f"{name}.base.exr").view(np.uint32),
                              beauty(out / f"{name}.new.exr").view(np.uint32))
        m = {k: statistics.median(v) for k, v in times.items()}
        print(f"{name:<28} {m['base']:>9.3f} {m['new']:>9.3f} {m['layers']:>21.3f}  {'yes' if same else 'NO'}")
        if not same:
            sys.exit(f"bench: {name}: the render without layers differs from BASE's")


if __name__ == "__main__":
    main()
