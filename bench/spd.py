#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Times Whitted against Tachyon (Debian's NFF ray tracer) on Eric Haines' SPD databases, read
from NFF by both: interleaved (Whitted, Tachyon, Whitted, ...), whole process, median of N runs,
peak memory of each; prints a table (docs/performance.md, "SPD databases").

Both render the same file at the file's own resolution with the same number of threads, to a
file (Whitted a PNG, Tachyon a TGA). The images are not the same by design: Tachyon shades NFF
its own way (ambient, its own highlight, no 1/√N lights) and draws some databases differently
(the teapot mirrored, gears blank); Whitted's image is the one `whitted check` compares with
POV-Ray (tests/nff, label spd).

Tachyon draws each NFF light as a white ball. A database with a light nearer the eye than its
hither distance (gears: its fifth light is 0.034 from the eye, hither 1) is blank in Tachyon's
image, every camera ray ending on that ball, so its time there is not the database's work. For
such a database a second row renders, with both programs, a copy written to OUT_DIR without
those lights: NAME-no-eye-light.nff ("NAME, lights at the eye left out").

Usage: bench/spd.py WHITTED OUT_DIR [--runs N] [--threads T] [--corpus DIR] [--databases a,b]"""
import argparse
import os
import shutil
import statistics
import sys
from pathlib import Path

import measure

DATABASES = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]


def timed(cmd):
    wall, peak_mb, code, stderr = measure.timed(cmd)
    if code != 0:
        sys.exit(f"bench: {' '.join(map(str, cmd))} failed ({code}):\n{stderr[-2000:]}")
    return wall, peak_mb


def count_primitives(path):
    counts = {}
    with open(path, "rb") as f:
        for line in f:
            word = line.split(maxsplit=1)[0] if line.strip() else b""
            if word in (b"s", b"c", b"p", b"pp"):
                counts[word.decode()] = counts.get(word.decode(), 0) + 1
    return counts


def lights_at_the_eye(path):
    """The lines of `path`'s lights nearer the eye ("from") than the hither distance: a light
    there is nothing the camera should see (the NFF document's positional light is a point),
    but Tachyon's ball around it covers the view."""
    eye, hither, lights = None, 0.0, []
    with open(path, "rb") as f:
        for number, line in enumerate(f):
            words = line.split()
            if not words:
                continue
            try:
                if words[0] == b"from" and len(words) >= 4:
                    eye = [float(w) for w in words[1:4]]
                elif words[0] == b"hither" and len(words) >= 2:
                    hither = float(words[1])
                elif words[0] == b"l" and len(words) >= 4:
                    lights.append((number, [float(w) for w in words[1:4]]))
            except ValueError:
                continue  # not a number: Whitted's render of the file says where
    if eye is None:
        return set()
    return {n for n, at in lights if sum((a - e) ** 2 for a, e in zip(at, eye)) < hither * hither}


def without_lines(path, lines, out):
    """A copy of `path` at `out` without the given line numbers (0-based)."""
    with open(path, "rb") as f, open(out, "wb") as o:
        o.writelines(line for number, line in enumerate(f) if number not in lines)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("whitted")
    ap.add_argument("out")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--corpus", default=str(Path(__file__).resolve().parents[1].parent / "shared" / "corpora" / "spd"))
    ap.add_argument("--databases", default=",".join(DATABASES))
    args = ap.parse_args()
    tachyon = shutil.which("tachyon")
    if not tachyon:
        sys.exit("bench: Tachyon is needed: apt-get install tachyon")
    corpus = Path(args.corpus)
    if not corpus.is_dir():
        sys.exit(f"bench: no SPD corpus at {corpus} (--corpus DIR: the databases as NFF)")
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    rows = []
    work = []
    for name in args.databases.split(","):
        scene = corpus / f"{name}.nff"
        if not scene.is_file():
            sys.exit(f"bench: {scene} is missing")
        work.append((name, scene))
        at_the_eye = lights_at_the_eye(scene)
        if at_the_eye:
            copy = without_lines(scene, at_the_eye, out / f"{name}-no-eye-light.nff")
            work.append((f"{name}, lights at the eye left out", copy))
    for label, scene in work:
        name = scene.stem
        ours = [args.whitted, "render", scene, "-o", out / f"{name}.whitted.png", "--threads", str(args.threads),
                "--quiet"]
        theirs = [tachyon, scene, "-numthreads", str(args.threads), "-o", out / f"{name}.tachyon.tga", "-format",
                  "TARGA"]
        timed(ours), timed(theirs)  # warm-up: files in the page cache, libraries loaded
        w, t = [], []
        for _ in range(args.runs):
            w.append(timed(ours))
            t.append(timed(theirs))
        med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
        ratios = [b[0] / a[0] for a, b in zip(w, t)]
        rows.append((label, count_primitives(scene), med(w, 0), med(t, 0), statistics.median(ratios), med(w, 1),
                     med(t, 1)))
        print(f"{label}: Whitted {med(w, 0):.3f} s, Tachyon {med(t, 0):.3f} s, "
              f"Tachyon/Whitted {statistics.median(ratios):.2f}x", file=sys.stderr)

    print(f"\n{args.runs} interleaved runs each, {args.threads} threads, whole process, medians\n")
    print("| database | primitives | Whitted | Tachyon | speed-up (median of pairs) | memory Whitted | memory Tachyon |")
    print("|---|---|---|---|---|---|---|")
    for name, counts, ws, ts, ratio, wm, tm in rows:
        prims = ", ".join(f"{n} {k}" for k, n in sorted(counts.items()))
        print(f"| {name} | {prims} | {ws:.3f} s | {ts:.3f} s | {ratio:.2f}× | {wm:.0f} MB | {tm:.0f} MB |")


if __name__ == "__main__":
    main()
