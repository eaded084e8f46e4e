# SPDX-License-Identifier: MIT
"""Whole-process wall time and peak memory of one command, for the benchmarks (run.py, scaling.py).

The peak resident memory is taken by GNU time (`/usr/bin/time -f %M`), not from os.wait4 here:
Linux counts the memory a child shares with its parent between fork and exec as the child's own,
so ru_maxrss of a child of this Python process is at least what this process held when it forked
(seen: every row after a 1M-box scene's SDL was read here reported 1318 MB, Whitted and POV-Ray
alike). GNU time is small, and the command it forks inherits only GNU time's few megabytes.
Package: `time` (scripts/setup installs it with the test tools)."""
import os
import subprocess
import sys
import tempfile
import time

GNU_TIME = "/usr/bin/time"


def timed(cmd, cwd=None, env=None):
    """(wall seconds, peak RSS of the command in MB, exit code, stderr): whole process."""
    if not os.access(GNU_TIME, os.X_OK):
        sys.exit("bench: GNU time is needed for peak memory: apt-get install time")
    with tempfile.NamedTemporaryFile("r", prefix="whitted-bench-time-", suffix=".txt") as report:
        start = time.perf_counter()
        proc = subprocess.run([GNU_TIME, "-f", "%M", "-o", report.name, *map(str, cmd)], cwd=cwd, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        wall = time.perf_counter() - start
        lines = [line for line in report.read().splitlines() if line.strip()]
    # On failure GNU time writes "Command exited with non-zero status N" before the figure.
    peak_kb = int(lines[-1]) if lines and lines[-1].strip().isdigit() else 0
    return wall, peak_kb / 1024.0, proc.returncode, proc.stderr
