# SPDX-License-Identifier: MIT
"""The POV-Ray input the benchmarks time: `whitted convert`'s SDL without its inside_vector lines.

The converter gives every mesh2 an inside_vector so that POV-Ray reports all of a ray's crossings
of the mesh, which `whitted check` needs (docs/pov-model.md §3). It also makes POV-Ray search the
whole of a mesh's bounding tree for every ray, 14-25 % slower on the torus anchors. A speed
comparison must give POV-Ray its fastest correct setting, so the benchmarks time POV-Ray's default
mesh2; the images column then shows the few pixels where its nearest-crossing rule differs."""
import subprocess
from pathlib import Path


def convert_for_timing(whitted: str, scene: Path, pov: Path) -> None:
    """Writes pov (and its .ini) from scene with `whitted convert`, then drops the inside_vector lines."""
    subprocess.run([whitted, "convert", str(scene), str(pov)], check=True, stderr=subprocess.DEVNULL)
    text = pov.read_text()
    pov.write_text("".join(line for line in text.splitlines(keepends=True) if line.strip() != "inside_vector <0, 0, 1>"))
