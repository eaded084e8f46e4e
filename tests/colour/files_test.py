#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every format and view, read back by programs other than Whitted, reports the colour space that
was written (docs/colour.md):

* the built-in config, written by `whitted colour --write-config`, passes `ociocheck`, and
  `oiiotool --colorconfig` with it turns Whitted's linear EXR into the same PNG codes Whitted
  wrote, to within one code, for every display and view (--ociodisplay and --colorconvert);
* EXR: chromaticities (Rec.709, D65) as OpenImageIO and ExifTool read them;
* PNG: an sRGB chunk (PIL) for the sRGB curve on Rec.709, else gAMA and cHRM with the curve's
  exponent (1 for Raw, linear) and the primaries (PIL, ExifTool), the cICP code points
  (ExifTool), the colour space OpenImageIO reports;
* JPEG and TIFF: an ICC profile whose description names the display and view (OpenImageIO,
  ExifTool, PIL), and which LittleCMS (PIL's ImageCms) uses to turn known codes into the sRGB
  codes computed here in closed form;
* everywhere: renderer and version, the scene's file name (no directory), config, display,
  view and render settings.

Usage: files_test.py WHITTED EXAMPLES_DIR"""
import io
import json
import os
import shutil
import sys
import tempfile

import yaml
from PIL import Image, ImageCms

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fail, run as run_program  # noqa: E402  (tests/harness.py)

whitted, examples = sys.argv[1], sys.argv[2]
# The version is written once, in CMake; `whitted --version` reports it ("whitted X.Y.Z" first).
software = "Whitted " + run_program([whitted, "--version"]).stdout.split()[1]
failures = Failures()
env = dict(os.environ)
env.pop("OCIO", None)


check = failures.require


def run(args, cwd):
    """ARGS in CWD without $OCIO; a tool that is not installed fails the test (not a skip)."""
    if not shutil.which(args[0]) and not os.path.isfile(args[0]):
        fail(f"{args[0]} is not installed (scripts/setup --with-test-tools installs it)")
    return failures.run(args, timeout=120, cwd=cwd, env=env)


def oiio_info(path, cwd):
    """OpenImageIO's view of a file's metadata, as name -> value text."""
    out = run(["oiiotool", "--info", "-v", path], cwd).stdout
    info = {}
    for line in out.splitlines():
        name, sep, value = line.strip().partition(": ")
        if sep:
            info[name] = value.strip('"')
    return info


def exif(path, cwd, numeric=False):
    args = ["exiftool", "-j", "-G1", "-a"] + (["-n"] if numeric else []) + [path]
    return json.loads(run(args, cwd).stdout)[0]


def srgb_encode(x):
    x = min(max(x, 0.0), 1.0)
    return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055


DECODE = {
    "srgb": lambda c: c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4,
    "gamma22": lambda c: c ** 2.2,
    "gamma24": lambda c: c ** 2.4,
    "linear": lambda c: c,
}
# P3-D65 -> Rec.709 linear, as commonly published (both D65).
P3_TO_709 = [[1.2249401, -0.2249404, 0.0], [-0.0420569, 1.0420571, 0.0], [-0.0196376, -0.0786361, 1.0982735]]
REC709 = (0.3127, 0.329, 0.64, 0.33, 0.3, 0.6, 0.15, 0.06)  # PIL's order: white, red, green, blue
P3 = (0.3127, 0.329, 0.68, 0.32, 0.265, 0.69, 0.15, 0.06)
# display -> (transfer, primaries, gAMA exponent, cICP primaries, cICP transfer, OpenImageIO's name)
STANDARD = {
    "sRGB": ("srgb", "rec709", None, 1, 13, "sRGB"),
    "Gamma 2.2": ("gamma22", "rec709", 1 / 2.2, 1, 4, "Gamma2.2"),
    "BT.1886": ("gamma24", "rec709", 1 / 2.4, 1, 1, "Gamma2.4"),
    # OpenImageIO 2.4 knows neither cICP nor cHRM: it reports the gAMA (the sRGB curve's usual 1/2.2).
    "Display P3": ("srgb", "p3", 1 / 2.2, 12, 13, "Gamma2.2"),
}
RAW = ("linear", "rec709", 1.0, 1, 8, "linear")


def expected_srgb_codes(codes, transfer, primaries):
    """The sRGB codes a colour-managed reader must show for a file's 8-bit `codes`."""
    linear = [DECODE[transfer](c / 255) for c in codes]
    if primaries == "p3":
        linear = [sum(P3_TO_709[i][k] * linear[k] for k in range(3)) for i in range(3)]
    return [round(255 * srgb_encode(v)) for v in linear]


def check_icc(path, label, transfer, primaries, description):
    im = Image.open(path)
    icc = im.info.get("icc_profile")
    if not check(icc, f"{label}: PIL finds no ICC profile"):
        return
    profile = ImageCms.ImageCmsProfile(io.BytesIO(icc))
    check(ImageCms.getProfileDescription(profile).strip() == description,
          f"{label}: ICC description {ImageCms.getProfileDescription(profile)!r}, expected {description!r}")
    # LittleCMS through the file's own profile: codes -> sRGB, against the closed form.
    samples = [(128, 128, 128), (200, 120, 60), (90, 140, 200), (30, 30, 30), (250, 250, 250)]
    probe = Image.new("RGB", (len(samples), 1))
    probe.putdata(samples)
    converted = ImageCms.profileToProfile(probe, profile, ImageCms.createProfile("sRGB"), outputMode="RGB")
    for codes, got in zip(samples, converted.getdata()):
        want = expected_srgb_codes(codes, transfer, primaries)
        check(max(abs(a - b) for a, b in zip(got, want)) <= 2,
              f"{label}: LittleCMS turns {codes} into sRGB {got}, closed form {want}")


def check_common(label, keys, scene_name, display, view):
    check(keys.get("Software") == software, f"{label}: Software is {keys.get('Software')!r}, expected {software!r}")
    check(keys.get("whitted:scene") == scene_name, f"{label}: whitted:scene is {keys.get('whitted:scene')!r}")
    check("x" in keys.get("whitted:settings", "") and "max depth" in keys.get("whitted:settings", ""),
          f"{label}: whitted:settings is {keys.get('whitted:settings')!r}")
    if display:
        check(keys.get("whitted:display") == display, f"{label}: whitted:display is {keys.get('whitted:display')!r}")
        check(keys.get("whitted:view") == view, f"{label}: whitted:view is {keys.get('whitted:view')!r}")
        check(keys.get("whitted:ocio_config") == "built-in (whitted-builtin)",
              f"{label}: whitted:ocio_config is {keys.get('whitted:ocio_config')!r}")


def description_keys(text):
    keys = {}
    for line in (text or "").splitlines():
        name, _, value = line.partition(": ")
        keys[name] = value
    return keys


with tempfile.TemporaryDirectory() as work:
    # A small copy of a lecture scene (coloured spheres, a mirror floor): quick to render.
    with open(os.path.join(examples, "lecture", "09-glazed-floor.yaml")) as f:
        scene = yaml.safe_load(f)
    scene["image"]["width"], scene["image"]["height"], scene["image"]["samples"] = 80, 60, 1
    scene_name = "small-scene.yaml"
    with open(os.path.join(work, scene_name), "w") as f:
        yaml.safe_dump(scene, f)

    config = os.path.join(work, "whitted.ocio")
    run([whitted, "colour", "--write-config", config], work)
    result = run(["ociocheck", "--iconfig", config], work)
    check("ERROR" not in result.stdout + result.stderr, f"ociocheck reports errors:\n{result.stdout}")
    listing = run([whitted, "colour", "--list", "--ocio-config", config], work).stdout
    for display in STANDARD:
        check(f"display '{display}'" in listing, f"colour --list of the written config lacks {display}")

    run([whitted, "render", scene_name, "-q", "-o", "linear.exr"], work)
    info = oiio_info("linear.exr", work)
    check(info.get("chromaticities") == "0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329",
          f"EXR: OpenImageIO reads chromaticities {info.get('chromaticities')!r}")
    check(info.get("oiio:ColorSpace") == "Linear", f"EXR: OpenImageIO reports {info.get('oiio:ColorSpace')!r}")
    check(info.get("whitted:colorspace") == "Linear Rec.709 (sRGB)", "EXR: whitted:colorspace")
    check_common("EXR", info, scene_name, None, None)
    tags = exif("linear.exr", work, numeric=True)
    chroma = [float(v) for v in str(tags.get("OpenEXR:Chromaticities", "")).split()]
    check(len(chroma) == 8 and all(abs(a - b) < 1e-6 for a, b in zip(chroma, [0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329])),
          f"EXR: ExifTool reads chromaticities {tags.get('OpenEXR:Chromaticities')!r}")

    for display, standard in STANDARD.items():
        for view in ["Standard", "Raw"]:
            transfer, primaries, gamma, cicp_primaries, cicp_transfer, oiio_name = standard if view == "Standard" else RAW
            stem = (display + "-" + view).replace(" ", "_").replace(".", "_")
            label = f"{display}/{view}"
            description = f"Whitted: {display} / {view} ("
            args = ["--display", display, "--view", view]

            # PNG
            png = stem + ".png"
            run([whitted, "render", scene_name, "-q", "-o", png] + args, work)
            info = oiio_info(png, work)
            check(info.get("oiio:ColorSpace") == oiio_name,
                  f"{label} PNG: OpenImageIO reports {info.get('oiio:ColorSpace')!r}, expected {oiio_name!r}")
            check_common(f"{label} PNG", info, scene_name, display, view)
            im = Image.open(os.path.join(work, png))
            if gamma is None:
                check(im.info.get("srgb") == 0, f"{label} PNG: PIL finds no sRGB chunk (perceptual)")
            else:
                check("srgb" not in im.info, f"{label} PNG: an sRGB chunk on a file that is not sRGB")
                check(abs(im.info.get("gamma", 0) - gamma) < 1e-5,
                      f"{label} PNG: PIL reads gAMA {im.info.get('gamma')}, expected {gamma:.5f}")
            check(tuple(im.info.get("chromaticity", ())) == (P3 if primaries == "p3" else REC709),
                  f"{label} PNG: PIL reads cHRM {im.info.get('chromaticity')}")
            check_common(f"{label} PNG (PIL)", im.info, scene_name, display, view)
            tags = exif(png, work, numeric=True)
            got = (tags.get("PNG-cICP:ColorPrimaries"), tags.get("PNG-cICP:TransferCharacteristics"),
                   tags.get("PNG-cICP:MatrixCoefficients"), tags.get("PNG-cICP:VideoFullRangeFlag"))
            check(got == (cicp_primaries, cicp_transfer, 0, 1),
                  f"{label} PNG: ExifTool reads cICP {got}, expected {(cicp_primaries, cicp_transfer, 0, 1)}")

            # The same transform through the written config in oiiotool: within one code.
            for how, steps in [("--ociodisplay", ["--ociodisplay", display, view]),
                               ("--colorconvert", ["--colorconvert", "Linear Rec.709 (sRGB)",
                                                   info.get("whitted:colorspace", "?")])]:
                reference = stem + ".oiiotool.png"
                run(["oiiotool", "--colorconfig", config, "linear.exr", "--iscolorspace", "Linear Rec.709 (sRGB)"]
                    + steps + ["-d", "uint8", "-o", reference], work)
                ours = list(Image.open(os.path.join(work, png)).getdata())
                theirs = list(Image.open(os.path.join(work, reference)).getdata())
                worst = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(ours, theirs))
                check(len(ours) == len(theirs) and worst <= 1,
                      f"{label}: oiiotool {how} with the written config differs by {worst} codes")

            # JPEG and 8-bit TIFF: the ICC profile read by LittleCMS; 16-bit TIFF by ExifTool.
            for name, extra in [(stem + ".jpg", []), (stem + ".8.tif", ["--bit-depth", "8"]), (stem + ".tif", [])]:
                run([whitted, "render", scene_name, "-q", "-o", name] + args + extra, work)
                flabel = f"{label} {name[len(stem) + 1:]}"
                info = oiio_info(name, work)
                check(info.get("ICCProfile:profile_description", "").startswith(description),
                      f"{flabel}: OpenImageIO reads ICC description {info.get('ICCProfile:profile_description')!r}")
                tags = exif(name, work)
                check(tags.get("ICC_Profile:ProfileDescription", "").startswith(description),
                      f"{flabel}: ExifTool reads ICC description {tags.get('ICC_Profile:ProfileDescription')!r}")
                keys = description_keys(tags.get("IFD0:ImageDescription") or tags.get("File:Comment"))
                keys["Software"] = tags.get("IFD0:Software") or info.get("Software")
                check_common(flabel, keys, scene_name, display, view)
                if not name.endswith(".tif") or extra:
                    check_icc(os.path.join(work, name), flabel, transfer, primaries,
                              info.get("ICCProfile:profile_description", "?"))
    left = [n for n in os.listdir(work) if ".whitted-" in n]
    check(not left, f"temporary files left: {left}")

failures.finish("ok: 0 problem(s)")
