#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Whitted's render-stage rays/s next to Embree's own rate on the same rays (docs/performance.md,
"Rays per second against Embree's own rate"). For each anchor scene (bench/generate.py) it writes
the scene as whitted_embree_rate reads it (NAME.rays: camera, lights, the floor, the spheres with
their km, the mesh with its placement), then runs, interleaved, `whitted render NAME.yaml -o
x.exr --stats --threads T` and `whitted_embree_rate NAME.rays --threads T`, and prints the medians
of both rates, their ratio and the two programs' ray counts by kind.
WHITTED_EMBREE_ISA (e.g. avx2) is honoured by both programs.
Usage: bench/embree_rate.py WHITTED_BINARY EMBREE_RATE_BINARY OUT_DIR [--runs N] [--threads T]
       [--scenes a,b]"""
import argparse
import math
import re
import statistics
import subprocess
import sys
from pathlib import Path

import yaml


def step_matrix(step):
    """The 3x4 matrix (rows) of one transform step (docs/scene-format.md §4)."""
    if "translate" in step:
        x, y, z = step["translate"]
        return [[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z]]
    if "scale" in step:
        s = step["scale"]
        x, y, z = (s, s, s) if isinstance(s, (int, float)) else s
        return [[x, 0, 0, 0], [0, y, 0, 0], [0, 0, z, 0]]
    if "rotate" in step:  # right-hand rule about the axis (Rodrigues)
        ax = step["rotate"]["axis"]
        n = math.sqrt(sum(a * a for a in ax))
        x, y, z = (a / n for a in ax)
        a = math.radians(step["rotate"]["angle"])
        c, s, t = math.cos(a), math.sin(a), 1 - math.cos(a)
        return [[t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0],
                [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0],
                [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0]]
    m = step["matrix"]
    return [m[0:4], m[4:8], m[8:12]]


def transform_matrix(transform):
    """The steps in list order: the first applies first."""
    steps = transform if isinstance(transform, list) else [transform] if transform else []
    total = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]
    for step in steps:
        m = step_matrix(step)
        total = [[sum(m[r][k] * total[k][c] for k in range(3)) + (m[r][3] if c == 3 else 0) for c in range(4)]
                 for r in range(3)]
    return total


def write_rays(scene_path: Path) -> Path:
    """NAME.rays for whitted_embree_rate: the anchors' items (plane, sphere, mesh, point lights)."""
    scene = yaml.safe_load(scene_path.read_text())
    materials = scene.get("materials", {})

    def km(obj):
        material = obj.get("material", {})
        material = materials[material] if isinstance(material, str) else material
        value = material.get("km", 0)
        return max(value) if isinstance(value, list) else value

    cam, image = scene["camera"], scene["image"]
    lines = ["camera " + " ".join(str(v) for v in cam["eye"] + cam["look_at"] + cam["up"]) + f" {cam['fov']}",
             f"image {image['width']} {image['height']}",
             f"max_depth {scene.get('render', {}).get('max_depth', 5)}"]
    for light in scene["lights"]:
        if light["type"] != "point":
            sys.exit(f"embree_rate: {scene_path.name}: only point lights")
        lines.append("light " + " ".join(map(str, light["position"])))
    for obj in scene["objects"]:
        if obj["type"] == "plane":
            lines.append("plane " + " ".join(map(str, obj["point"] + obj["normal"])) + f" {km(obj)}")
        elif obj["type"] == "sphere":
            lines.append("sphere " + " ".join(map(str, obj["center"])) + f" {obj['radius']} {km(obj)}")
        elif obj["type"] == "mesh":
            m = transform_matrix(obj.get("transform"))
            lines.append(f"mesh {(scene_path.parent / obj['file']).resolve()} {km(obj)} " +
                         " ".join(repr(float(v)) for row in m for v in row))
        else:
            sys.exit(f"embree_rate: {scene_path.name}: no {obj['type']} in the yardstick")
    out = scene_path.with_suffix(".rays")
    out.write_text("\n".join(lines) + "\n")
    return out


def run(cmd):
    proc = subprocess.run(list(map(str, cmd)), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        sys.exit(f"embree_rate: {' '.join(map(str, cmd))} failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return proc.stdout + proc.stderr


def whitted_run(cmd):
    """(M rays/s of the render stage, render seconds, (camera, shadow, reflected) in M)."""
    text = run(cmd)
    m = re.search(r"render ([0-9.]+)s .*?([0-9.]+) M rays \(camera ([0-9.]+), shadow ([0-9.]+), "
                  r"reflected ([0-9.]+)\)", text)
    if not m:
        sys.exit(f"embree_rate: no --stats line in:\n{text}")
    seconds, total = float(m.group(1)), float(m.group(2))
    return total / seconds, seconds, tuple(float(m.group(k)) for k in (3, 4, 5))


def embree_run(cmd):
    """(M rays/s, tracing seconds, (camera, shadow, reflected) in M, the program's first line)."""
    text = run(cmd)
    counts = re.search(r"camera (\d+) shadow (\d+) reflected (\d+)", text)
    timing = re.search(r"trace ([0-9.]+) s, ([0-9.]+) M rays/s", text)
    return (float(timing.group(2)), float(timing.group(1)), tuple(int(c) / 1e6 for c in counts.groups()),
            text.splitlines()[0])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("whitted")
    ap.add_argument("embree_rate")
    ap.add_argument("out")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default="spheres,torus100k,torus1m")
    args = ap.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    here = Path(__file__).resolve().parent
    subprocess.run([sys.executable, str(here / "generate.py"), str(out)], check=True, stdout=subprocess.DEVNULL)
    rows = []
    for name in args.scenes.split(","):
        scene = out / f"{name}.yaml"
        rays = write_rays(scene)
        ours = [args.whitted, "render", scene, "-o", out / f"{name}.rate.exr", "--stats", "--threads", args.threads]
        theirs = [args.embree_rate, rays, "--threads", args.threads]
        w, e = [], []
        for _ in range(args.runs):  # interleaved: both see the same machine
            w.append(whitted_run(ours))
            e.append(embree_run(theirs))
        ratios = [a[0] / b[0] for a, b in zip(w, e)]  # pair by pair: the machine's drift cancels
        rows.append((name, [r[0] for r in w], [r[0] for r in e], ratios, w[0][2], e[0][2], e[0][3]))
    print(f"\n{args.threads} thread(s), {args.runs} interleaved runs: median (min-max); Whitted: render stage "
          "(--stats), Embree: tracing only; ratio: Whitted's rate / Embree's, run by run")
    print(f"{'scene':<10} {'Whitted M rays/s':>17} {'Embree M rays/s':>17} {'ratio':>17}  "
          "rays Whitted / Embree, M (camera, shadow, reflected)")

    def spread(values, scale=1.0, digits=1):
        return (f"{scale * statistics.median(values):.{digits}f} ({scale * min(values):.{digits}f}-"
                f"{scale * max(values):.{digits}f})")

    for name, w_rates, e_rates, ratios, w_counts, e_counts, _ in rows:
        kinds = ", ".join(f"{a:.2f}/{b:.3f} ({100 * (a - b) / b:+.1f}%)" for a, b in zip(w_counts, e_counts))
        print(f"{name:<10} {spread(w_rates):>17} {spread(e_rates):>17} {spread(ratios, 100, 0) + ' %':>17}  {kinds}")
    for name, *_, first in rows:
        print(f"{name}: {first}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
