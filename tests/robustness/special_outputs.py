#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Outputs that must never replace what is at their path (docs/robustness.md, "Outputs"):
a character device (made here with mknod, the same numbers as /dev/full and /dev/null, so a
failure replaces only this test's own node), a FIFO, and a link to a device; and an output that
is the command's own input (`convert a.yaml a.yaml`, `convert a.ini a.pov`). Each of `render`,
`convert` and `colour --write-config` must refuse at once (exit 2, the path and "not a regular
file" or "input" in the message), leave the node or file as it was, and write nothing else.
A replaced regular file keeps its mode (0600 stays 0600).
Usage: special_outputs.py WHITTED"""

import os
import stat
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

SCENE = """version: 1
camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }
image: { width: 8, height: 8 }
lights: [ { type: point, position: [0, 5, 5] } ]
objects:
  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 1 } }
"""
TIMEOUT = 60


def main():
    whitted = os.path.abspath(sys.argv[1])
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-outputs-") as d:
        scene = os.path.join(d, "scene.yaml")
        with open(scene, "w") as f:
            f.write(SCENE)
        fifo = os.path.join(d, "out.png")
        os.mkfifo(fifo)
        nodes = {"FIFO": fifo}
        if os.geteuid() == 0:
            for name, minor in (("full.png", 7), ("null.yaml", 3)):
                path = os.path.join(d, name)
                os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
                nodes[f"character device {name}"] = path
            os.symlink(os.path.join(d, "full.png"), os.path.join(d, "link.exr"))
            nodes["link to a character device"] = os.path.join(d, "link.exr")
        else:
            print("not root: device nodes cannot be made here; FIFO cases only")
        fifo_yaml, fifo_ocio = os.path.join(d, "out.yaml"), os.path.join(d, "config.ocio")
        os.mkfifo(fifo_yaml)
        os.mkfifo(fifo_ocio)
        nodes["FIFO named .yaml"] = fifo_yaml
        nodes["FIFO named .ocio"] = fifo_ocio

        def kind(path):
            return stat.S_IFMT(os.lstat(path).st_mode)

        def refused(what, command, path, says):
            before = kind(path)
            listing = sorted(os.listdir(d))
            failures.refused(what, command, [says, os.path.basename(path)], timeout=TIMEOUT)
            if kind(path) != before:
                failures.fail(f"{what}: {path} was replaced")
            if sorted(os.listdir(d)) != listing:
                failures.fail(f"{what}: files changed: {sorted(set(os.listdir(d)) ^ set(listing))}")

        for what, path in nodes.items():
            if path.endswith((".png", ".exr")):
                refused(f"render -o {what}", [whitted, "render", scene, "-o", path, "-q"], path, "not a regular file")
            if path.endswith(".yaml"):
                refused(f"convert to {what}", [whitted, "convert", scene, path], path, "not a regular file")
            refused(f"colour --write-config {what}", [whitted, "colour", "--write-config", path], path,
                    "not a regular file")

        # An output that is the command's own input.
        with open(scene) as f:
            original = f.read()
        refused("convert a.yaml a.yaml", [whitted, "convert", scene, scene], scene, "input")
        link = os.path.join(d, "same.yaml")
        os.symlink(scene, link)
        refused("convert a.yaml (a link to it)", [whitted, "convert", scene, link], link, "input")
        ini_scene = os.path.join(d, "scene.ini")
        with open(ini_scene, "w") as f:
            f.write(SCENE)
        refused("convert scene.ini scene.pov (the .ini is the input)",
                [whitted, "convert", ini_scene, os.path.join(d, "scene.pov")], ini_scene, "input")
        with open(scene) as f:
            if f.read() != original:
                failures.fail("convert a.yaml a.yaml changed its input")

        # A replaced regular file keeps its mode.
        private = os.path.join(d, "private.png")
        with open(private, "w") as f:
            f.write("old")
        os.chmod(private, 0o600)
        result = run([whitted, "render", scene, "-o", private, "-q"], expect=None, timeout=TIMEOUT)
        mode = stat.S_IMODE(os.stat(private).st_mode)
        if result.returncode != 0 or mode != 0o600:
            failures.fail(f"re-render over a 0600 file: exit {result.returncode}, mode {oct(mode)}\n{result.stderr}")

    failures.finish(f"special outputs: {len(nodes)} nodes and 3 own inputs refused, modes kept")


if __name__ == "__main__":
    main()
