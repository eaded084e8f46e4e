#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Reading time against the number of definitions (issue 40: a linear look-up per reference made
reading quadratic). For N = 10^3 .. 10^6 it writes, for each kind, a scene of N definitions each
referenced once, and times `whitted.load` on it: parsing, validation and mesh/MTL loading, the
"read" stage of `whitted render --stats`, without the BVH build that would dominate at 10^6
instances. Each load runs in a fresh process; the best of --runs is kept.

  bench/parsing.py WHITTED OUT_DIR [--max-n N] [--runs R] [--kinds materials,prototypes,...]

Kinds (each definition referenced once, unless said):
  materials    YAML: N named materials, N spheres each naming one
  prototypes   YAML: N prototypes (each one OBJ mesh of one triangle), N instances each placing one
  shaders      course XML: N named shaders, N spheres each with <shader ref=.../>
  mtl          OBJ + MTL: N `newmtl` materials, N faces each after `usemtl` of one
  mtllib       OBJ: N `mtllib` lines naming one MTL file (read once), one face

Prints a markdown table (docs/performance.md, "Parsing against the number of definitions": CPU
seconds of the process, every thread, with the wall seconds in brackets) and,
per kind, the log-log slope between the two largest N and the least-squares slope over the N from
10^4 on (1 is linear, 2 quadratic; below 10^4 the process's fixed cost dominates). The Python
module is taken from WHITTED's build (../python beside bin/), or --module-dir."""
import argparse
import math
import os
import subprocess
import sys
from pathlib import Path

KINDS = ["materials", "prototypes", "shaders", "mtl", "mtllib"]
HEADER = ("version: 1\ncamera: { eye: [0, 0, 10], look_at: [0, 0, 0] }\nimage: { width: 8, height: 8 }\n"
          "lights: [ { type: point, position: [0, 5, 10] } ]\n")


def write_scene(kind, n, out):
    """Writes the scene of `kind` with n definitions under `out`; returns its path."""
    out.mkdir(parents=True, exist_ok=True)
    if kind == "materials":
        path = out / "materials.yaml"
        with open(path, "w") as f:
            f.write(HEADER + "materials:\n")
            f.writelines(f"  m{i}: {{ kd: 0.5 }}\n" for i in range(n))
            f.write("objects:\n")
            f.writelines(f"  - {{ type: sphere, center: [0, 0, 0], radius: 1, material: m{i} }}\n" for i in range(n))
    elif kind == "prototypes":
        # Each prototype a one-triangle OBJ mesh: an inline triangle is 14 values, and 10^6 of
        # them pass the 10^7 values a scene may hold at once (docs/robustness.md, "Limits").
        path = out / "prototypes.yaml"
        (out / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        with open(path, "w") as f:
            f.write(HEADER + "prototypes:\n")
            f.writelines(f"  p{i}: {{ type: mesh, file: tri.obj }}\n" for i in range(n))
            f.write("objects:\n")
            f.writelines(f"  - {{ type: instance, prototype: p{i}, material: {{ kd: 0.5 }} }}\n" for i in range(n))
    elif kind == "shaders":
        path = out / "shaders.xml"
        with open(path, "w") as f:
            f.write('<scene>\n <camera><viewPoint>0 0 10</viewPoint><viewDir>0 0 -1</viewDir>'
                    '<viewUp>0 1 0</viewUp><projDistance>1</projDistance><viewWidth>1</viewWidth>'
                    '<viewHeight>1</viewHeight></camera>\n <image>8 8</image>\n'
                    ' <light><position>0 5 10</position><intensity>1 1 1</intensity></light>\n')
            f.writelines(f' <shader name="s{i}" type="Lambertian"><diffuseColor>.5 .5 .5</diffuseColor></shader>\n'
                         for i in range(n))
            f.writelines(f' <surface type="Sphere"><shader ref="s{i}"/><center>0 0 0</center><radius>1</radius>'
                         f'</surface>\n' for i in range(n))
            f.write('</scene>\n')
    elif kind == "mtl":
        path = out / "mtl.yaml"
        with open(out / "many.mtl", "w") as f:
            f.writelines(f"newmtl m{i}\nKd 0.5 0.5 0.5\n" for i in range(n))
        with open(out / "many.obj", "w") as f:
            f.write("mtllib many.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
            f.writelines(f"usemtl m{i}\nf 1 2 3\n" for i in range(n))
        path.write_text(HEADER + "objects:\n  - { type: mesh, file: many.obj }\n")
    elif kind == "mtllib":
        path = out / "mtllib.yaml"
        (out / "one.mtl").write_text("newmtl m\nKd 0.5 0.5 0.5\n")
        with open(out / "lines.obj", "w") as f:
            f.writelines("mtllib one.mtl\n" for _ in range(n))
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n")
        path.write_text(HEADER + "objects:\n  - { type: mesh, file: lines.obj }\n")
    else:
        raise ValueError(kind)
    return path


LOAD = """import sys, time, whitted
cpu, wall = time.process_time(), time.perf_counter()
whitted.load(sys.argv[1])
print(time.process_time() - cpu, time.perf_counter() - wall)
"""


def load_seconds(module_dir, scene, runs):
    """(CPU seconds, wall seconds) of the best of `runs` whole loads, each in a new process. The
    CPU time (every thread of the process) is what the slope is taken from: on a shared machine
    the wall time also holds the waits for a core."""
    env = dict(os.environ, PYTHONPATH=str(module_dir))
    best = (math.inf, math.inf)
    for _ in range(runs):
        result = subprocess.run([sys.executable, "-c", LOAD, str(scene)], env=env, capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"parsing: loading {scene} failed ({result.returncode}): {result.stderr[-800:]}")
        cpu, wall = map(float, result.stdout.split()[-2:])
        best = min(best, (cpu, wall))
    return best


def slope(points):
    """Least-squares slope of log t against log N."""
    xs = [math.log10(n) for n, _ in points]
    ys = [math.log10(t) for _, t in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("whitted")
    parser.add_argument("out_dir")
    parser.add_argument("--max-n", type=int, default=1000000)
    parser.add_argument("--runs", type=int, default=3, help="loads per scene below 10^6 (one at 10^6)")
    parser.add_argument("--kinds", default=",".join(KINDS))
    parser.add_argument("--module-dir", default=None)
    args = parser.parse_args()
    module_dir = Path(args.module_dir) if args.module_dir else Path(args.whitted).resolve().parent.parent / "python"
    kinds = args.kinds.split(",")
    sizes = [n for n in (1000, 10000, 100000, 1000000) if n <= args.max_n]
    out = Path(args.out_dir)
    times = {kind: [] for kind in kinds}
    walls = {kind: [] for kind in kinds}
    for kind in kinds:
        for n in sizes:
            scene = write_scene(kind, n, out / f"{kind}-{n}")
            cpu, wall = load_seconds(module_dir, scene, 1 if n >= 1000000 else args.runs)
            times[kind].append((n, cpu))
            walls[kind].append(wall)
            size = sum(f.stat().st_size for f in (out / f"{kind}-{n}").iterdir())
            print(f"parsing: {kind} N={n}: {cpu:.3f} s CPU, {wall:.3f} s wall ({size / 1e6:.1f} MB of files)",
                  file=sys.stderr, flush=True)
            for leftover in (out / f"{kind}-{n}").iterdir():
                leftover.unlink()
            (out / f"{kind}-{n}").rmdir()
    print("| definitions (N) | " + " | ".join(kinds) + " |")
    print("|---|" + "---|" * len(kinds))
    for i, n in enumerate(sizes):
        print(f"| {n:,} | " + " | ".join(f"{times[kind][i][1]:.3f} s ({walls[kind][i]:.2f} s)" for kind in kinds) +
              " |")
    if len(sizes) >= 2:
        print("| slope, two largest N | " +
              " | ".join(f"{slope(times[kind][-2:]):.2f}" for kind in kinds) + " |")
    big = [i for i, n in enumerate(sizes) if n >= 10000]
    if len(big) >= 2:
        print("| slope, least squares from 10^4 | " +
              " | ".join(f"{slope([times[kind][i] for i in big]):.2f}" for kind in kinds) + " |")


if __name__ == "__main__":
    main()
