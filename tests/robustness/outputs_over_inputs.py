#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Outputs that would replace an input, a link, or go where nothing can be written
(docs/robustness.md, "Outputs never replace anything but a regular file"). Each must be refused
before any work, exit 2, with a message naming the path, and leave every file as it was:
  * `check --report r` where the scene is r/metrics.json, r/scene.pov or r/ours.exr;
  * `convert s.yaml mesh.pov` where mesh.pov is the scene's OBJ mesh, and `convert s.yaml
    out.pov` where the OBJ says `mtllib out.ini` (convert writes the .pov and the .ini);
  * `render s.yaml -o mtl.png` where the OBJ says `mtllib mtl.png`, and the same through a hard
    link to that MTL file;
  * `render -o`, `convert` and `colour --write-config` to a symlink to /proc/self/fd/1 while
    standard output is a regular file (the file and the link stay as they were);
  * `convert` into an immutable directory (chattr +i, root only): refused at once, not after
    reading a large mesh.
Usage: outputs_over_inputs.py WHITTED"""

import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

SCENE = """version: 1
camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }
image: { width: 8, height: 8 }
lights: [ { type: point, position: [0, 5, 5] } ]
objects:
  - { type: sphere, center: [0, 0, 0], radius: 1, material: { kd: 1 } }
"""
MESH_SCENE = """version: 1
camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }
image: { width: 8, height: 8 }
lights: [ { type: point, position: [0, 5, 5] } ]
objects:
  - { type: mesh, file: MESH }
"""
OBJ = "mtllib MTL\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
MTL = "newmtl red\nKd 1 0 0\n"
TIMEOUT = 60


def snapshot(d):
    """Every entry under d: its kind and, for files, bytes and mode."""
    state = {}
    for root, dirs, files in os.walk(d):
        for name in dirs + files:
            path = os.path.join(root, name)
            info = os.lstat(path)
            content = open(path, "rb").read() if stat.S_ISREG(info.st_mode) else os.readlink(path) if stat.S_ISLNK(
                info.st_mode) else None
            state[os.path.relpath(path, d)] = (stat.S_IFMT(info.st_mode), stat.S_IMODE(info.st_mode), content)
    return state


def main():
    whitted = os.path.abspath(sys.argv[1])
    failures = Failures()
    env = dict(os.environ, WHITTED_POVRAY="/bin/false")  # POV-Ray must never be reached

    def refused(what, command, cwd, says, names, stdout=subprocess.PIPE, watch=None):
        before = snapshot(watch or cwd)
        failures.refused(what, command, [says] + names, timeout=TIMEOUT, cwd=cwd, stdout=stdout, env=env)
        after = snapshot(watch or cwd)
        if after != before:
            changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
            failures.fail(f"{what}: files changed: {changed}")

    with tempfile.TemporaryDirectory(prefix="whitted-own-outputs-") as d:
        # check: the scene is one of the report's files.
        for name in ["metrics.json", "scene.pov", "ours.exr"]:
            report = os.path.join(d, "rep-" + name.replace(".", "-"))
            os.mkdir(report)
            with open(os.path.join(report, name), "w") as f:
                f.write(SCENE)
            refused(f"check {name} --report (the scene is the report's {name})",
                    [whitted, "check", "-q", os.path.join(report, name), "--report", report], d,
                    "an input of the same check", [name])

        # convert: the mesh, or its MTL, is one of the outputs.
        work = os.path.join(d, "convert")
        os.mkdir(work)
        with open(os.path.join(work, "mesh.pov"), "w") as f:
            f.write(OBJ.replace("MTL", "red.mtl"))
        with open(os.path.join(work, "red.mtl"), "w") as f:
            f.write(MTL)
        with open(os.path.join(work, "s2.yaml"), "w") as f:
            f.write(MESH_SCENE.replace("MESH", "mesh.pov"))
        refused("convert s2.yaml mesh.pov (the OBJ mesh)", [whitted, "convert", "s2.yaml", "mesh.pov"], work,
                "an input of the same command", ["mesh.pov", "mesh file"])
        with open(os.path.join(work, "m.obj"), "w") as f:
            f.write(OBJ.replace("MTL", "out.ini"))
        with open(os.path.join(work, "out.ini"), "w") as f:
            f.write(MTL)
        with open(os.path.join(work, "s3.yaml"), "w") as f:
            f.write(MESH_SCENE.replace("MESH", "m.obj"))
        refused("convert s3.yaml out.pov (mtllib out.ini)", [whitted, "convert", "s3.yaml", "out.pov"], work,
                "an input of the same command", ["out.ini", "MTL file"])

        # render: the image is the MTL file an OBJ of the scene names, by its name or another
        # (a hard link): refused once the scene is read, before the BVH is built.
        with open(os.path.join(work, "mtl.png"), "w") as f:
            f.write(MTL)
        os.link(os.path.join(work, "mtl.png"), os.path.join(work, "hard.png"))
        with open(os.path.join(work, "m5.obj"), "w") as f:
            f.write(OBJ.replace("MTL", "mtl.png"))
        with open(os.path.join(work, "s5.yaml"), "w") as f:
            f.write(MESH_SCENE.replace("MESH", "m5.obj"))
        for image in ["mtl.png", "hard.png"]:
            refused(f"render s5.yaml -o {image} (mtllib mtl.png)", [whitted, "render", "s5.yaml", "-o", image, "-q"],
                    work, "MTL file", [image, "mtl.png"])

        # A symlink to /proc/self/fd/1, standard output a regular file.
        links = os.path.join(d, "links")
        os.mkdir(links)
        with open(os.path.join(links, "s.yaml"), "w") as f:
            f.write(SCENE)
        for name in ["o.exr", "o.pov", "o.ocio"]:
            os.symlink("/proc/self/fd/1", os.path.join(links, name))
        stdout_path = os.path.join(d, "stdout.txt")
        for what, command, name in [("render -o", [whitted, "render", "s.yaml", "-o", "o.exr", "-q"], "o.exr"),
                                    ("convert", [whitted, "convert", "s.yaml", "o.pov"], "o.pov"),
                                    ("colour --write-config", [whitted, "colour", "--write-config", "o.ocio"],
                                     "o.ocio")]:
            with open(stdout_path, "w") as out:
                out.write("stdout stays\n")
            with open(stdout_path, "a") as out:
                refused(f"{what} a link to /proc/self/fd/1", command, links, "symbolic link", [name], stdout=out)
            if open(stdout_path).read() != "stdout stays\n":
                failures.fail(f"{what} a link to /proc/self/fd/1: the standard output file was written")

        # convert into an immutable directory: refused before the mesh is read.
        with open(os.path.join(work, "g.obj"), "w") as f:
            f.write(OBJ.replace("mtllib MTL\n", ""))
        with open(os.path.join(work, "s4.yaml"), "w") as f:
            f.write(MESH_SCENE.replace("MESH", "g.obj"))
        locked = os.path.join(d, "locked")
        os.mkdir(locked)
        lock = run(["chattr", "+i", locked], expect=None)
        if lock.returncode != 0:
            print(f"SKIP immutable directory: chattr +i failed ({lock.stderr.strip()})")
        else:
            try:
                start = time.monotonic()
                refused("convert into an immutable directory",
                        [whitted, "convert", "s4.yaml", os.path.join(locked, "x.pov")], work,
                        "cannot create a file in directory", ["x.pov"])
                print(f"immutable directory: refused in {time.monotonic() - start:.3f} s")
            finally:
                run(["chattr", "-i", locked])

        # A re-render over a set-user-ID file: the new image keeps the permissions, not the bit.
        scene = os.path.join(links, "s.yaml")
        setuid = os.path.join(d, "setuid.exr")
        with open(setuid, "w") as f:
            f.write("old")
        os.chmod(setuid, 0o4755)
        result = run([whitted, "render", scene, "-o", setuid, "-q"], expect=None, timeout=TIMEOUT)
        mode = stat.S_IMODE(os.stat(setuid).st_mode)
        if result.returncode != 0 or mode != 0o755:
            failures.fail(f"re-render over a 4755 file: exit {result.returncode}, mode {oct(mode)}, expected "
                            f"0o755\n{result.stderr}")

    failures.finish("outputs over inputs: all refused")


if __name__ == "__main__":
    main()
