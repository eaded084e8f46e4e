#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`whitted live` in a real browser (ctest -L browser; tests/browser/README.md).

Starts `whitted live` on a copy of a lecture scene, checks that a foreign Origin and a foreign
Host get 403 (and the same request without them 200), then live_test.js opens the page in
Debian's Chromium, moves a material slider and saves the values the page sent and the PNG it
shows, clicks a pixel (explain), shows the diffuse layer, saves the edited scene as saved.yaml,
runs the check against POV-Ray, writes a bad edit to the file and saves the error the page
shows. Here, without the page: the server's EXR of those values and the page's PNG must equal
`whitted render` of the scene with the values written into the file, pixel for pixel (read with
OpenImageIO), and so must the render of saved.yaml; the page's explain must be `whitted explain
--json`'s numbers, its diffuse layer `whitted render --layers diffuse`'s, its data views'
channels `whitted render --layers N,...`'s, its verdict `whitted
check`'s, all of saved.yaml; saving over a file without "overwrite" is refused; the page's error
must be the message `whitted render` prints for the bad file; SIGTERM exits 143.

usage: live_browser.py WHITTED SOURCE_DIR WORK_DIR TOOLS_DIR
"""
import http.client
import json
import os
import shutil
import signal
import subprocess
import sys
import urllib.request

import numpy as np
import OpenImageIO as oiio
import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fail, fresh_folder, run as run_program  # noqa: E402  (tests/harness.py)
from browser_tools import CHROMIUM, chromium_env, require_tools  # noqa: E402  (beside this file)

SCENE = "examples/lecture/05-blinn-phong-p10.yaml"
DATA_LAYERS = ("N", "Ng", "P", "Z", "albedo", "objectId", "materialId", "hits")
failures = Failures()
check = failures.check


def pixels(path):
    image = oiio.ImageInput.open(path)
    if not image:
        fail(f"cannot read {path}: {oiio.geterror()}")
    data = image.read_image(0, 0, 0, image.spec().nchannels, oiio.UNKNOWN)
    image.close()
    return np.asarray(data)


def status(port, headers):
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    connection.putrequest("GET", "/state", skip_host=True)
    for name, value in headers.items():
        connection.putheader(name, value)
    connection.endheaders()
    code = connection.getresponse().status
    connection.close()
    return code


def post(port, route, body, headers=None):
    """POST a JSON body to the server (as our own page, unless `headers` says otherwise)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=180)
    connection.request("POST", route, body=json.dumps(body),
                       headers=dict({"Content-Type": "application/json", "Origin": f"http://127.0.0.1:{port}"},
                                    **(headers or {})))
    response = connection.getresponse()
    code, data = response.status, response.read()
    connection.close()
    return code, data


def main():
    whitted, source, work, tools = sys.argv[1:5]
    require_tools(tools)
    fresh_folder(work)
    shots = os.path.join(work, "screenshots")
    home = os.path.join(work, "home")
    for d in (shots, os.path.join(home, "tmp")):
        os.makedirs(d)
    scene = os.path.join(work, "scene.yaml")
    shutil.copyfile(os.path.join(source, SCENE), scene)
    original = open(scene).read()

    server = subprocess.Popen([whitted, "live", scene, "--no-open"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)
    line = server.stdout.readline().strip()
    prefix = "whitted live: http://127.0.0.1:"
    if not line.startswith(prefix):
        server.kill()
        fail(f"whitted live printed {line!r}, not its address; stderr: {server.stderr.read()}")
    address = line[len("whitted live: "):]
    port = int(line[len(prefix):].rstrip("/"))
    try:
        own = f"127.0.0.1:{port}"
        check(status(port, {"Host": own}) == 200, "GET /state with our Host: 200")
        check(status(port, {"Host": own, "Origin": f"http://{own}"}) == 200, "with our own Origin: 200")
        check(status(port, {"Host": own, "Origin": "http://evil.example"}) == 403, "Origin http://evil.example: 403")
        check(status(port, {"Host": f"evil.example:{port}"}) == 403, "Host evil.example (DNS rebinding): 403")

        env = chromium_env(home, tools)
        run = run_program(["node", os.path.join(source, "tests", "browser", "live_test.js"), address, scene, work,
                           shots, CHROMIUM], expect=None, env=env, timeout=240, stdout=None, stderr=None)
        check(run.returncode == 0, f"live_test.js in Chromium (exit {run.returncode})")
        if run.returncode != 0:
            fail("the page did not do what it should (above)")
        values = json.load(open(os.path.join(work, "values.json")))

        # The server's linear image of the same values, as EXR; its diffuse layer, as EXR and PNG;
        # the N view as PNG and each data layer's view as EXR.
        requests = [("served.exr", {"format": "exr"}), ("served-diffuse.exr", {"format": "exr", "view": "diffuse"}),
                    ("served-diffuse.png", {"format": "png", "view": "diffuse"}),
                    ("served-N.png", {"format": "png", "view": "N"})]
        requests += [(f"served-{layer}.exr", {"format": "exr", "view": layer}) for layer in DATA_LAYERS]
        requests += [("served-preview.exr", {"format": "exr", "level": "preview"})]
        for name, body in requests:
            code, data = post(port, "/render", dict({"level": "full", "values": values}, **body))
            check(code == 200, f"POST /render {body}: {code}")
            open(os.path.join(work, name), "wb").write(data)

        # Saving over an existing file without the page's "overwrite" is refused; so is a
        # save from another origin, and a file that is not YAML.
        saved = os.path.join(work, "saved.yaml")
        saved_text = open(saved).read()
        code, data = post(port, "/save", {"path": "saved.yaml", "values": values})
        check(code == 409 and open(saved).read() == saved_text,
              f"POST /save over saved.yaml without overwrite: {code} {data[:120]!r}, the file unchanged")
        code, _ = post(port, "/save", {"path": "foreign.yaml", "values": values}, {"Origin": "http://evil.example"})
        check(code == 403 and not os.path.exists(os.path.join(work, "foreign.yaml")),
              f"POST /save from Origin http://evil.example: {code}, nothing written")
        code, _ = post(port, "/save", {"path": "saved.txt", "values": values})
        check(code == 400 and not os.path.exists(os.path.join(work, "saved.txt")), f"POST /save saved.txt: {code}")
    finally:
        server.send_signal(signal.SIGTERM)
        code = server.wait(timeout=30)
    check(code == 128 + signal.SIGTERM, f"SIGTERM stops whitted live with exit {code}")

    # The values written into the file, rendered by `whitted render`.
    document = yaml.safe_load(original)
    for name, fields in values.get("materials", {}).items():
        document["materials"][name].update(fields)
    for i, light in enumerate(values.get("lights", [])):
        if light:
            document["lights"][i].update(light)
    edited = os.path.join(work, "edited.yaml")
    with open(edited, "w") as f:
        yaml.safe_dump(document, f, sort_keys=False)
    for output in ("edited.exr", "edited.png"):
        r = run_program([whitted, "render", edited, "-q", "-o", os.path.join(work, output)], expect=None)
        if r.returncode != 0:
            fail(f"whitted render {edited} -o {output} exited {r.returncode}")
    # The page's second image, full resolution at one sample per pixel: `whitted render` of the
    # edited file with samples: 1.
    document["image"]["samples"] = 1
    with open(os.path.join(work, "edited-1.yaml"), "w") as f:
        yaml.safe_dump(document, f, sort_keys=False)
    r = run_program([whitted, "render", os.path.join(work, "edited-1.yaml"), "-q", "-o",
                     os.path.join(work, "edited-1.exr")], expect=None)
    preview, rendered_1 = pixels(os.path.join(work, "served-preview.exr")), pixels(os.path.join(work, "edited-1.exr"))
    check(r.returncode == 0 and preview.shape == rendered_1.shape and np.array_equal(preview, rendered_1)
          and not np.array_equal(preview, pixels(os.path.join(work, "edited.exr"))),
          f"the preview level {preview.shape} equals `whitted render` with samples: 1 bit for bit (not the full image)")
    r = run_program([whitted, "render", scene, "-q", "-o", os.path.join(work, "original.png")], expect=None)
    if r.returncode != 0:
        fail(f"whitted render {scene} exited {r.returncode}")
    served, rendered = pixels(os.path.join(work, "served.exr")), pixels(os.path.join(work, "edited.exr"))
    check(served.dtype == np.float32 and served.shape == rendered.shape and np.array_equal(served, rendered),
          f"served EXR {served.shape} {served.dtype} equals `whitted render` of the edited file bit for bit")
    page_png, rendered_png = pixels(os.path.join(work, "page.png")), pixels(os.path.join(work, "edited.png"))
    check(page_png.shape == rendered_png.shape and np.array_equal(page_png, rendered_png),
          f"the page's PNG {page_png.shape} equals `whitted render -o edited.png` pixel for pixel")
    check(not np.array_equal(page_png, pixels(os.path.join(work, "original.png"))),
          "and differs from the render of the unedited file (the comparison can fail)")

    # After a light moved (the server rendered: its shading cache does not cover a light's
    # position) the page's PNG is `whitted render`'s of those values too.
    moved_values = json.load(open(os.path.join(work, "values-moved.json")))
    moved = yaml.safe_load(original)
    for i, light in enumerate(moved_values.get("lights", [])):
        if light:
            moved["lights"][i].update(light)
    with open(os.path.join(work, "edited-moved.yaml"), "w") as f:
        yaml.safe_dump(moved, f, sort_keys=False)
    r = run_program([whitted, "render", os.path.join(work, "edited-moved.yaml"), "-q", "-o",
                     os.path.join(work, "edited-moved.png")], expect=None)
    moved_png = pixels(os.path.join(work, "page-moved.png"))
    check(r.returncode == 0 and np.array_equal(moved_png, pixels(os.path.join(work, "edited-moved.png")))
          and not np.array_equal(moved_png, pixels(os.path.join(work, "original.png"))),
          "after the light moved, the page's PNG equals `whitted render` of those values pixel for pixel")

    # The saved file renders to the image the page showed: whitted render, bit for bit.
    saved = os.path.join(work, "saved.yaml")
    # (The page's PNG is the edited file's, above: the same EXR gives the same PNG.)
    r = run_program([whitted, "render", saved, "-q", "-o", os.path.join(work, "saved.exr")], expect=None)
    check(r.returncode == 0, f"whitted render saved.yaml -o saved.exr: exit {r.returncode}")
    check(np.array_equal(pixels(os.path.join(work, "saved.exr")), served),
          "the saved file's EXR equals the served EXR of the page's values bit for bit")

    # explain of the clicked pixel: the numbers `whitted explain --json` gives for the saved file
    # (its places in the file, `where`, and its name differ: the saved file is another file).
    explained = json.load(open(os.path.join(work, "explain.json")))
    check(explained["values"] == values, "the page explained the saved values")
    r = run_program([whitted, "explain", saved, "--pixel", f"{explained['x']},{explained['y']}", "--json"],
                    expect=None)
    check(r.returncode == 0, f"whitted explain saved.yaml: exit {r.returncode} {r.stderr}")

    def numbers(document):
        if isinstance(document, dict):
            return {k: numbers(v) for k, v in document.items() if k not in ("scene", "where")}
        if isinstance(document, list):
            return [numbers(v) for v in document]
        return document

    page_terms, cli_terms = numbers(explained["result"]), numbers(json.loads(r.stdout))
    check(page_terms == cli_terms and cli_terms["samples"][0]["segments"][0]["hit"],
          f"the page's explain of pixel ({explained['x']}, {explained['y']}) equals `whitted explain --json` "
          f"(ambient {cli_terms['layers']['ambient']}, light 1 {cli_terms['layers']['lights'][0]})")

    # The diffuse layer the page showed: `whitted render --layers diffuse`'s channels, bit for bit.
    r = run_program([whitted, "render", saved, "-q", "--layers", "diffuse", "-o", os.path.join(work, "layers.exr")],
                    expect=None)
    check(r.returncode == 0, f"whitted render --layers diffuse: exit {r.returncode}")
    layers = oiio.ImageInput.open(os.path.join(work, "layers.exr"))
    names = list(layers.spec().channelnames)
    first = names.index("diffuse.R")
    diffuse = np.asarray(layers.read_image(0, 0, first, first + 3, oiio.FLOAT))
    layers.close()
    served_diffuse = pixels(os.path.join(work, "served-diffuse.exr"))
    check(names[first:first + 3] == ["diffuse.R", "diffuse.G", "diffuse.B"] and np.array_equal(served_diffuse, diffuse),
          "the served diffuse layer equals `whitted render --layers diffuse`'s diffuse.R/G/B bit for bit")
    check(np.array_equal(pixels(os.path.join(work, "page-diffuse.png")), pixels(os.path.join(work, "served-diffuse.png"))),
          "the page showed the server's PNG of that layer")

    # The data layers as views: each served EXR holds the layer's channels exactly as `whitted
    # render --layers` writes them (bit for bit), beside the R, G, B the page shows of them.
    r = run_program([whitted, "render", saved, "-q", "--layers", ",".join(DATA_LAYERS), "-o",
                     os.path.join(work, "data-layers.exr")], expect=None)
    check(r.returncode == 0, f"whitted render --layers {','.join(DATA_LAYERS)}: exit {r.returncode}")
    rendered_data = oiio.ImageInput.open(os.path.join(work, "data-layers.exr"))
    rendered_names = list(rendered_data.spec().channelnames)
    rendered_all = np.asarray(rendered_data.read_image(0, 0, 0, len(rendered_names), oiio.FLOAT))
    rendered_data.close()
    shown_data = {}
    for layer in DATA_LAYERS:
        served = oiio.ImageInput.open(os.path.join(work, f"served-{layer}.exr"))
        served_names = list(served.spec().channelnames)
        served_all = np.asarray(served.read_image(0, 0, 0, len(served_names), oiio.FLOAT))
        served.close()
        wanted = [n for n in rendered_names if n == layer or n.startswith(layer + ".")]
        same = bool(wanted) and all(n in served_names for n in wanted) and all(
            np.array_equal(served_all[..., served_names.index(n)], rendered_all[..., rendered_names.index(n)],
                           equal_nan=True) for n in wanted)
        check(same and served_names[:3] == ["R", "G", "B"],
              f"the served {layer} view holds {wanted} equal to `whitted render --layers {layer}`'s bit for bit")
        shown_data[layer] = (served_all[..., :3], {n: rendered_all[..., rendered_names.index(n)] for n in wanted})
    shown, raw = shown_data["N"]
    n = np.stack([raw["N.X"], raw["N.Y"], raw["N.Z"]], axis=-1)
    hit = np.any(n != 0, axis=-1)
    mapped = np.where(hit[..., None], np.float32(0.5) + np.float32(0.5) * n, np.float32(0))
    check(np.array_equal(shown, mapped) and hit.any() and not hit.all(),
          "the N view shows 0.5 + 0.5·N where the ray hits, black where it misses")
    shown, raw = shown_data["Z"]
    z = raw["Z"]
    finite = np.isfinite(z)
    near, far = z[finite].min(), z[finite].max()
    check(np.allclose(shown[..., 0][finite], 0.1 + 0.9 * (far - z[finite]) / (far - near), atol=1e-6)
          and np.all(shown[~finite] == 0) and shown[..., 0][finite].max() == 1,
          f"the Z view shows 1 at the nearest hit ({near:.4g}) down to 0.1 at the farthest ({far:.4g}), misses black")
    shown, raw = shown_data["objectId"]
    ids = raw["objectId"]
    colours = {i: {tuple(c) for c in shown[ids == i]} for i in np.unique(ids)}
    check(all(len(c) == 1 for c in colours.values()) and colours.get(0.0, {(0, 0, 0)}) == {(0, 0, 0)}
          and len({next(iter(c)) for c in colours.values()}) == len(colours) > 1,
          f"the objectId view shows one colour per id, a different one for each of {len(colours)} ids, black for 0")
    check(np.array_equal(pixels(os.path.join(work, "page-N.png")), pixels(os.path.join(work, "served-N.png"))),
          "the page showed the server's PNG of the N view")

    # check: the verdict the page showed is `whitted check`'s for the saved file.
    checked = json.load(open(os.path.join(work, "check.json")))["result"]
    r = run_program([whitted, "check", saved, "-q"], expect=None)
    verdict = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else ""
    expected_figures = verdict.split(": ", 1)[-1]
    check(r.returncode in (0, 1) and verdict.startswith("PASS" if checked["passed"] else "FAIL")
          and checked["verdict"].split(": ", 1)[-1] == expected_figures and (r.returncode == 0) == checked["passed"],
          f"the page's verdict {checked['verdict']!r} is `whitted check`'s {verdict!r}")

    # The error the page showed is the one `whitted render` gives for the same file.
    shown = open(os.path.join(work, "page-error.txt")).read()
    bad = original.replace("p: 10", "p: [10", 1)
    with open(scene, "w") as f:
        f.write(bad)
    r = run_program([whitted, "render", scene, "-q", "-o", os.path.join(work, "bad.png")], expect=None)
    expected = r.stderr.strip().removeprefix("whitted: error: ")
    check(r.returncode == 2 and shown == expected, f"page error {shown!r} is render's {expected!r}")

    failures.finish("all checks passed")


if __name__ == "__main__":
    main()
