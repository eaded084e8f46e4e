#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Render layers and `whitted explain` (docs/layers.md), checked from outside Whitted.

    layers_test.py WHITTED SCENE_DIR OUT_DIR CASE

SCENE_DIR holds the POV-Ray tier's scenes (tests/pov). The EXR files are read with OpenImageIO's
Python module and `oiiotool`, neither of which is Whitted's code. CASE is one of:

  sum       every pixel's R, G, B is the float32 sum ambient + diffuse + specular + mirror +
            background of the file's own layers, bit for bit, on scenes with mirrors, several
            lights, shadows and 4x4 samples; the light<k> layers add up to diffuse + specular
            (to float rounding); the beauty with layers is within 1e-6 of the one without.
  closed    each layer against a closed-form value computed here from the geometry: one sphere
            seen head-on, two point lights (one behind the surface), a mirror term, a plane
            behind, and without it a corner that misses.
  names     `oiiotool --info -v` lists the conventional channel names.
  explain   `whitted explain --json`: over many pixels of several scenes (mirrors, samples 4),
            its float pixel equals the EXR's pixel bit for bit, and summing its own terms in
            the lecture's order (in double, here) gives its total exactly.
  usage     layers with a PNG, a bad layer name, bad --pixel: exit 2 before any work, no file.
"""

import json
import math
import os
import random
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import read_pixels, run  # noqa: E402  (tests/harness.py)

import numpy as np

COLOUR_TERMS = ["ambient", "diffuse", "specular", "mirror", "transmission", "background"]


def read_exr(path):
    """{channel name: HxW float32 array}, read with OpenImageIO."""
    pixels, names = read_pixels(path, with_names=True)
    return {name: pixels[:, :, c].astype(np.float32) for c, name in enumerate(names)}


def layer(channels, name):
    return np.stack([channels[f"{name}.{c}"] for c in "RGB"], axis=-1)


def render(whitted, scene, out, *extra):
    run([whitted, "render", scene, "-o", out, "-q", *extra])
    return read_exr(out)


def scene_with(out_dir, source, name, replace):
    """A copy of `source` with regex replacements (e.g. more samples)."""
    text = open(source).read()
    for pattern, repl in replace:
        text, n = re.subn(pattern, repl, text)
        if n == 0:
            sys.exit(f"FAIL: test set-up: '{pattern}' not found in {source}")
    path = os.path.join(out_dir, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def sum_scenes(scene_dir, out_dir):
    scenes = [os.path.join(scene_dir, s) for s in
              ["glazed_floor.yaml", "three_coloured_lights.yaml", "shadow_box.yaml", "facing_mirrors_depth12.yaml",
               "phong_blinn_mixed.yaml", "mesh_obj_smooth.yaml", "samples_2.yaml"]]
    scenes.append(scene_with(out_dir, os.path.join(scene_dir, "glazed_floor.yaml"), "glazed_floor_4x4.yaml",
                             [(r"background:", "samples: 4, background:")]))
    scenes.append(scene_with(out_dir, os.path.join(scene_dir, "three_coloured_lights.yaml"),
                             "three_lights_4x4.yaml", [(r"image: \{", "image: { samples: 4,")]))
    return scenes


def case_sum(whitted, scene_dir, out_dir):
    worst_relative = 0.0
    for scene in sum_scenes(scene_dir, out_dir):
        name = os.path.splitext(os.path.basename(scene))[0]
        layered = render(whitted, scene, os.path.join(out_dir, name + "_layers.exr"), "--layers", "all")
        plain = render(whitted, scene, os.path.join(out_dir, name + ".exr"))
        beauty = np.stack([layered[c] for c in "RGB"], axis=-1)
        total = np.zeros_like(beauty, dtype=np.float32)
        for term in COLOUR_TERMS:
            total = (total + layer(layered, term)).astype(np.float32)  # float32 adds, in this order
        bad = np.argwhere(total.view(np.uint32) != beauty.view(np.uint32))
        if len(bad):
            y, x, c = bad[0]
            sys.exit(f"FAIL: {name}: {len(bad)} channels where the layers do not sum to the beauty; first "
                     f"pixel ({x}, {y}) channel {c}: sum {total[y, x, c]!r} != beauty {beauty[y, x, c]!r}")
        lights = sorted(k[:-2] for k in layered if re.fullmatch(r"light\d+\.R", k))
        if not lights:
            sys.exit(f"FAIL: {name}: no light<k> layers")
        light_sum = sum(layer(layered, l).astype(np.float64) for l in lights)
        direct = layer(layered, "diffuse").astype(np.float64) + layer(layered, "specular").astype(np.float64)
        error = np.max(np.abs(light_sum - direct) / np.maximum(1.0, np.abs(direct)))
        if error > 1e-6:
            sys.exit(f"FAIL: {name}: the light layers sum to diffuse + specular only within {error:g}")
        plain_beauty = np.stack([plain[c] for c in "RGB"], axis=-1).astype(np.float64)
        relative = np.max(np.abs(beauty.astype(np.float64) - plain_beauty) / np.maximum(1e-3, np.abs(plain_beauty)))
        differ = int(np.count_nonzero(beauty.view(np.uint32) != plain_beauty.astype(np.float32).view(np.uint32)))
        if relative > 1e-6:
            sys.exit(f"FAIL: {name}: the beauty with layers differs from the one without by {relative:g} (relative)")
        worst_relative = max(worst_relative, relative)
        print(f"ok {name}: {beauty.shape[1]}x{beauty.shape[0]}, layers sum to the beauty bit for bit; "
              f"{len(lights)} light layer(s); beauty with layers vs without: {differ} of {beauty.size} channels "
              f"differ, by at most {relative:.3g} (relative)")
    print(f"worst relative difference, beauty with vs without layers: {worst_relative:.3g}")


def normalize(v):
    length = math.sqrt(sum(c * c for c in v))
    return [c / length for c in v]


def dot(a, b):
    return sum(p * q for p, q in zip(a, b))


CLOSED_SCENE = """version: 1
camera: { eye: [0, 0, -6], look_at: [0, 0, 0], fov: 40 }
image: { width: 33, height: 33, background: [0.1, 0.2, 0.3] }
ambient: [0.5, 0.6, 0.7]
lights:
  - { type: point, position: [3, 4, -5], intensity: [1, 0.9, 0.8] }
  - { type: point, position: [0, 0, 10], intensity: [0.7, 0.7, 0.7] }
