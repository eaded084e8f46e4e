#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`whitted live` in a real browser (ctest -L browser; tests/browser/README.md).

Starts `whitted live` on a copy of a lecture scene, checks that a foreign Origin and a foreign
Host get 403 (and the same request without them 200), then live_test.js opens the page in
Debian's Chromium, moves a material slider and saves the values the page sent and the PNG it
shows, writes a bad edit to the file and saves the error the page shows. Here, without the
page: the server's EXR of those values and the page's PNG must equal `whitted render` of the
scene with the values written into the file, pixel for pixel (read with OpenImageIO); the
page's error must be the message `whitted render` prints for the bad file; SIGTERM exits 143.

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

SCENE = "examples/lecture/05-blinn-phong-p10.yaml"
CHROMIUM = os.environ.get("WHITTED_CHROMIUM", "/usr/bin/chromium")
problems = []


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def check(ok, message):
    print(("ok    " if ok else "FAIL  ") + message)
    if not ok:
        problems.append(message)


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


def main():
    whitted, source, work, tools = sys.argv[1:5]
    missing = []
    if not os.access(CHROMIUM, os.X_OK):
        missing.append(f"{CHROMIUM} is missing: apt-get install chromium (scripts/setup --with-test-tools does)")
    if not shutil.which("node"):
        missing.append("node is missing: apt-get install nodejs (scripts/setup --with-test-tools does)")
    if not os.path.isfile(os.path.join(tools, "node_modules", "playwright-core", "package.json")):
        missing.append(f"playwright-core is not installed in {tools}: scripts/setup --with-test-tools runs npm ci")
    if missing:
        fail("the browser tests need Chromium, node and playwright-core:\n  " + "\n  ".join(missing))
    shutil.rmtree(work, ignore_errors=True)
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

        env = dict(os.environ, HOME=home, XDG_CONFIG_HOME=os.path.join(home, ".config"),
                   XDG_CACHE_HOME=os.path.join(home, ".cache"), XDG_DATA_HOME=os.path.join(home, ".local/share"),
                   TMPDIR=os.path.join(home, "tmp"), NODE_PATH=os.path.join(tools, "node_modules"))
        run = subprocess.run(["node", os.path.join(source, "tests", "browser", "live_test.js"), address, scene, work,
                              shots, CHROMIUM], env=env, timeout=240)
        check(run.returncode == 0, f"live_test.js in Chromium (exit {run.returncode})")
        if run.returncode != 0:
            fail("the page did not do what it should (above)")
        values = json.load(open(os.path.join(work, "values.json")))

        # The server's linear image of the same values, as EXR.
        request = urllib.request.Request(address + "render", method="POST",
                                         data=json.dumps({"level": "full", "format": "exr",
                                                          "values": values}).encode(),
                                         headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(request, timeout=120) as response:
            open(os.path.join(work, "served.exr"), "wb").write(response.read())
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
        r = subprocess.run([whitted, "render", edited, "-q", "-o", os.path.join(work, output)])
        if r.returncode != 0:
            fail(f"whitted render {edited} -o {output} exited {r.returncode}")
    r = subprocess.run([whitted, "render", scene, "-q", "-o", os.path.join(work, "original.png")])
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

    # The error the page showed is the one `whitted render` gives for the same file.
    shown = open(os.path.join(work, "page-error.txt")).read()
    bad = original.replace("p: 10", "p: [10", 1)
    with open(scene, "w") as f:
        f.write(bad)
    r = subprocess.run([whitted, "render", scene, "-q", "-o", os.path.join(work, "bad.png")], capture_output=True,
                       text=True)
    expected = r.stderr.strip().removeprefix("whitted: error: ")
    check(r.returncode == 2 and shown == expected, f"page error {shown!r} is render's {expected!r}")

    if problems:
        print(f"{len(problems)} problem(s)")
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
