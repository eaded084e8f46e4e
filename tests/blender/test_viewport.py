#!/usr/bin/python3
"""ctest blender.viewport: the viewport's camera from a view's matrices, what a change re-does (a view
move re-renders without re-exporting), cancellation, and the pixels it draws equal `whitted render` of
the scene text it rendered (which is F12's export with the view's camera), bit for bit."""
import json, math, os, sys, tempfile
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from headless import blender, require_blender, run  # noqa: E402  (tests/blender/headless.py)
require_blender()
import OpenImageIO as oiio
out = tempfile.mkdtemp(prefix="whitted-blender-viewport-")
blender("viewport_checks.py", out)
res = json.load(open(os.path.join(out, "result.json")))


def close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


# 1. camera: eye (4,-3,2) looking at (0,0,0.5), Z up; mathutils matrices are float32: 1e-5
eye, target = [4.0, -3.0, 2.0], [0.0, 0.0, 0.5]
p = res["persp"]
assert close(p["eye"], eye, 1e-5), p
fwd = unit([t - e for t, e in zip(target, eye)])
assert close(unit([l - e for l, e in zip(p["look_at"], p["eye"])]), fwd, 1e-5), p
assert abs(sum(u * f for u, f in zip(p["up"], fwd))) < 1e-5 and p["up"][2] > 0, p  # perpendicular, Z side up
assert abs(p["fov"] - 50.0) < 1e-5, p
o = res["ortho"]
assert o["type"] == "orthographic" and abs(o["view_width"] - 7.5) < 1e-5, o
assert close(o["eye"], [e - 30.0 * f for e, f in zip(eye, fwd)], 1e-4), o  # moved back to the near plane (-30)
assert "off-centre" in res["off_centre"], res["off_centre"]
v, c = res["via_camera"], res["scene_camera"]
for k in ("eye", "look_at", "up"):
    assert close(v[k], c[k], 1e-5), (k, v, c)
assert abs(v["fov"] - c["fov"]) < 1e-5, (v, c)
# 2. what a change re-does
assert res["first_ready"] and res["first"]["exports"] == 1 and res["first"]["restarts"] == 1, res["first"]
assert [i[1] for i in res["first"]["images"]] == [False, True], res["first"]  # coarse first, then full
assert res["first"]["images"][0][2] == [12, 16, 3] and res["first"]["images"][1][2] == [48, 64, 3], res["first"]
assert res["moved_ready"] and res["moved"] == {"exports": 1, "restarts": 2}, res["moved"]  # no re-export
assert res["redrawn"] == {"exports": 1, "restarts": 2}, res["redrawn"]
assert res["selected"] == {"exports": 2, "restarts": 2}, res["selected"]  # same text: no re-render
assert res["material_ready"] and res["material"] == {"exports": 3, "restarts": 3}, res["material"]
assert res["export_equals_view"], "the viewport's scene text is not F12's export with the view's camera"
# cancellation: the superseded 1600x1200 never published; stop() ends the thread
assert res["superseded_ready"], res
assert [1200, 1600, 3] not in res["superseded_images"], res["superseded_images"]
assert not res["stopped_alive"], res
# 3. pixels: the uploaded buffer equals `whitted render` of the text the viewport rendered
run([os.environ["WHITTED"], "render", os.path.join(out, "view.json"), "-o", os.path.join(out, "cli.exr")])
cli = oiio.ImageBuf(os.path.join(out, "cli.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
drawn = np.load(os.path.join(out, "view.npy"))
assert drawn.shape == (48, 64, 4) and cli.shape == (48, 64, 3), (drawn.shape, cli.shape)
assert cli.max() > cli.min(), "flat image"
assert np.array_equal(drawn[::-1, :, :3], cli), f"{np.count_nonzero(drawn[::-1, :, :3] != cli)} values differ"
assert (drawn[:, :, 3] == 1).all()
t = res["timings_960x540"]
print("blender.viewport: camera from view matrices OK; view move: 0 exports; pixels identical to whitted render; "
      f"superseded change's full image after {res['superseded_seconds']:.3f} s; stop() {res['stop_seconds']:.3f} s; "
      "factory scene 960x540 view change -> coarse/full: " +
      ", ".join(f"{c[3]:.3f}/{f[3]:.3f} s" for c, f in t))
