#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Files that are not regular files, given where a scene, mesh, MTL or course .msh file is
expected (docs/robustness.md): a character device with no end (/dev/zero, /dev/urandom), one
that is always empty (/dev/null), and a FIFO with no writer, whose plain open() would wait
forever; and links to such files. Each must be refused at once (exit 2, "not a regular file"
and the path in the message), by `render`, `convert` and `explain` alike, with no output file
written.
Usage: special_files.py WHITTED"""

import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

SCENE_HEAD = """version: 1
camera: { eye: [0, 0, 5], look_at: [0, 0, 0] }
image: { width: 8, height: 8 }
lights: [ { type: point, position: [0, 5, 5] } ]
"""
COURSE = """<?xml version="1.0" encoding="UTF-8" ?>
<scene>
  <camera><viewPoint>0 0 5</viewPoint><viewWidth>2</viewWidth><viewHeight>2</viewHeight></camera>
  <image>8 8</image>
  <shader name="green" type="Lambertian"><diffuseColor>.2 1 .3</diffuseColor></shader>
  <surface type="Mesh"><shader ref="green"/><data>{msh}</data></surface>
</scene>
"""
# Far longer than a refusal takes; a run that reaches it has hung (a FIFO opened blocking).
TIMEOUT = 20


def main():
    whitted = os.path.abspath(sys.argv[1])
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-special-") as d:
        fifo = os.path.join(d, "fifo")
        os.mkfifo(fifo)
        for name in ("scene.yaml", "scene.xml", "mesh.obj", "mesh.msh", "table.mtl"):
            os.mkfifo(os.path.join(d, "fifo-" + name))

        def write(name, text):
            path = os.path.join(d, name)
            with open(path, "w") as f:
                f.write(text)
            return path

        # (what, scene path, path the message must name). An MTL file that is not a regular file is
        # not read: its materials are undefined, which is a warning (the faces get the default
        # material), so that case renders; every other case is refused (exit 2).
        cases = [(f"scene file {dev}", dev, dev) for dev in ("/dev/zero", "/dev/urandom", "/dev/null")]
        cases += [
            ("scene file: a FIFO", fifo, fifo),
            ("scene file: a FIFO named .yaml", os.path.join(d, "fifo-scene.yaml"), "fifo-scene.yaml"),
            ("course scene file: a FIFO named .xml", os.path.join(d, "fifo-scene.xml"), "fifo-scene.xml"),
            ("OBJ mesh file: a FIFO",
             write("obj.yaml", SCENE_HEAD + "objects:\n  - { type: mesh, file: fifo-mesh.obj, material: { kd: 1 } }\n"),
             "fifo-mesh.obj"),
            ("OBJ mesh file: /dev/zero",
             write("zero.yaml", SCENE_HEAD + "objects:\n  - { type: mesh, file: /dev/zero, material: { kd: 1 } }\n"),
             "/dev/zero"),
            ("MTL file: a FIFO",
             write("mtl.yaml", SCENE_HEAD + "objects:\n  - { type: mesh, file: with_mtl.obj }\n"), "fifo-table.mtl"),
            ("course .msh file: a FIFO", write("msh.xml", COURSE.format(msh="fifo-mesh.msh")), "fifo-mesh.msh"),
            ("course .msh file: a link to /dev/urandom", write("urandom.xml", COURSE.format(msh="urandom.msh")),
             "urandom.msh"),
            ("scene file: a link to /dev/zero named .yaml", os.path.join(d, "zero-link.yaml"), "zero-link.yaml"),
        ]
        os.symlink("/dev/urandom", os.path.join(d, "urandom.msh"))
        os.symlink("/dev/zero", os.path.join(d, "zero-link.yaml"))
        write("with_mtl.obj", "mtllib fifo-table.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n")

        def expect_refused(command, what, named, env=None):
            """The command exits 2, in bounded time, saying `named` is not a regular file."""
            failures.refused(f"{command[0]}, {what}", [whitted, *command], ["not a regular file", named],
                             timeout=TIMEOUT, stdin=subprocess.DEVNULL, cwd=d, env={**os.environ, **(env or {})})

        # The OpenColorIO config: a FIFO given with --ocio-config or $OCIO is refused before OCIO
        # opens it (it would wait for a writer forever).
        ocio_scene = write("plain.yaml", SCENE_HEAD + "objects:\n  - { type: sphere, center: [0, 0, 0], radius: 1, "
                                                      "material: { kd: 1 } }\n")
        for how, args, env in [("--ocio-config", ["--ocio-config", fifo], {}),
                               ("$OCIO", [], {"OCIO": fifo})]:
            for command in (["render", ocio_scene, "-o", os.path.join(d, "ocio.png"), *args],
                            ["colour", "--list", *args]):
                expect_refused(command, f"OCIO config a FIFO by {how}", fifo, env)

        # A config whose FileTransform reads a FIFO (found on its search path) or a device: refused
        # before OpenColorIO builds a transform from it (it would wait, or read without end).
        os.makedirs(os.path.join(d, "luts"), exist_ok=True)
        os.mkfifo(os.path.join(d, "luts", "fifo.spi1d"))
        for lut in ("fifo.spi1d", "/dev/zero"):
            config = write(f"lut-{os.path.basename(lut)}.ocio", f"""ocio_profile_version: 2
search_path: luts
roles:
  default: linear
  scene_linear: linear
file_rules:
  - !<Rule> {{name: Default, colorspace: default}}
displays:
  sRGB:
    - !<View> {{name: Lut, colorspace: lut}}
colorspaces:
  - !<ColorSpace>
    name: linear
  - !<ColorSpace>
    name: lut
    from_reference: !<GroupTransform>
      children:
        - !<FileTransform> {{src: {lut}, interpolation: linear}}
""")
            for command in (["render", ocio_scene, "-o", os.path.join(d, "lut.png"), "--ocio-config", config],
                            ["colour", "--list", "--ocio-config", config]):
                expect_refused(command, f"a FileTransform from {lut}", lut)

        for what, scene, named in cases:
            for command in ("render", "convert", "explain"):
                output = os.path.join(d, "out." + ("pov" if command == "convert" else "png"))
                args = {"render": ["render", scene, "-o", output],
                        "convert": ["convert", scene, output],
                        "explain": ["explain", scene, "--pixel", "4,4"]}[command]
                start = time.monotonic()
                r = run([whitted, *args], expect=None, timeout=TIMEOUT, stdin=subprocess.DEVNULL, cwd=d)
                seconds = time.monotonic() - start
                problems = []
                warned = what.startswith("MTL file")
                if r.returncode != (0 if warned else 2):
                    problems.append(f"exit {r.returncode}, expected {0 if warned else 2}")
                if "not a regular file" not in r.stderr:
                    problems.append("no 'not a regular file' in the message")
                if named not in r.stderr:
                    problems.append(f"the message does not name {named}")
                if warned and "whitted: warning:" not in r.stderr:
                    problems.append("no warning")
                if os.path.exists(output):
                    if not warned:
                        problems.append(f"{os.path.basename(output)} was written")
                    os.unlink(output)
                for extra in [output[:-4] + ".ini"] if command == "convert" else []:
                    if os.path.exists(extra):
                        os.unlink(extra)
                failures.check(not problems, f"{command}, {what}: exit {r.returncode} in {seconds:.2f} s: "
                                             + ("; ".join(problems) + ": " if problems else "") + r.stderr.strip())
    failures.finish()


if __name__ == "__main__":
    main()
