#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The report of `whitted check` in a real browser (ctest -L browser; tests/browser/README.md).

Makes a report with `whitted check` (against the image tier's stored POV-Ray image, so no
POV-Ray is needed), works out what the page must show from check's own files, read without the
page: metrics.json, ours.exr and its render layers and povray-16bit.png (read with OpenImageIO's
Python module), ours.png and diff.png; then report_test.js opens report.html from file:// in
Debian's Chromium (Playwright, every non-file request aborted and counted as a failure), moves
the wipe, zooms, probes pixels and compares what the page shows with those numbers.

usage: report_browser.py WHITTED SOURCE_DIR WORK_DIR TOOLS_DIR CASE
  CASE: layers  (check --layers all: the probe's per-term breakdown)
        plain   (no layers: no breakdown)
        static  (no layers, JavaScript off: the verdict, the figures and the three images as plain HTML)
        index   (scripts/validate on one scene: the index page's thumbnails; needs POV-Ray)
"""
import json
import math
import os
import re
import shutil
import sys
import time

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, fresh_folder, run  # noqa: E402  (tests/harness.py)
from browser_tools import CHROMIUM, chromium_env, require_tools  # noqa: E402  (beside this file)

SCENE = "tests/pov/three_coloured_lights.yaml"
REFERENCE = "tests/image/ref/three_coloured_lights.png"  # POV-Ray's render, exposure 1 (references.txt)


def read(path):
    """The pixels in the file's own type (uint16 for POV-Ray's PNG, float32 for the EXR) and the channel names."""
    image = oiio.ImageInput.open(path)
    if not image:
        fail(f"cannot read {path}: {oiio.geterror()}")
    spec = image.spec()
    pixels = image.read_image(0, 0, 0, spec.nchannels, oiio.UNKNOWN)
    names = list(spec.channelnames)
    image.close()
    return pixels, names


def codes(v):
    """As `whitted check` prints codes: one decimal of value x 65535, rounded half to even."""
    return f"{float(v) * 65535:.1f}"


def expectations_for_report(report, layers_wanted):
    """What the page must show, from check's files only."""
    with open(os.path.join(report, "metrics.json")) as f:
        metrics = json.load(f)
    exposure = metrics["exposure"]
    width, height = metrics["width"], metrics["height"]
    ours, names = read(os.path.join(report, "ours.exr"))
    ours = np.asarray(ours, dtype=np.float32)
    # POV-Ray's own 16-bit PNG, as integers: with image.samples 1 these are the compared codes.
    # metrics.json names it: povray-16bit.png in the report, or the stored image check was given.
    theirs, _ = read(os.path.join(report, metrics["files"]["povray_output"]))
    theirs = np.asarray(theirs)
    if theirs.dtype != np.uint16:
        fail(f"povray-16bit.png read as {theirs.dtype}, expected uint16")
    if metrics["samples"] != 1:
        fail("the scene must have image.samples 1 for POV-Ray's PNG codes to be the compared values")
    channel = {n: i for i, n in enumerate(names)}
    beauty = np.stack([ours[:, :, channel[c]] for c in "RGB"], axis=2)
    # ours.exr is at the scene's scale; the compared image is x exposure (a power of two: exact).
    beauty_exposed = (beauty.astype(np.float64) * exposure).astype(np.float32)
    layer_names = sorted({n.split(".")[0] for n in names if "." in n})
    colour_layers = [n for n in layer_names if all(f"{n}.{c}" in channel for c in "RGB") and
                     (n in ("ambient", "diffuse", "specular", "mirror", "transmission", "background") or re.fullmatch(r"light\d+", n))]
    if layers_wanted and not {"ambient", "diffuse", "specular"} <= set(colour_layers):
        fail(f"ours.exr has layers {layer_names}, expected the colour layers of --layers all")
    if not layers_wanted and layer_names:
        fail(f"ours.exr has layers {layer_names} though the check was run without --layers")

    def pixel(x, y):
        e = {"x": x, "y": y,
             "whitted": [codes(beauty_exposed[y, x, c]) for c in range(3)],
             "povray": [f"{int(theirs[y, x, c])}.0" for c in range(3)],
             "layers": {}}
        for n in colour_layers:
            e["layers"][n] = [codes(np.float32(float(ours[y, x, channel[f"{n}.{c}"]]) * exposure)) for c in "RGB"]
        return e

    worst = metrics["worst_pixels"]
    if not worst:
        fail("metrics.json lists no worst pixels")
    probes = []
    # The worst pixel: the page must agree with metrics.json's own values (check's output) too.
    w = worst[0]
    first = pixel(w["x"], w["y"])
    for side, key in (("whitted", "whitted"), ("povray", "povray")):
        from_metrics = [codes(v) for v in w[key]]
        if from_metrics != first[side]:
            fail(f"metrics.json worst pixel {key} {from_metrics} != the files' {first[side]}")
    probes.append(first)
    # A lit pixel with diffuse and specular both nonzero (the breakdown has several terms), and
    # one in the background.
    lit = None
    if layers_wanted:
        d, s = ours[:, :, channel["diffuse.R"]], ours[:, :, channel["specular.R"]]
        every_light = np.ones(d.shape, dtype=bool)
        for n in colour_layers:
            if n.startswith("light"):
                every_light &= ours[:, :, channel[f"{n}.R"]] > 0
        candidates = np.argwhere((d > 0) & (s > 0) & every_light)
        if len(candidates) == 0:
            candidates = np.argwhere((d > 0) & (s > 0))
        if len(candidates) == 0:
            fail("no pixel has both diffuse and specular light")
        y, x = candidates[len(candidates) // 2]
        lit = pixel(int(x), int(y))
    else:
        lit = pixel(width // 3, height // 2)
    probes.append(lit)
    probes.append(pixel(0, 0))

    # Pixels above a threshold, counted from the files: max over channels of |Whitted - POV-Ray|.
    povray_linear = (theirs.astype(np.float64) / 65535).astype(np.float32)
    diff = np.abs(beauty_exposed - povray_linear).max(axis=2).astype(np.float64) * 65535
    tolerance = metrics["tolerance_codes"]
    above = {"0": int((diff > 0).sum()), str(tolerance): int(metrics["pixels"] - metrics["pixels_within"])}
    if int((diff > tolerance).sum()) != above[str(tolerance)]:
        fail(f"{int((diff > tolerance).sum())} pixels beyond the tolerance in the files, metrics.json says "
             f"{above[str(tolerance)]}")

    # Displayed colours for the wipe: ours.png (sRGB) and diff.png (heat map), 8-bit.
    ours_png, _ = read(os.path.join(report, "ours.png"))
    diff_png, _ = read(os.path.join(report, "diff.png"))
    povray_png, _ = read(os.path.join(report, "povray.png"))
    for name, img in (("ours.png", ours_png), ("diff.png", diff_png), ("povray.png", povray_png)):
        if np.asarray(img).dtype != np.uint8:
            fail(f"{name} is not 8-bit")
    # A pixel whose heat-map colour differs clearly from Whitted's colour, to tell the sides apart.
    contrast = np.abs(np.asarray(ours_png, dtype=int) - np.asarray(diff_png, dtype=int)).sum(axis=2)
    y, x = np.unravel_index(int(np.argmax(contrast[:, width // 4: 3 * width // 4])), (height, width // 2))
    x += width // 4
    wipe = {"x": int(x), "y": int(y), "whitted_rgb": [int(v) for v in ours_png[y, x]],
            "povray_rgb": [int(v) for v in povray_png[y, x]], "diff_rgb": [int(v) for v in diff_png[y, x]]}
    return {"width": width, "height": height, "tolerance_codes": tolerance, "layers": layers_wanted,
            "colour_layers": colour_layers, "probes": probes, "above": above, "wipe": wipe,
            "worst_count": len(worst)}


def static_expectations(report):
    """What the page shows before any script runs: metrics.json's verdict and numbers, formatted
    as `whitted check` prints them, and the three images at the image's size."""
    with open(os.path.join(report, "metrics.json")) as f:
        m = json.load(f)
    if not m["worst_pixels"]:
        fail("metrics.json lists no worst pixels")
    worst = m["worst_pixels"][0]
    within = "100.000%" if m["pixels_within"] == m["pixels"] else \
        f"{math.floor(m['fraction_within'] * 100000.0) / 1000.0:.3f}%"
    metrics = {"fraction_within": within, "pixels_within": str(m["pixels_within"]), "pixels": str(m["pixels"]),
               "max_error_codes": f"{m['max_error_codes']:.1f}", "worst_x": str(worst["x"]),
               "worst_y": str(worst["y"]), "worst_error_codes": f"{worst['error_codes']:.1f}",
               "mean_error_codes": f"{m['mean_error'] * 65535:.3f}"}
    images = {}
    for name in ("whitted_png", "povray_png", "heat_map_png"):
        png, _ = read(os.path.join(report, m["files"][name]))
        if png.shape[:2] != (m["height"], m["width"]):
            fail(f"{m['files'][name]} is {png.shape[1]}x{png.shape[0]}, metrics.json says {m['width']}x{m['height']}")
        images[m["files"][name]] = [m["width"], m["height"]]
    return {"verdict": "PASS" if m["passed"] else "FAIL", "metrics": metrics, "images": images}


def main():
    if len(sys.argv) != 6:
        print(__doc__)
        sys.exit(2)
    whitted, source, work, tools, case = sys.argv[1:]
    require_tools(tools)
    fresh_folder(work)
    shots = os.path.join(work, "screenshots")
    os.makedirs(shots)

    if case in ("layers", "plain", "static"):
        report = os.path.join(work, "report")
        command = [whitted, "check", os.path.join(source, SCENE), "--povray-image", os.path.join(source, REFERENCE),
                   "--exposure", "1", "--report", report]
        if case == "layers":
            command += ["--layers", "all"]
        print(run(command).stdout, end="")
        expect = static_expectations(report) if case == "static" else expectations_for_report(report, case == "layers")
        page = os.path.join(report, "report.html")
        print(f"report-data.js: {os.path.getsize(os.path.join(report, 'report-data.js'))} bytes, "
              f"report.html: {os.path.getsize(page)} bytes")
    elif case == "index":
        if not shutil.which(os.environ.get("WHITTED_POVRAY", "povray")):
            fail("POV-Ray is missing: apt-get install povray (scripts/setup --with-test-tools does)")
        out = os.path.join(work, "validation")
        env = dict(os.environ, WHITTED_BUILD_DIR=os.path.dirname(os.path.dirname(whitted)))
        print(run(["bash", os.path.join(source, "scripts", "validate"), "--out", out,
                   os.path.join(source, SCENE)], env=env).stdout, end="")
        page = os.path.join(out, "index.html")
        png, _ = read(os.path.join(out, "three_coloured_lights", "ours.png"))
        expect = {"thumbnails": ["three_coloured_lights/ours.png", "three_coloured_lights/diff.png"],
                  "thumb_size": [int(png.shape[1]), int(png.shape[0])]}
    else:
        print(__doc__)
        sys.exit(2)

    expect_file = os.path.join(work, "expect.json")
    with open(expect_file, "w") as f:
        json.dump(expect, f, indent=1)
    env = chromium_env(os.path.join(work, "home"), tools)
    start = time.monotonic()
    browser = run(["node", os.path.join(source, "tests", "browser", "report_test.js"), case, page, expect_file,
                   shots, CHROMIUM], expect=None, env=env, timeout=120, stdout=None, stderr=None)
    print(f"browser part: {time.monotonic() - start:.1f} s; screenshots in {shots}")
    sys.exit(browser.returncode)


if __name__ == "__main__":
    main()
