#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A tiny scene's whole process against Tachyon's: where a small render's time goes when the
rendering is nothing (issue 38, docs/performance.md "Start-up").

One sphere, 64×48, written as NFF so that both programs read the same file; Whitted writes the
default 8-bit sRGB PNG (and, as further rows, an EXR and `whitted --version`, which loads the
program and does nothing), Tachyon a TGA. The runs are interleaved (Whitted, Tachyon, ...) after
one warm-up each; each figure is the median wall time of the whole process, started and reaped
here (os.posix_spawn, os.wait4), so the small cost of starting a process from Python is in both
columns alike. Also counted: the shared objects each loads (`LD_TRACE_LOADED_OBJECTS`, the
dynamic loader's own list) and its relocations (`LD_DEBUG=statistics`).

Usage: bench/startup.py WHITTED OUT_DIR [--runs N] [--threads T]"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

TINY_NFF = """v
from 0 0 -5
at 0 0 0
up 0 1 0
angle 40
hither 0.01
resolution 64 48
b 0.1 0.1 0.1
l 5 5 -5
f 1 0.2 0.2 0.8 0.3 20 0 1
s 0 0 0 1
"""


def wall(cmd):
    """Whole-process wall seconds of one run; its output goes to /dev/null."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        start = time.perf_counter()
        pid = os.posix_spawn(cmd[0], [str(c) for c in cmd], os.environ,
                             file_actions=[(os.POSIX_SPAWN_DUP2, devnull, 1), (os.POSIX_SPAWN_DUP2, devnull, 2)])
        _, status, _ = os.wait4(pid, 0)
        seconds = time.perf_counter() - start
    finally:
        os.close(devnull)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"bench: {' '.join(map(str, cmd))} failed ({os.waitstatus_to_exitcode(status)})")
    return seconds


def loaded_objects(program):
    """The shared objects the dynamic loader maps for `program` (vdso and itself excepted)."""
    out = subprocess.run([program], env={**os.environ, "LD_TRACE_LOADED_OBJECTS": "1"}, capture_output=True,
                         text=True).stdout
    return sum(1 for line in out.splitlines() if "=>" in line or line.strip().startswith("/"))


def relocations(cmd):
    """(symbol relocations, relative relocations) of the start-up, as the dynamic loader counts them."""
    err = subprocess.run([str(c) for c in cmd], env={**os.environ, "LD_DEBUG": "statistics"},
                         capture_output=True, text=True).stderr
    symbols = re.findall(r"number of relocations: (\d+)", err)
    relative = re.findall(r"number of relative relocations: (\d+)", err)
    return (int(symbols[0]) if symbols else 0), (int(relative[0]) if relative else 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("whitted")
    ap.add_argument("out")
    ap.add_argument("--runs", type=int, default=21)
    ap.add_argument("--threads", type=int, default=os.cpu_count())
    args = ap.parse_args()
    tachyon = shutil.which("tachyon")
    if not tachyon:
        sys.exit("bench: Tachyon is needed: apt-get install tachyon")
    whitted = str(Path(args.whitted).resolve())
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    scene = out / "tiny.nff"
    scene.write_text(TINY_NFF)
    threads = str(args.threads)
    commands = {
        "Whitted, PNG (default sRGB)": [whitted, "render", scene, "-o", out / "tiny.png", "--threads", threads,
                                        "--quiet"],
        "Whitted, EXR": [whitted, "render", scene, "-o", out / "tiny.exr", "--threads", threads, "--quiet"],
        "Whitted --version": [whitted, "--version"],
        "Tachyon, TGA": [tachyon, scene, "-numthreads", threads, "-o", out / "tiny.tga", "-format", "TARGA"],
    }
    for cmd in commands.values():
        wall(cmd)  # warm-up: files in the page cache
    times = {name: [] for name in commands}
    for _ in range(args.runs):
        for name, cmd in commands.items():
            times[name].append(wall(cmd))
    tachyon_times = times["Tachyon, TGA"]
    print(f"\n{args.runs} interleaved runs, {args.threads} threads, whole process, medians\n")
    print("| run | wall ms (median) | min–max ms | ÷ Tachyon (median of pairs) | shared objects | relocations "
          "(symbol / relative) |")
    print("|---|---|---|---|---|---|")
    for name, cmd in commands.items():
        ts = times[name]
        ratio = statistics.median(a / b for a, b in zip(ts, tachyon_times))
        symbols, relative = relocations(cmd)
        print(f"| {name} | {1e3 * statistics.median(ts):.1f} | {1e3 * min(ts):.1f}–{1e3 * max(ts):.1f} | "
              f"{ratio:.2f} | {loaded_objects(cmd[0])} | {symbols} / {relative} |")


if __name__ == "__main__":
    main()