materials:
  shiny: { ka: [0.1, 0.05, 0.02], kd: [0.6, 0.3, 0.2], ks: [0.4, 0.5, 0.6], p: 20, km: [0.25, 0.5, 0.75] }
  dull: { kd: 0.5 }
objects:
  - { type: plane, point: [0, 0, 30], normal: [0, 0, -1], material: dull }
  - { type: sphere, center: [0, 0, 0], radius: 1.5, material: shiny }
"""


def case_closed(whitted, out_dir):
    scene = os.path.join(out_dir, "closed.yaml")
    with open(scene, "w") as f:
        f.write(CLOSED_SCENE)
    got = render(whitted, scene, os.path.join(out_dir, "closed.exr"), "--layers", "all")
    # The centre pixel (16, 16) of a 33x33 image: screen point (0, 0), so its ray is the view
    # axis, from the eye along +z; it meets the sphere at x = (0, 0, -1.5), where n = (0, 0, -1)
    # faces the ray and v = (0, 0, -1). Light 2 sits behind the sphere (n·l < 0): it adds
    # nothing. The mirror ray r = 2(n·v)n − v = (0, 0, −1) goes back past the eye into the
    # background, so the mirror layer is km·background and the path has 1 hit.
    eye, x = [0, 0, -6], [0, 0, -1.5]
    n = [0, 0, -1]
    v = [0, 0, -1]
    ka, kd, ks, p, km = [0.1, 0.05, 0.02], [0.6, 0.3, 0.2], [0.4, 0.5, 0.6], 20, [0.25, 0.5, 0.75]
    ia, bg, i1 = [0.5, 0.6, 0.7], [0.1, 0.2, 0.3], [1, 0.9, 0.8]
    l = normalize([3 - x[0], 4 - x[1], -5 - x[2]])
    h = normalize([a + b for a, b in zip(l, v)])
    expect = {
        "ambient": [ka[c] * ia[c] for c in range(3)],
        "diffuse": [kd[c] * i1[c] * dot(n, l) for c in range(3)],
        "specular": [ks[c] * i1[c] * dot(n, h) ** p for c in range(3)],
        "mirror": [km[c] * bg[c] for c in range(3)],
        "transmission": [0, 0, 0],
        "background": [0, 0, 0],
        "light2": [0, 0, 0],
        "albedo": kd,
    }
    expect["light1"] = [expect["diffuse"][c] + expect["specular"][c] for c in range(3)]
    data = {"N": n, "Ng": n, "P": x}
    scalars = {"Z": 6 - 1.5, "objectId": 2, "materialId": 1, "hits": 1}
    checks = 0
    for name, value in expect.items():
        for c, channel in enumerate("RGB"):
            g = float(got[f"{name}.{channel}"][16, 16])
            if not math.isclose(g, value[c], rel_tol=1e-6, abs_tol=1e-7):
                sys.exit(f"FAIL: closed form: {name}.{channel} at the centre is {g!r}, expected {value[c]!r}")
            checks += 1
    for name, value in data.items():
        for c, channel in enumerate("XYZ"):
            g = float(got[f"{name}.{channel}"][16, 16])
            if not math.isclose(g, value[c], rel_tol=1e-6, abs_tol=1e-7):
                sys.exit(f"FAIL: closed form: {name}.{channel} at the centre is {g!r}, expected {value[c]!r}")
            checks += 1
    for name, value in scalars.items():
        g = float(got[name][16, 16])
        if not math.isclose(g, value, rel_tol=1e-6):
            sys.exit(f"FAIL: closed form: {name} at the centre is {g!r}, expected {value!r}")
        checks += 1
    # The corner pixel's ray goes past the sphere to the plane z = 30 (object 1, material 2):
    # a dull plane has no mirror, so 1 hit, Z = the ray's length to z = 30, and P.z = 30.
    # Its normal (0, 0, −1) faces the ray already, so N = Ng.
    width, fov = 33, math.radians(40)
    half = math.tan(fov / 2)
    x0, y0 = (0.5 / width - 0.5), (0.5 - 0.5 / width)
    # right = forward × up = −x, up = +y, and the forward vector's length 1/(2·tan(fov/2)) for a
    # square image (docs/scene-format.md: the camera).
    d = normalize([-x0, y0, 1 / (2 * half)])
    t = (30 - eye[2]) / d[2]
    corner = {"Z": t, "objectId": 1, "materialId": 2, "hits": 1, "P.Z": 30.0, "P.X": t * d[0], "P.Y": t * d[1],
              "N.Z": -1.0, "Ng.Z": -1.0, "mirror.R": 0.0, "background.R": 0.0}
    for name, value in corner.items():
        g = float(got[name][0, 0])
        if not math.isclose(g, value, rel_tol=1e-6, abs_tol=1e-7):
            sys.exit(f"FAIL: closed form: {name} at the corner is {g!r}, expected {value!r}")
        checks += 1
    # With no plane, the corner misses: background layer = background, Z = +inf, ids 0, hits 0.
    open_scene = os.path.join(out_dir, "closed_miss.yaml")
    with open(open_scene, "w") as f:
        f.write(CLOSED_SCENE.replace("  - { type: plane, point: [0, 0, 30], normal: [0, 0, -1], material: dull }\n", ""))
    miss = render(whitted, open_scene, os.path.join(out_dir, "closed_miss.exr"), "--layers", "all")
    for name, value in {"background.R": 0.1, "background.G": 0.2, "background.B": 0.3, "Z": math.inf,
                        "objectId": 0, "materialId": 0, "hits": 0, "N.X": 0, "P.Z": 0, "ambient.R": 0,
                        "R": 0.1, "B": 0.3}.items():
        g = float(miss[name][0, 0])
        if not (g == value or math.isclose(g, value, rel_tol=1e-6)):
            sys.exit(f"FAIL: closed form: {name} where the camera ray misses is {g!r}, expected {value!r}")
        checks += 1
    # Now the sphere is object 1 and its material 'shiny' still 1.
    if float(miss["objectId"][16, 16]) != 1 or float(miss["materialId"][16, 16]) != 1:
        sys.exit("FAIL: closed form: object/material numbering without the plane")
    print(f"ok closed form: {checks + 2} layer values match the geometry")


EXPECTED_CHANNELS = (["R", "G", "B", "Z", "objectId", "materialId", "hits"] +
                     [f"{l}.{c}" for l in COLOUR_TERMS + ["light1", "light2", "albedo"] for c in "RGB"] +
                     [f"{l}.{c}" for l in ["N", "Ng", "P"] for c in "XYZ"])


def case_names(whitted, out_dir):
    scene = os.path.join(out_dir, "names.yaml")
    with open(scene, "w") as f:
        f.write(CLOSED_SCENE)
    out = os.path.join(out_dir, "names.exr")
    run([whitted, "render", scene, "-o", out, "-q", "--layers", "all"])
    info = run(["oiiotool", "--info", "-v", out]).stdout
    match = re.search(r"channel list: (.*)", info)
    if not match:
        sys.exit(f"FAIL: oiiotool --info -v printed no channel list:\n{info}")
    listed = [c.strip() for c in match.group(1).split(",")]
    listed = [c.split(" ")[0] for c in listed]
    missing = [c for c in EXPECTED_CHANNELS if c not in listed]
    extra = [c for c in listed if c not in EXPECTED_CHANNELS]
    if missing or extra:
        sys.exit(f"FAIL: channels: missing {missing}, unexpected {extra}; oiiotool lists {listed}")
    # A subset, asked for in the scene file, with --half: colour layers half, data layers float.
    subset_scene = os.path.join(out_dir, "names_subset.yaml")
    with open(subset_scene, "w") as f:
        f.write(CLOSED_SCENE.replace("version: 1\n", "version: 1\nrender: { layers: [diffuse, N, objectId] }\n"))
    out = os.path.join(out_dir, "names_subset.exr")
    run([whitted, "render", subset_scene, "-o", out, "-q", "--half"])
    info = run(["oiiotool", "--info", "-v", out]).stdout
    listed = [c.strip() for c in re.search(r"channel list: (.*)", info).group(1).split(",")]
    want = {"R (half)", "G (half)", "B (half)", "diffuse.R (half)", "diffuse.G (half)", "diffuse.B (half)",
            "N.X (float)", "N.Y (float)", "N.Z (float)", "objectId (float)"}
    if set(listed) != want:
        sys.exit(f"FAIL: render.layers [diffuse, N, objectId] with --half: channels {listed}, expected {sorted(want)}")
    print(f"ok names: oiiotool lists the {len(EXPECTED_CHANNELS)} expected channels; render.layers subset with "
          f"--half: {', '.join(listed)}")


def explained_total(e, background):
    """Re-adds the explanation's own terms in the lecture's order, in double; checks each step."""
    total = [0.0, 0.0, 0.0]
    for sample in e["samples"]:
        radiance = [0.0, 0.0, 0.0]
        for s in sample["segments"]:
            w = s["weight"]
            if not s["hit"]:
                seen = [w[c] * background[c] for c in range(3)]
                assert seen == s["seen"], (seen, s["seen"])
                radiance = [radiance[c] + seen[c] for c in range(3)]
                continue
            m = s["material"]
            local = [m["ka"][c] * s["ambient_light"][c] for c in range(3)]
            assert local == s["ambient"], (local, s["ambient"])
            for light in s["lights"]:
                if not light["facing"] or light["blocked"]:
                    assert light["diffuse"] == [0, 0, 0] and light["specular"] == [0, 0, 0]
                    continue
                i = light["intensity"]
                diffuse = [m["kd"][c] * i[c] * light["n_dot_l"] for c in range(3)]
                specular = [m["ks"][c] * i[c] * light["lobe"] for c in range(3)]
                assert diffuse == light["diffuse"] and specular == light["specular"], (diffuse, light)
                local = [local[c] + (diffuse[c] + specular[c]) for c in range(3)]
            assert local == s["local"], (local, s["local"])
            added = [w[c] * local[c] for c in range(3)]
            assert added == s["added"], (added, s["added"])
            radiance = [radiance[c] + added[c] for c in range(3)]
            if s["mirror"] is not None:
                assert s["mirror"]["weight"] == [w[c] * m["km"][c] for c in range(3)]
        assert radiance == sample["radiance"], (radiance, sample["radiance"])
        total = [total[c] + radiance[c] for c in range(3)]
    n = e["samples_per_side"]
    return total if n == 1 else [t / (n * n) for t in total]


def case_explain(whitted, scene_dir, out_dir):
    scenes = [os.path.join(scene_dir, s) for s in
              ["glazed_floor.yaml", "three_coloured_lights.yaml", "shadow_box.yaml", "facing_mirrors_depth12.yaml",
               "mesh_obj_smooth.yaml"]]
    scenes.append(scene_with(out_dir, os.path.join(scene_dir, "glazed_floor.yaml"), "glazed_floor_explain_4x4.yaml",
                             [(r"background:", "samples: 4, background:")]))
    schema_path = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "explain.schema.json")
    import jsonschema
    schema = json.load(open(schema_path))
    rng = random.Random(14)
    checked = blocked = mirrored = 0
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        plain = render(whitted, scene, os.path.join(out_dir, name + "_plain.exr"))
        layered = render(whitted, scene, os.path.join(out_dir, name + "_layers.exr"), "--layers", "all")
        height, width = plain["R"].shape
        pixels = [(0, 0), (width - 1, height - 1), (width // 2, height // 2)]
        pixels += [(rng.randrange(width), rng.randrange(height)) for _ in range(9)]
        for x, y in pixels:
            e = json.loads(run([whitted, "explain", scene, "--pixel", f"{x},{y}", "--json"]).stdout)
            jsonschema.validate(e, schema)
            for c, channel in enumerate("RGB"):
                want = np.float32(plain[channel][y, x])
                got = np.float32(e["rgb"][c])
                if got.view(np.uint32) != want.view(np.uint32):
                    sys.exit(f"FAIL: {name} pixel ({x}, {y}) {channel}: explain says {got!r}, the EXR has {want!r}")
                want_layered = np.float32(layered[channel][y, x])
                if np.float32(e["layers"]["beauty"][c]).view(np.uint32) != want_layered.view(np.uint32):
                    sys.exit(f"FAIL: {name} pixel ({x}, {y}) {channel}: explain's layer beauty "
                             f"{e['layers']['beauty'][c]!r} != the --layers EXR's {want_layered!r}")
            total = explained_total(e, e["background"])
            if total != e["pixel"]:
                sys.exit(f"FAIL: {name} pixel ({x}, {y}): its terms add up to {total}, explain says {e['pixel']}")
            if [float(np.float32(t)) for t in total] != e["rgb"]:
                sys.exit(f"FAIL: {name} pixel ({x}, {y}): float of the terms' total {total} != {e['rgb']}")
            for sample in e["samples"]:
                for s in sample["segments"]:
                    blocked += sum(1 for l in s.get("lights", []) if l["blocked"] and l["blocker"])
                    mirrored += s.get("mirror") is not None
            checked += 1
        text = run([whitted, "explain", scene, "--pixel", f"{pixels[2][0]},{pixels[2][1]}"]).stdout
        if "pixel = " not in text or "L = " not in text:
            sys.exit(f"FAIL: {name}: the text form lacks the totals:\n{text}")
    if blocked == 0 or mirrored == 0:
        sys.exit(f"FAIL: the sampled pixels had {blocked} blocked shadow rays and {mirrored} mirror rays; "
                 "the test needs both")
    print(f"ok explain: {checked} pixels of {len(scenes)} scenes equal the EXRs bit for bit and add up from their "
          f"own terms ({blocked} blocked shadow rays named, {mirrored} mirror rays)")


OVERFLOW_NFF = """v
from 0 0 10
at 0 0 0
up 0 1 0
angle 45
hither 0.01
resolution 16 12
b 0 0 0
l 5 5 5 1e300 1e300 1e300
f 1e300 1e300 1e300 1 0 10 0 1
s 0 0 0 2
"""


def non_finite_strings(value):
    """Every "inf", "-inf" or "nan" string in a decoded JSON document."""
    if isinstance(value, str):
        return [value] if value in ("inf", "-inf", "nan") else []
    if isinstance(value, list):
        return [s for item in value for s in non_finite_strings(item)]
    if isinstance(value, dict):
        return [s for item in value.values() for s in non_finite_strings(item)]
    return []


def case_overflow(whitted, out_dir):
    """A legal scene whose light and colour are 1e300 overflows the float pixel to +inf (and
    products of inf and 0 give NaN); JSON has no such numbers, so explain --json writes the
    strings the schema allows instead of null (which failed the schema 30 times)."""
    scene = os.path.join(out_dir, "overflow.nff")
    with open(scene, "w") as f:
        f.write(OVERFLOW_NFF)
    import jsonschema
    schema_path = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "explain.schema.json")
    schema = json.load(open(schema_path))
    text = run([whitted, "explain", scene, "--pixel", "8,6", "--json"]).stdout
    if "null" in text.replace('"shadow_ray": null', "").replace('"blocker": null', "").replace(
            '"mirror": null', "").replace('"refracted": null', ""):
        sys.exit(f"FAIL: explain --json wrote a number as null:\n{text[:3000]}")
    e = json.loads(text)
    jsonschema.validate(e, schema)
    named = non_finite_strings(e)
    if e["layers"]["beauty"] != ["inf", "inf", "inf"] or e["rgb"] != ["inf", "inf", "inf"]:
        sys.exit(f"FAIL: the overflowing pixel is {e['rgb']} (layers: {e['layers']['beauty']}), expected inf")
    print(f"ok overflow: the document validates; {len(named)} non-finite values written as strings")


def case_usage(whitted, out_dir):
    scene = os.path.join(out_dir, "usage.yaml")
    with open(scene, "w") as f:
        f.write(CLOSED_SCENE)
    layered_scene = os.path.join(out_dir, "usage_layers.yaml")
    with open(layered_scene, "w") as f:
        f.write(CLOSED_SCENE.replace("version: 1\n", "version: 1\nrender:\n  layers: [diffuse, nromal]\n"))
    good_layers_scene = os.path.join(out_dir, "usage_good_layers.yaml")
    with open(good_layers_scene, "w") as f:
        f.write(CLOSED_SCENE.replace("version: 1\n", "version: 1\nrender: { layers: [all] }\n"))
    png = os.path.join(out_dir, "usage.png")
    for stale in [png, os.path.join(out_dir, "u.exr")]:  # an earlier run's files would hide a write
        if os.path.exists(stale):
            os.remove(stale)
    cases = [
        ([whitted, "render", scene, "-o", png, "--layers", "all"], "written as channels of an EXR only"),
        ([whitted, "render", good_layers_scene, "-o", png], "render.layers at " + good_layers_scene + ":2:"),
        ([whitted, "render", scene, "-o", os.path.join(out_dir, "u.exr"), "--layers", "diffuse,speculr"],
         "unknown render layer 'speculr'"),
        ([whitted, "render", layered_scene, "-o", os.path.join(out_dir, "u.exr")],
         layered_scene + ":3:21: render.layers: unknown render layer 'nromal'"),
        ([whitted, "explain", scene, "--pixel", "33,0"], "outside the 33x33 image"),
        ([whitted, "explain", scene, "--pixel", "5"], "expected X,Y"),
        ([whitted, "explain", scene, "--pixel", "-1,4"], "whole number"),
        ([whitted, "explain", scene, "--pixel", "a,4"], "whole number"),
    ]
    for args, message in cases:
        result = run(args, expect=2)
        if message not in result.stderr:
            sys.exit(f"FAIL: {' '.join(args)}: stderr lacks '{message}':\n{result.stderr}")
    for path in [png, os.path.join(out_dir, "u.exr")]:
        if os.path.exists(path):
            sys.exit(f"FAIL: a refused render wrote {path}")
    # --layers none overrides the scene's render.layers: the PNG is written.
    written = os.path.join(out_dir, "usage_no_layers.png")
    run([whitted, "render", good_layers_scene, "-o", written, "-q", "--layers", "none"])
    if not os.path.exists(written):
        sys.exit(f"FAIL: --layers none wrote no {written}")
    print(f"ok usage: {len(cases)} refusals with exit 2 and a clear message; --layers none overrides the scene")


def main():
    whitted, scene_dir, out_dir, case = sys.argv[1:5]
    os.makedirs(out_dir, exist_ok=True)
    if case == "sum":
        case_sum(whitted, scene_dir, out_dir)
    elif case == "closed":
        case_closed(whitted, out_dir)
    elif case == "names":
        case_names(whitted, out_dir)
    elif case == "explain":
        case_explain(whitted, scene_dir, out_dir)
    elif case == "overflow":
        case_overflow(whitted, out_dir)
    elif case == "usage":
        case_usage(whitted, out_dir)
    else:
        sys.exit(f"unknown case {case}")


if __name__ == "__main__":
    main()
