#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Inputs truncated by another program while `whitted render` (and `whitted check`) reads them (docs/robustness.md,
"Files that change while they are read"): a 1M-triangle OBJ (read by several threads at once)
and a YAML scene of 300,000 spheres are cut to 1000 bytes at moments spread over the read.
Every run must end with exit 0 (the cut came after the read), or exit 1 saying the file
"changed while it was read" and naming it, or exit 2 naming it (the cut came before the open:
the 1000 bytes are a broken file) -- never a signal (SIGBUS, exit 135, was what a cut did).
`whitted check` must give the same exit 1 for a change (it gave 2, as for bad input).
The cut must land inside the read at least once per file, or the test proves nothing: the
moments are spread over the read time measured here first.
Usage: truncated_inputs.py WHITTED"""

import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures  # noqa: E402  (tests/harness.py)

ATTEMPTS = 24  # per file, at most; stops after HITS_WANTED cuts inside the read
HITS_WANTED = 3


def write_obj(path, side=708):
    """A grid of side x side quads (about 1M triangles)."""
    lines = [f"v {i % side} {i // side} {((i * 7919) % 13) * 0.01:.2f}\n" for i in range(side * side)]
    for y in range(side - 1):
        for x in range(side - 1):
            a = y * side + x + 1
            lines.append(f"f {a} {a + 1} {a + side + 1}\nf {a} {a + side + 1} {a + side}\n")
    with open(path, "w") as f:
        f.writelines(lines)


def write_yaml(path, spheres=300000):
    with open(path, "w") as f:
        f.write("version: 1\ncamera: { eye: [0, 0, 900], look_at: [0, 0, 0] }\nimage: { width: 16, height: 16 }\n"
                "lights: [ { type: point, position: [0, 5, 900] } ]\nmaterials:\n  m: { kd: 0.5 }\nobjects:\n")
        f.writelines(f"  - {{ type: sphere, center: [{i % 700}.5, {i // 700}.25, -{i % 97}], radius: 0.25, "
                     f"material: m }}\n" for i in range(spheres))


def main():
    whitted = os.path.abspath(sys.argv[1])
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-truncated-") as d:
        obj_master, yaml_master = os.path.join(d, "master.obj"), os.path.join(d, "master.yaml")
        write_obj(obj_master)
        write_yaml(yaml_master)
        mesh_scene = os.path.join(d, "mesh_scene.yaml")
        with open(mesh_scene, "w") as f:
            f.write("version: 1\ncamera: { eye: [350, 350, 900], look_at: [350, 350, 0] }\n"
                    "image: { width: 16, height: 16 }\nlights: [ { type: point, position: [0, 5, 900] } ]\n"
                    "objects:\n  - { type: mesh, file: big.obj, material: { kd: 0.5 } }\n")
        render = lambda scene: [whitted, "render", scene, "-o", os.path.join(d, "out.exr"), "-q"]
        # check reads the scene as render does; POV-Ray is a stand-in that fails (exit 2 after the
        # read): only the read is under test, and a change found there is exit 1 as for render.
        check = lambda scene: [whitted, "check", scene, "-q"]
        cases = [("OBJ mesh", obj_master, os.path.join(d, "big.obj"), mesh_scene, render, HITS_WANTED),
                 ("YAML scene", yaml_master, os.path.join(d, "big.yaml"), os.path.join(d, "big.yaml"), render,
                  HITS_WANTED),
                 ("YAML scene under check", yaml_master, os.path.join(d, "big.yaml"), os.path.join(d, "big.yaml"),
                  check, 1)]
        env = dict(os.environ, WHITTED_POVRAY="/bin/false")
        for what, master, victim, scene, command, hits_wanted in cases:
            shutil.copyfile(master, victim)
            start = time.monotonic()
            # Under check POV-Ray cannot run: the exit status of the whole check is not the point.
            whole = failures.run(command(scene), expect=None if command is check else 0, timeout=300, env=env)
            seconds = time.monotonic() - start
            if command is not check and whole.returncode != 0:
                continue
            hits, outcomes = 0, []
            for attempt in range(ATTEMPTS):
                if hits >= hits_wanted:
                    break
                shutil.copyfile(master, victim)
                # Early in the run: the read comes first (on a loaded machine the whole run was 5.5 s
                # and the OBJ was read within its first 0.9 s).
                # Denser near the start, where the read is however fast the machine: from 0.2 % to
                # 42 % of the whole run, the steps growing quadratically, in a shuffled order.
                step = (attempt * 7) % ATTEMPTS
                delay = seconds * (0.002 + 0.42 * (step / ATTEMPTS) ** 2)
                process = subprocess.Popen(command(scene), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                           env=env)
                time.sleep(delay)
                os.truncate(victim, 1000)
                try:
                    _, stderr = process.communicate(timeout=300)
                except subprocess.TimeoutExpired:
                    process.kill()
                    failures.fail(f"{what}: cut after {delay:.3f} s: hung")
                    continue
                rc = process.returncode
                outcomes.append(f"{delay:.3f}s->{rc}")
                name = os.path.basename(victim)
                if rc < 0 or rc > 128:
                    failures.fail(f"{what}: cut after {delay:.3f} s: killed by a signal (exit {rc})\n{stderr}")
                elif rc == 1:
                    if "changed while it was read" not in stderr or name not in stderr:
                        failures.fail(f"{what}: cut after {delay:.3f} s: exit 1 without naming the change and "
                                        f"'{name}': {stderr!r}")
                    hits += 1
                elif "changed while it was read" in stderr:
                    failures.fail(f"{what}: cut after {delay:.3f} s: exit {rc} for a file that changed while it "
                                    f"was read; expected 1 (a failure, not bad input): {stderr!r}")
                elif rc == 2 and command is check and "POV-Ray" in stderr:
                    pass  # the cut came after the read: the stand-in POV-Ray failed
                elif rc == 2:
                    if name not in stderr:
                        failures.fail(f"{what}: cut after {delay:.3f} s: exit 2 without naming '{name}': {stderr!r}")
                elif rc != 0:
                    failures.fail(f"{what}: cut after {delay:.3f} s: exit {rc}\n{stderr}")
            print(f"{what}: whole run {seconds:.3f} s; cuts: {' '.join(outcomes)}; {hits} inside the read")
            if hits == 0:
                failures.fail(f"{what}: no cut landed inside the read in {len(outcomes)} attempts")
    failures.finish()


if __name__ == "__main__":
    main()
