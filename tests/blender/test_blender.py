#!/usr/bin/python3
"""ctest blender.render: the add-on's render equals `whitted render` of the scene text bit for bit."""
import os, shutil, subprocess, sys, tempfile
import numpy as np
if shutil.which("blender") is None:
    print("SKIPPED: blender is not installed (apt-get install blender)"); sys.exit(77)
import OpenImageIO as oiio
here = os.path.dirname(os.path.abspath(__file__))
out = tempfile.mkdtemp(prefix="whitted-blender-")
r = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1",
                    "--python", os.path.join(here, "scene.py"), "--", out], capture_output=True, text=True)
if r.returncode != 0:
    print(r.stdout[-3000:], r.stderr[-3000:]); sys.exit(1)
subprocess.run([os.environ["WHITTED"], "render", os.path.join(out, "rendered.json"), "-o",
                os.path.join(out, "cli.exr")], check=True)
a = oiio.ImageBuf(os.path.join(out, "blender.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
b = oiio.ImageBuf(os.path.join(out, "cli.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
assert a.shape == (48, 64, 3) and b.shape == a.shape, (a.shape, b.shape)
assert b.max() > b.min(), "image is flat: nothing rendered"
assert np.array_equal(a, b), f"{np.count_nonzero(a != b)} values differ"
print("blender.render: identical to whitted render of the rendered scene text")
