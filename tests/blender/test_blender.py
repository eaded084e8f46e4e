#!/usr/bin/python3
"""ctest blender.render: the add-on's render equals `whitted render` of the EXPORTED file bit for bit;
instances and prototypes are keyed by evaluated mesh."""
import json, os, sys, tempfile
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from headless import blender, require_blender, run  # noqa: E402  (tests/blender/headless.py)
require_blender()
import OpenImageIO as oiio
out = tempfile.mkdtemp(prefix="whitted-blender-")
blender("scene.py", out)
exported = os.path.join(out, "export.json")
run([os.environ["WHITTED"], "render", exported, "-o", os.path.join(out, "cli.exr")])
a = oiio.ImageBuf(os.path.join(out, "blender.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
b = oiio.ImageBuf(os.path.join(out, "cli.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
assert a.shape == (48, 64, 3) and b.shape == a.shape, (a.shape, b.shape)
assert b.max() > b.min(), "image is flat: nothing rendered"
assert np.array_equal(a, b), f"{np.count_nonzero(a != b)} values differ"
# the exported text is the rendered text, byte for byte (same render depsgraph path)
assert open(exported).read() == open(os.path.join(out, "rendered.json")).read(), "export != rendered text"
d = json.load(open(exported))
facts = json.load(open(os.path.join(out, "facts.json")))
assert facts["is_instance_meshes"] == 2, facts  # the collection instance's two monkeys
protos = d["prototypes"]
objs = d["objects"]
# monkey + 2 linked duplicates + 2 collection-instance monkeys: one prototype, 5 placements
monkey_keys = [k for k in protos if k.startswith("mesh:Suzanne")]
assert len(monkey_keys) == 1, sorted(protos)
assert sum(o["prototype"] == monkey_keys[0] for o in objs) == 5, [o["prototype"] for o in objs]
# subdivided sphere (render levels 2) and its plain twin sharing the mesh: two prototypes
sub, plain = protos["object:Sphere"], protos["mesh:Sphere"]
# render levels 2 give about 16x the triangles, viewport level 1 about 4x: > 8x means render
assert len(sub["triangles"]) > 8 * len(plain["triangles"]), (len(sub["triangles"]), len(plain["triangles"]))
print(f"blender.render: identical to whitted render of the exported file; prototypes {sorted(protos)}; "
      f"sphere triangles subdivided {len(sub['triangles'])} vs plain {len(plain['triangles'])}")
