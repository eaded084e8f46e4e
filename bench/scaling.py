#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""How whole-process time and peak memory grow with the size of the scene (issue 13 item 3):
Whitted and POV-Ray 3.7 side by side, one run each, interleaved, on scenes of bench/generate.py
at several N, with the images compared. Prints a markdown table (docs/performance.md holds the
measured one).

  bench/scaling.py WHITTED OUT_DIR [--threads T] [--rows spheres,boxes,triangles,instances,lights,image]
                   [--max-seconds S] [--memory-target]

--memory-target measures the instancing target alone: 1,000 instances of the 100k-triangle
torus against one (an instance and a plain mesh), peak RSS of the whole process.
A row whose POV-Ray run would exceed --max-seconds (estimated from the row before it) is left
out for POV-Ray and marked so; none is ever estimated in the table."""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import measure
from povray_input import convert_for_timing

HERE = Path(__file__).resolve().parent

SERIES = {
    # name: (generate.py option, values, what N counts)
    "spheres": ("--many", [1000, 10000, 100000, 1000000], "spheres"),
    "boxes": ("--boxes", [1000, 10000, 100000, 1000000], "axis-aligned boxes"),
    "triangles": ("--torus", [100000, 1000000, 10000000], "triangles"),
    "instances": ("--instances", [1, 10, 100, 1000, 10000], "instances of the 100k torus"),
    "lights": ("--lights", [1, 10, 100, 1000], "point lights (100 spheres)"),
    "image": ("--image", [0.3, 1.2, 4.9, 19.7, 33], "megapixels (100 spheres)"),
}


def timed(cmd, cwd=None, env=None):
    """(wall seconds, peak RSS of the process in MB, exit code): whole process (bench/measure.py)."""
    wall, peak_mb, code, stderr = measure.timed(cmd, cwd=cwd, env=env)
    if code != 0:
        print(f"scaling: {' '.join(map(str, cmd))} failed ({code}): {stderr[-500:]}", file=sys.stderr)
    return wall, peak_mb, code


def generate(option, value, out):
    result = subprocess.run([sys.executable, str(HERE / "generate.py"), option, str(value), str(out)], check=True,
                            stdout=subprocess.PIPE, text=True)
    return [Path(line) for line in result.stdout.split()]


def size_of(scene):
    for line in scene.read_text(errors="replace").splitlines()[:40]:
        if line.startswith("image:") or line.startswith(' "image"'):
            import re
            w = re.search(r'"?width"?: (\d+)', line)
            h = re.search(r'"?height"?: (\d+)', line)
            return int(w.group(1)), int(h.group(1))
    return 640, 480


def run_pair(whitted, povray, scene, threads, env, skip_pov):
    out = scene.parent
    name = scene.stem
    pov = out / f"{name}.pov"
    ours_img, theirs_img = out / f"{name}.whitted.exr", out / f"{name}.povray.png"
    w_s, w_mb, w_rc = timed([whitted, "render", str(scene), "-o", str(ours_img), "--threads", str(threads)])
    row = {"whitted_s": w_s, "whitted_mb": w_mb, "whitted_rc": w_rc}
    if skip_pov:
        return row
    convert_for_timing(whitted, scene, pov)  # POV-Ray at its fastest (bench/povray_input.py)
    width, height = size_of(scene)
    pov_cmd = [povray, f"+I{pov.name}", f"+O{theirs_img.name}", f"+W{width}", f"+H{height}", "-D", "-A", "+Q9",
               "+FN16", "File_Gamma=1.0", f"+WT{threads}", "-GA"]
    p_s, p_mb, p_rc = timed(pov_cmd, cwd=out, env=env)
    row.update(pov_s=p_s, pov_mb=p_mb, pov_rc=p_rc)
    if w_rc == 0 and p_rc == 0:
        agree = subprocess.run([whitted, "compare", str(ours_img), str(theirs_img), "--clip"], stdout=subprocess.PIPE,
                               text=True)
        row["images"] = ("agree" if agree.returncode == 0 else "DIFFER") + ": " + agree.stdout.strip().split(":")[-1].strip()
    for f in (pov, ours_img, theirs_img, pov.with_suffix(".ini")):
        f.unlink(missing_ok=True)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("whitted")
    ap.add_argument("out")
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    ap.add_argument("--rows", default=",".join(SERIES))
    ap.add_argument("--max-seconds", type=float, default=300.0,
                    help="leave POV-Ray out of a row it would take longer than this for (estimated from the row before)")
    ap.add_argument("--memory-target", action="store_true")
    args = ap.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    povray = shutil.which("povray")
    if not povray:
        sys.exit("scaling: POV-Ray 3.7 is needed: apt-get install povray")
    home = tempfile.mkdtemp(prefix="whitted-scaling-home-")
    env = dict(os.environ, HOME=home)
    env.pop("POVINI", None)
    print(f"{args.threads} thread(s), one run each, whole process (wall time, peak RSS); "
          f"the machine may be shared with other work.\n")

    if args.memory_target:
        scenes = generate("--instances", 1, out) + generate("--instances", 1000, out)
        print("| scene | Whitted s | Whitted peak MB | POV-Ray s | POV-Ray peak MB | images |")
        print("|---|---:|---:|---:|---:|---|")
        for scene in scenes:
            r = run_pair(args.whitted, povray, scene, args.threads, env, False)
            print(f"| {scene.stem} | {r['whitted_s']:.2f} | {r['whitted_mb']:.0f} | {r.get('pov_s', 0):.2f} | "
                  f"{r.get('pov_mb', 0):.0f} | {r.get('images', '-')} |", flush=True)
        return 0

    print("| series | N | Whitted s | Whitted peak MB | POV-Ray s | POV-Ray peak MB | images |")
    print("|---|---:|---:|---:|---:|---:|---|")
    for series in args.rows.split(","):
        option, values, what = SERIES[series]
        last_pov = None
        for value in values:
            scenes = generate(option, value, out)
            scene = scenes[0]
            # POV-Ray's time grows at least as fast as N: skip it when the last row times the
            # growth already passes the limit.
            skip = last_pov is not None and last_pov[0] * value / last_pov[1] > args.max_seconds
            r = run_pair(args.whitted, povray, scene, args.threads, env, skip)
            if "pov_s" in r:
                last_pov = (r["pov_s"], value)
            pov = (f"{r['pov_s']:.2f} | {r['pov_mb']:.0f}" if "pov_s" in r else "not run (over --max-seconds) | -")
            print(f"| {series} ({what}) | {value:g} | {r['whitted_s']:.2f} | {r['whitted_mb']:.0f} | {pov} | "
                  f"{r.get('images', '-')} |", flush=True)
            for extra in scenes:
                if extra.suffix in (".yaml", ".json"):
                    extra.unlink(missing_ok=True)
            for obj in out.glob("torus-*.obj"):
                obj.unlink()
    shutil.rmtree(home, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
