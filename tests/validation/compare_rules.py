#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted compare` through the whole program (docs/validation.md):
  - each rule of the pass rule fails on its own, on float EXRs with known pixels (written as
    PFMs and converted by oiiotool): 6 pixels far off (cap), a NaN, an Inf, many pixels a
    little off (share), another size, another channel count; and the verdict line names the rule;
  - files that are not complete images are refused with exit 2 and a `whitted: error:` message,
    quickly: a PNG whose header claims 65535x65535, a truncated PNG, /dev/zero, a fifo.
Usage: compare_rules.py WHITTED OIIOTOOL"""

import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import images  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

CODE = 1 / 65535


def compare(whitted, *arguments, timeout=30):
    result = run([whitted, "compare", *arguments], expect=None, timeout=timeout)
    return result.returncode, result.stdout.strip(), result.stderr.strip()


def main():
    whitted, oiiotool = sys.argv[1], sys.argv[2]
    problems = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-compare-rules-") as d:
        def exr(name, value=0.5, overrides=None, width=96, height=72, channels=3):
            path = os.path.join(d, name + ".exr")
            images.exr(oiiotool, path, width, height, value, overrides, channels)
            return path

        reference = exr("reference")

        def case(name, other, expect_code, expect_in, expect_not_in=(), options=()):
            code, out, err = compare(whitted, reference, other, *options)
            ok = code == expect_code and all(t in out for t in expect_in) and not any(t in out for t in expect_not_in)
            print(f"{name}: exit {code}: {out or err}" + ("" if ok else "  <- unexpected"))
            if not ok:
                problems.fail(f"{name}: exit {code}, stdout {out!r}, stderr {err!r}")

        case("identical", reference, 0, ["PASS ", "max 0.0 codes (cap 64)"], ["failed"])
        six = {(10 + i, 30, 0): 0.5 + 1000 * CODE for i in range(6)}
        case("6 pixels 1000 codes off", exr("six", overrides=six), 1,
             ["FAIL ", "99.913% of pixels", "at (10, 30)", "; failed: cap (max 1000.0 codes > 64)"],
             ["share (", "finite ("])
        case("... with --max-error 2000", exr("six2", overrides=six), 0, ["PASS ", "(cap 2000)"],
             options=("--max-error", "2000"))
        case("one NaN", exr("nan", overrides={(95, 71, 2): float("nan")}), 1,
             ["FAIL ", "max inf codes", "failed: cap (max inf codes > 64), finite (0 NaN/Inf value(s) in"])
        case("one Inf, clipped", exr("inf", overrides={(0, 0, 1): float("inf")}), 1,
             ["FAIL ", "finite (0 NaN/Inf value(s) in", ", 1 in "], options=("--clip",))
        rows = {(x, y, 1): 0.5 + 3 * CODE for y in range(0, 72, 8) for x in range(96)}
        case("9 rows 3 codes off", exr("rows", overrides=rows), 1, ["FAIL ", "failed: share (87.500% within"],
             ["cap ("])
        case("another size", exr("small", width=95), 1, ["FAIL ", "failed: size (96x72 vs 95x72)"])
        case("grey against RGB", exr("grey", channels=1), 1, ["FAIL ", "failed: channels (3 vs 1: colour against grey)"])
        # The colour is what is compared: RGBA (or an EXR with render layers) against RGB passes.
        rgba = os.path.join(d, "rgba.exr")
        run([oiiotool, exr("rgb"), "--ch", "R,G,B,A=1.0", "-o", rgba])
        case("RGBA against RGB", rgba, 0, ["PASS "])

        def refused(name, path, fragment):
            code, out, err = compare(whitted, reference, path)
            ok = code == 2 and err.startswith("whitted: error: ") and fragment in err and not out
            print(f"{name}: exit {code}: {err}" + ("" if ok else "  <- unexpected"))
            if not ok:
                problems.fail(f"{name}: exit {code}, stdout {out!r}, stderr {err!r} (expected exit 2, {fragment!r})")

        huge = os.path.join(d, "huge.png")
        images.png_claiming(huge, 65535, 65535)
        refused("PNG header claiming 65535x65535", huge, "is 65535x65535; the limit is 65536 per side")
        whole = os.path.join(d, "whole.png")
        images.png16(whole, 96, 72, [32768, 32768, 32768])
        with open(whole, "rb") as f:
            data = f.read()
        cut = os.path.join(d, "cut.png")
        with open(cut, "wb") as f:
            f.write(data[:len(data) // 2])
        refused("truncated PNG", cut, "the PNG file is truncated")
        code, out, err = compare(whitted, reference, whole)  # the uncut file reads: the cut was the fault
        # Its verdict is the last line (compare first says how it decoded each file).
        if code not in (0, 1) or not out.strip().splitlines()[-1:][0].startswith(("PASS", "FAIL")):
            problems.fail(f"the complete PNG did not compare: exit {code}, {out!r} {err!r}")
        refused("/dev/zero", "/dev/zero", "'/dev/zero': it is a character device")
        fifo = os.path.join(d, "fifo.png")
        os.mkfifo(fifo)
        refused("a fifo", fifo, "it is a fifo")
    problems.finish()


if __name__ == "__main__":
    main()
