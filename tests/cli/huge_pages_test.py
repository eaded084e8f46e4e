#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""WHITTED_HUGE_PAGES (renderer/app/large_blocks.cpp, docs/performance.md "Huge pages where they
pay"): the large blocks' page size is memory only, so the image is the same bit for bit with
huge pages on, off and chosen by the program; --stats says which was used; a value the program
does not know is a usage error (exit 2, before any work, an existing output kept) for every
command that traces rays.

usage: huge_pages_test.py WHITTED SOURCE_DIR WORK_DIR
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "isa"))
from harness import Failures, fresh_folder  # noqa: E402  (tests/harness.py)
from isa_identical import first_difference, scanlines  # noqa: E402  (tests/isa/isa_identical.py)

SUMMARY = {
    "on": "memory: 2 MiB pages for large blocks (WHITTED_HUGE_PAGES=on)",
    "off": "memory: 4 KiB pages (WHITTED_HUGE_PAGES=off)",
}
NEVER = "memory: 4 KiB pages (transparent huge pages are 'never' on this system)"
SANITIZED = "memory: 4 KiB pages (the sanitizer's allocator)"  # a build under AddressSanitizer


def with_setting(value):
    env = dict(os.environ)
    env.pop("WHITTED_HUGE_PAGES", None)
    if value is not None:
        env["WHITTED_HUGE_PAGES"] = value
    return env


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    whitted, source, work = (os.path.abspath(a) for a in sys.argv[1:4])
    fresh_folder(work)
    failures = Failures()
    # Images of 3.7 MB (over the 2 MiB from which blocks take huge pages): meshes from OBJ files
    # (the arrays mapped for Embree) and spheres, boxes and glass (no triangles).
    scenes = [os.path.join(source, "examples", "meshes", "meshes.yaml"),
              os.path.join(source, "examples", "glass-ball.yaml")]

    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        images = {}
        for value in ("off", "on", "auto", None):
            label = value or "unset"
            out = os.path.join(work, f"{name}.{label}.exr")
            result = failures.run([whitted, "render", scene, "-o", out, "--threads", "2", "--stats",
                                   "--exr-compression", "none"], env=with_setting(value), timeout=300)
            if result.returncode != 0:
                continue
            said = [line for line in result.stderr.splitlines() if "memory: " in line]
            said = said[0][said[0].index("memory: "):] if said else "(no memory: in --stats)"
            if value == "off":
                failures.check(said == SUMMARY["off"], f"{name}, WHITTED_HUGE_PAGES=off: --stats says '{said}'")
            elif value == "on":
                failures.check(said in (SUMMARY["on"], NEVER, SANITIZED),
                               f"{name}, WHITTED_HUGE_PAGES=on: --stats says '{said}'")
            else:
                measured = "first write took" in said and "huge pages from 2.0" in said
                failures.check(said in (NEVER, SANITIZED) or measured,
                               f"{name}, WHITTED_HUGE_PAGES {label}: --stats says '{said}'")
            images[label], width, _ = scanlines(out)
        if "off" in images:
            for label, pixels in images.items():
                if label == "off":
                    continue
                where = "" if pixels == images["off"] else f" ({first_difference(pixels, images['off'], width)})"
                failures.check(pixels == images["off"], f"{name}: the pixels with {label} are those with off{where}")

    # A value the program does not know: refused by every command that traces, before any work.
    scene = scenes[1]
    message = ["WHITTED_HUGE_PAGES=2M: not one of auto, on, off"]
    kept = os.path.join(work, "kept.png")
    with open(kept, "wb") as f:
        f.write(b"an earlier render")
    failures.refused("render", [whitted, "render", scene, "-o", kept], message, env=with_setting("2M"))
    failures.check(open(kept, "rb").read() == b"an earlier render", "render: the existing output is kept")
    fresh = os.path.join(work, "fresh.png")
    failures.refused("render, no output yet", [whitted, "render", scene, "-o", fresh], message, env=with_setting("2M"))
    failures.check(not os.path.exists(fresh), "render: no output is written")
    failures.check(not [f for f in os.listdir(work) if ".tmp" in f], "render: no temporary file is left")
    failures.refused("render, a value with an escape sequence", [whitted, "render", scene, "-o", fresh],
                     ["WHITTED_HUGE_PAGES=on\\x1b[31m: not one of auto, on, off"], env=with_setting("on\x1b[31m"))
    failures.refused("explain", [whitted, "explain", scene, "--pixel", "1,1"], message, env=with_setting("2M"))
    failures.refused("check", [whitted, "check", scene], message, env=with_setting("2M"), cwd=work)
    failures.refused("live", [whitted, "live", scene, "--no-open"], message, env=with_setting("2M"), timeout=60)
    # A command that traces nothing does not read it.
    failures.run([whitted, "convert", scene, os.path.join(work, "converted.yaml")], env=with_setting("2M"))
    failures.finish("WHITTED_HUGE_PAGES: the same pixels on, off and auto; unknown values refused")


if __name__ == "__main__":
    main()
