# SPDX-License-Identifier: MIT
"""The POV-Ray input the benchmarks time: `whitted convert`'s SDL without the two additions that
make POV-Ray's answer exact but cost it time.

* The converter gives every mesh2 an inside_vector so that POV-Ray reports all of a ray's
  crossings of the mesh, which `whitted check` needs (docs/pov-model.md §3). It also makes
  POV-Ray search the whole of a mesh's bounding tree for every ray, 14-25 % slower on the torus
  anchors.
* The converter writes every box inside a union with two radius-0 spheres, so that POV-Ray's
  single-precision bounding box holds the whole box (docs/pov-model.md §3). Here each box is
  written bare again.

A speed comparison must give POV-Ray its fastest setting, so the benchmarks time POV-Ray's
default mesh2 and bare boxes. bench/run.py compares Whitted's images with POV-Ray's render of the
exact SDL (made once more, untimed); bench/scaling.py's images column shows the few pixels where
the fastest input differs."""
import re
import subprocess
from pathlib import Path

# The line that closes a box's union (converters/pov_writer.cpp, box).
BOX_UNION_TAIL = re.compile(r"^\s*sphere \{ <[^>]*>, 0 \} sphere \{ <[^>]*>, 0 \} split_union off \}\n?$")


def fastest_sdl(text: str) -> str:
    """The SDL with its inside_vector lines dropped and each box's union taken apart."""
    out = []
    for line in text.splitlines(keepends=True):
        if line.strip() == "inside_vector <0, 0, 1>" or BOX_UNION_TAIL.match(line):
            continue
        out.append(line[len("union { "):] if line.startswith("union { box {") else line)
    return "".join(out)


def convert_for_timing(whitted: str, scene: Path, pov: Path, exact_pov: Path | None = None) -> bool:
    """Writes pov (and its .ini) from scene with `whitted convert`, then makes it fastest_sdl.
    True when that changed the SDL (POV-Ray's image of it may then differ in a few pixels); the
    SDL as converted is then kept in exact_pov, where given."""
    subprocess.run([whitted, "convert", str(scene), str(pov)], check=True, stderr=subprocess.DEVNULL)
    exact = pov.read_text()
    fast = fastest_sdl(exact)
    pov.write_text(fast)
    if fast != exact and exact_pov is not None:
        exact_pov.write_text(exact)
    return fast != exact
