#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Mutation smoke test: seeded random damage to valid scenes, each run through `whitted render`.
Fails on a signal, an exit code other than 0/1/2, a sanitizer report, a temporary file left
behind, or a hang. Seeds are the example scenes, shrunk to a small image first so that an
undamaged scene renders in well under a second.

A mutation can also make a legal but enormous render (width 65536, 16x16 samples, ...): when a
render passes the time limit it is sent SIGINT, and it counts as "slow but legal" only if it
then stops promptly with 130; otherwise it is a hang.
Usage: mutate_scenes.py WHITTED SOURCE_DIR [--count N] [--seed S] [--timeout SECONDS]"""

import argparse
import glob
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import SANITIZER_MARKERS, Failures, fail  # noqa: E402  (tests/harness.py)

NUMBER = re.compile(rb"(?<![\w.])-?\d+(\.\d+)?([eE][-+]?\d+)?(?![\w.])")
KEY = re.compile(rb"^(\s*-?\s*)(\w+):", re.MULTILINE)
NASTY_NUMBERS = [b"0", b"-1", b"-0", b"1e308", b"-1e308", b"1e-320", b"1e400", b".nan", b"nan", b".inf", b"-.inf",
                 b"65536", b"65537", b"99999999999", b"4294967296", b"2147483648", b"-2147483649", b"16", b"17",
                 b"256", b"257", b"1e9", b"0.0000001", b"3.5"]


def shrink(text):
    """Small images, few samples: an intact seed renders in a fraction of a second."""
    text = re.sub(rb"width: *\d+", b"width: 48", text)
    text = re.sub(rb"height: *\d+", b"height: 36", text)
    return re.sub(rb"samples: *\d+", b"samples: 1", text)


def mutate(text, rng):
    data = bytearray(text)
    for _ in range(rng.choice([1, 1, 1, 2, 3])):
        kind = rng.randrange(8)
        if not data:
            data = bytearray(b"{")
        if kind == 0:  # flip a bit
            i = rng.randrange(len(data))
            data[i] ^= 1 << rng.randrange(8)
        elif kind == 1:  # delete bytes
            i = rng.randrange(len(data))
            del data[i:i + rng.randint(1, 16)]
        elif kind == 2:  # duplicate bytes
            i = rng.randrange(len(data))
            data[i:i] = data[i:i + rng.randint(1, 64)]
        elif kind in (3, 4):  # replace a number by a nasty one
            numbers = list(NUMBER.finditer(data))
            if numbers:
                m = rng.choice(numbers)
                data[m.start():m.end()] = rng.choice(NASTY_NUMBERS)
        elif kind == 5:  # delete a line
            lines = data.split(b"\n")
            del lines[rng.randrange(len(lines))]
            data = bytearray(b"\n".join(lines))
        elif kind == 6:  # duplicate a line
            lines = data.split(b"\n")
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
            data = bytearray(b"\n".join(lines))
        else:  # swap two keys
            keys = list(KEY.finditer(data))
            if len(keys) >= 2:
                a, b = sorted(rng.sample(keys, 2), key=lambda m: m.start())
                ka, kb = bytes(a.group(2)), bytes(b.group(2))
                data[b.start(2):b.end(2)] = ka
                data[a.start(2):a.end(2)] = kb
    return bytes(data)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("source_dir")
    parser.add_argument("--count", type=int, default=300)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=20)
    parser.add_argument("--keep", help="copy failing scenes here")
    parser.add_argument("--no-shrink", action="store_true", help="mutate the examples at their own image size")
    args = parser.parse_args()

    seeds = sorted(glob.glob(os.path.join(args.source_dir, "examples", "**", "*.yaml"), recursive=True))
    if not seeds:
        fail("no example scenes found")
    rng = random.Random(args.seed)
    work = tempfile.mkdtemp(prefix="whitted-mutate-")
    # Mesh files the seeds name, beside the mutated scenes.
    for mesh in glob.glob(os.path.join(args.source_dir, "examples", "meshes", "*.[om][bt][jl]")):
        shutil.copy(mesh, work)
    texts = [(os.path.basename(s), open(s, "rb").read()) for s in seeds]
    if not args.no_shrink:
        texts = [(name, shrink(text)) for name, text in texts]
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "detect_leaks=1") + ":allocator_may_return_null=1"
    codes, failures, slow = {}, [], []
    start = time.monotonic()
    for n in range(args.count):
        name, text = rng.choice(texts)
        mutated = mutate(text, rng)
        scene = os.path.join(work, "scene.yaml")
        with open(scene, "wb") as f:
            f.write(mutated)
        output = os.path.join(work, "out.exr")
        process = subprocess.Popen([args.whitted, "render", scene, "-o", output, "-t", "2", "-q"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
        problem = None
        try:
            _, stderr = process.communicate(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            process.send_signal(signal.SIGINT)
            try:
                _, stderr = process.communicate(timeout=2)
                if process.returncode == 130:
                    size = re.search(rb"width: *([^,}\s]+).*?height: *([^,}\s]+)", mutated, re.S)
                    samples = re.search(rb"samples: *([^,}\s]+)", mutated)
                    depth = re.search(rb"max_depth: *([^,}\s]+)", mutated)
                    slow.append((n, name, [m.groups() if m else None for m in (size, samples, depth)]))
                else:
                    problem = f"slow, then exit {process.returncode} after SIGINT"
            except subprocess.TimeoutExpired:
                process.kill()
                _, stderr = process.communicate()
                problem = f"hang: no exit {args.timeout:.0f} s, nor within 2 s of SIGINT"
        code = process.returncode
        codes[code] = codes.get(code, 0) + 1
        text_err = stderr.decode("utf-8", "replace")
        if problem is None and code < 0:
            problem = f"killed by signal {-code}"
        elif problem is None and code not in (0, 1, 2, 130):
            problem = f"exit code {code}"
        elif problem is None and any(m in text_err for m in SANITIZER_MARKERS):
            problem = "sanitizer report"
        leftovers = [f for f in os.listdir(work) if ".tmp" in f]
        if problem is None and leftovers:
            problem = f"temporary files left: {leftovers}"
        for f in leftovers:
            os.remove(os.path.join(work, f))
        if problem:
            failures.append((n, name, problem, text_err[-2000:]))
            if args.keep:
                os.makedirs(args.keep, exist_ok=True)
                with open(os.path.join(args.keep, f"mutant-{args.seed}-{n}.yaml"), "wb") as f:
                    f.write(mutated)
        if os.path.exists(output):
            os.remove(output)
    shutil.rmtree(work, ignore_errors=True)
    elapsed = time.monotonic() - start
    print(f"mutate_scenes: {args.count} mutants of {len(texts)} scenes in {elapsed:.1f} s; exit codes {codes}")
    for n, name, size in slow:
        print(f"  slow but legal (stopped by SIGINT): mutant {n} of {name}, (width, height), samples, max_depth: {size}")
    verdict = Failures()
    for n, name, problem, err in failures:
        verdict.fail(f"mutant {n} of {name}: {problem}\n{err}")
    verdict.finish()


if __name__ == "__main__":
    main()
