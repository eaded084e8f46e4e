#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted check` fails each rule of the pass rule on its own (docs/validation.md), through
the whole program: the scene is an empty 96x72 image of background (0.5, 0.25, 0.125), which
Whitted renders exactly, and a stand-in POV-Ray (fake_povray.py) writes the rounded codes of
that (0.5, 0.25 and 0.125 codes off) plus the pixels each case injects. Also checks that the
report lists the 10 worst pixels and that scripts/validate reads the verdict line.
Usage: check_rules.py WHITTED VALIDATE_SCRIPT"""

import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fake_povray  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)
SCENE = ("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\n"
         "image: { width: 96, height: 72, background: [0.5, 0.25, 0.125] }\n"
         "lights: []\nmaterials: {}\nobjects: []\n")
CODES = "32768,16384,8192"  # the background, rounded as a 16-bit PNG holds it
SIX_FAR = ";".join(f"{10 + 7 * i},{20 + i},1,{16384 + 1000}" for i in range(6))  # 6 of 6912: under 0.1 %


def check(whitted, scene, environment, *options):
    result = run([whitted, "check", scene, "-q", *options], expect=None, timeout=120, env=environment)
    lines = result.stdout.strip().splitlines()
    return result.returncode, lines[-1] if lines else "", result.stderr


def main():
    whitted, validate = sys.argv[1], sys.argv[2]
    problems = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-check-rules-") as directory:
        scene = os.path.join(directory, "background.yaml")
        with open(scene, "w") as f:
            f.write(SCENE)
        base = dict(os.environ, WHITTED_POVRAY=fake_povray.install(directory), FAKE_POVRAY_CODES=CODES)

        def case(name, expect_code, expect_in, expect_not_in=(), options=(), **fake):
            code, verdict, stderr = check(whitted, scene, dict(base, **fake), *options)
            ok = code == expect_code and all(t in verdict for t in expect_in) and \
                not any(t in verdict for t in expect_not_in)
            print(f"{name}: exit {code}: {verdict}" + ("" if ok else f"  <- expected exit {expect_code}, "
                                                            f"{expect_in} and none of {list(expect_not_in)}"))
            if not ok:
                problems.fail(f"{name}: exit {code}, verdict {verdict!r}, stderr {stderr!r}")

        case("agreeing images", 0, ["PASS ", "100.000% of pixels within 2/65535", "max 0.5 codes (cap 64)"],
             ["failed"])
        case("6 pixels 1000 codes off", 1, ["FAIL ", "99.913% of pixels", "; failed: cap (max 1000."],
             ["share (", "size (", "finite ("], FAKE_POVRAY_PIXELS=SIX_FAR)
        near = ";".join(f"{i},5,0,{32768 + 60}" for i in range(6))
        case("6 pixels 60 codes off", 0, ["PASS ", "max 60.5 codes (cap 64)"], FAKE_POVRAY_PIXELS=near)
        case("6 pixels 60 codes off, --max-error 50", 1, ["FAIL ", "(cap 50); failed: cap (max 60.5 codes > 50)"],
             options=("--max-error", "50"), FAKE_POVRAY_PIXELS=near)
        rows = ";".join(f"{x},{y},2,{8192 + 3}" for y in range(0, 72, 10) for x in range(96))  # 11 % of pixels
        case("8 rows 3 codes off", 1, ["FAIL ", "; failed: share (88.888% within 2/65535 < 99.9%)"], ["cap ("],
             FAKE_POVRAY_PIXELS=rows)
        case("POV-Ray image one column short", 1, ["FAIL ", "failed: size (96x72 vs 95x72)"],
             FAKE_POVRAY_SIZE="95x72")
        case("POV-Ray image with alpha", 1, ["FAIL ", "failed: channels (3 vs 4)"], FAKE_POVRAY_CHANNELS="4")

        # The report lists the worst pixels: the six injected ones first, in reading order.
        report = os.path.join(directory, "report")
        code, verdict, _ = check(whitted, scene, dict(base, FAKE_POVRAY_PIXELS=SIX_FAR), "--report", report)
        with open(os.path.join(report, "metrics.json")) as f:
            metrics = json.load(f)
        worst = metrics["worst_pixels"]
        injected = [[10 + 7 * i, 20 + i] for i in range(6)]
        if metrics["passed"] or metrics["failed_rules"] != ["cap"]:
            problems.fail(f"metrics.json: passed {metrics['passed']}, failed_rules {metrics['failed_rules']}")
        if len(worst) != 10 or [[w["x"], w["y"]] for w in worst[:6]] != injected:
            problems.fail(f"metrics.json worst_pixels: {[[w['x'], w['y']] for w in worst]}, expected 10 "
                            f"starting with {injected}")
        elif abs(worst[0]["error_codes"] - 1000.25) > 0.01 or worst[6]["error_codes"] > 1:
            problems.fail(f"metrics.json worst errors: {[w['error_codes'] for w in worst]}")
        with open(os.path.join(report, "report.html")) as f:
            html = f.read()
        if "The 10 worst pixels" not in html or "<li><code>cap (max 1000." not in html:
            problems.fail("report.html does not list the 10 worst pixels and the broken rule")
        print("report: worst", [[w["x"], w["y"]] for w in worst], "ok" if not problems.messages else "")

        # scripts/validate reads the verdict line: its summary shows the figures and the rule.
        result = run(["bash", validate, "--out", os.path.join(directory, "validation"), scene], expect=None,
                     timeout=120, env=dict(base, FAKE_POVRAY_PIXELS=SIX_FAR,
                                      WHITTED_BUILD_DIR=os.path.dirname(os.path.dirname(whitted))))
        print("scripts/validate:", result.stdout.strip().replace("\n", " | "))
        if result.returncode != 1 or "FAIL background: max 1000." not in result.stdout or \
                "codes, 99.913% within; failed: cap (max 1000." not in result.stdout:
            problems.fail(f"scripts/validate: exit {result.returncode}, output {result.stdout!r} {result.stderr!r}")
        # A scene file name that is not UTF-8 (byte 0xE9): the report is still JSON, written whole
        # (it printed PASS, then failed writing metrics.json with exit 2).
        latin1 = os.path.join(os.fsencode(directory), b"caf\xe9.yaml")
        with open(latin1, "w") as f:
            f.write(SCENE)
        latin1_report = os.path.join(directory, "latin1-report")
        result = run([os.fsencode(whitted), b"check", latin1, b"-q", b"--report", os.fsencode(latin1_report)],
                     expect=None, timeout=120, text=False, env=base)
        try:
            with open(os.path.join(latin1_report, "metrics.json"), encoding="utf-8") as f:
                named = json.load(f)["scene"]
            ok = result.returncode == 0 and named.endswith("caf\ufffd.yaml")
        except (OSError, ValueError, KeyError) as e:
            ok, named = False, repr(e)
        print(f"scene name not UTF-8: exit {result.returncode}, metrics.json names {named!r}", "ok" if ok else "")
        if not ok:
            problems.fail(f"scene name not UTF-8: exit {result.returncode}, {result.stderr!r}, {named!r}")
        # A report directory under a file is a usage error found before the scene is even read: with
        # a scene that is itself wrong, the report directory is what the message names (it was
        # found only after the render, 28-38 s into a large scene). The fake POV-Ray never runs.
        blocker = os.path.join(directory, "a-file")
        with open(blocker, "w") as f:
            f.write("not a directory\n")
        broken = os.path.join(directory, "broken.yaml")
        with open(broken, "w") as f:
            f.write("version: 1\nimage: {width: x}\n")
        marker = os.path.join(directory, "povray-ran")
        result = run([whitted, "check", broken, "-q", "--report", os.path.join(blocker, "report")], expect=None,
                     timeout=120, env=dict(base, FAKE_POVRAY_MARKER=marker))
        ok = result.returncode == 2 and f"'{blocker}' is not a directory" in result.stderr and \
            "broken.yaml" not in result.stderr and not os.path.exists(marker)
        print(f"report under a file: exit {result.returncode}: {result.stderr.strip()}", "ok" if ok else "")
        if not ok:
            problems.fail(f"report under a file: exit {result.returncode}, {result.stderr!r}")
    problems.finish()


if __name__ == "__main__":
    main()
