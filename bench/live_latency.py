#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The response time of `whitted live` (issue 36's target: a slider move shown at full
resolution within 100 ms at 640x480 on two cores). Starts `whitted live` on a lecture scene,
moves a material slider N times in Debian's Chromium (bench/live_latency.js, playwright-core as
in tests/browser) and prints, per move and as median and worst, the time from the slider's input
event to each image shown (coarse; full resolution at 1 sample per pixel; the full image),
and the full image's split: the server's render,
its encode (the PNG written and read back), how many full images the server shaded again
from its cache of the last render's hits (a kd move: all but none), the rest of its answer (the file parsed, the scene
and its BVH built), the request's round trip beyond the server's time, and the browser's decode. The load
average before and after is printed: the machine may be shared.

usage: live_latency.py WHITTED TOOLS_DIR [--moves N] [--scene FILE] [--threads T]
  TOOLS_DIR holds node_modules/playwright-core (scripts/setup --with-test-tools: build/browser-tools)
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHROMIUM = os.environ.get("WHITTED_CHROMIUM", "/usr/bin/chromium")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("tools")
    parser.add_argument("--moves", type=int, default=20)
    parser.add_argument("--scene", default=os.path.join(HERE, "..", "examples", "lecture", "05-blinn-phong-p10.yaml"))
    parser.add_argument("--threads", type=int, default=0)
    args = parser.parse_args()
    for needed, hint in ((CHROMIUM, "apt-get install chromium"), (shutil.which("node") or "/nonexistent/node",
                                                                  "apt-get install nodejs"),
                         (os.path.join(args.tools, "node_modules", "playwright-core", "package.json"),
                          "scripts/setup --with-test-tools")):
        if not os.path.exists(needed):
            sys.exit(f"live_latency: {needed} is missing ({hint})")
    with tempfile.TemporaryDirectory(prefix="whitted-live-latency-") as work:
        scene = os.path.join(work, "scene.yaml")
        shutil.copyfile(args.scene, scene)
        command = [args.whitted, "live", scene, "--no-open"] + (["-t", str(args.threads)] if args.threads else [])
        server = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        address = server.stdout.readline().strip().removeprefix("whitted live: ")
        if not address.startswith("http://127.0.0.1:"):
            server.kill()
            sys.exit(f"live_latency: whitted live printed no address: {server.stderr.read()}")
        load_before = os.getloadavg()
        out = os.path.join(work, "samples.json")
        try:
            run = subprocess.run(["node", os.path.join(HERE, "live_latency.js"), address, str(args.moves), CHROMIUM, out],
                                 env=dict(os.environ, NODE_PATH=os.path.join(os.path.abspath(args.tools), "node_modules"),
                                          HOME=work, XDG_CONFIG_HOME=os.path.join(work, ".config"),
                                          XDG_CACHE_HOME=os.path.join(work, ".cache")), timeout=600)
        finally:
            server.terminate()
            server.wait(timeout=30)
        load_after = os.getloadavg()
        if run.returncode != 0:
            sys.exit(f"live_latency: live_latency.js exited {run.returncode}")
        samples = json.load(open(out))
    print(f"whitted live, {os.path.relpath(args.scene)}: {len(samples)} slider moves "
          f"(load average {load_before[0]:.2f} before, {load_after[0]:.2f} after; {os.cpu_count()} cores)")
    columns = (("input→coarse shown", "coarseShownSinceInput"),
               ("input→1-sample full res", "previewShownSinceInput"), ("input→full shown", "fullShownSinceInput"),
               ("coarse: server", "coarseServer"), ("1-sample: render", "previewRender"), ("full: render", "fullRender"), ("full: encode", "fullEncode"),
               ("full: rest (±1, whole ms)", None), ("round trip beyond server", None), ("decode+show", "fullDecode"))

    def value(sample, key, name):
        # (An older page's timings lack some of these: a build before the shading cache, say.)
        # The server's headers are whole milliseconds each, so the rest of its answer (the file
        # parsed, the scene and its BVH built) is known to ±1 ms and may show as -1.
        if name.startswith("full: rest"):
            parts = [sample.get(k) for k in ("fullServer", "fullRender", "fullEncode")]
            return None if None in parts else parts[0] - parts[1] - parts[2]
        if name == "round trip beyond server":
            parts = [sample.get(k) for k in ("fullRoundTrip", "fullServer")]
            return None if None in parts else parts[0] - parts[1]
        return sample.get(key)

    print(f"{'ms':>26} {'median':>8} {'min':>8} {'worst':>8}")
    for name, key in columns:
        values = [v for v in (value(s, key, name) for s in samples) if v is not None]
        if values:
            print(f"{name:>26} {statistics.median(values):8.1f} {min(values):8.1f} {max(values):8.1f}"
                  + (f"  ({len(values)} of {len(samples)})" if len(values) < len(samples) else ""))
    print(f"full image: {samples[-1].get('bytes')} bytes of PNG; shaded again from the last render's hits "
          f"(the server's shading cache) in {sum(1 for s in samples if s.get('reshaded'))} of {len(samples)} moves")
    for what, key in (("the 1-sample full-resolution image", "previewShownSinceInput"),
                      ("the full image (`whitted render`'s)", "fullShownSinceInput")):
        values = [s[key] for s in samples if s.get(key) is not None]
        if not values:
            continue
        median = statistics.median(values)
        print(f"target 100 ms, {what}: {'met' if median <= 100 else 'not met'} (median {median:.0f} ms)")


if __name__ == "__main__":
    main()
