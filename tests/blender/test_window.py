#!/usr/bin/python3
"""ctest blender.window: a real Blender window under Xvfb (Mesa's software OpenGL): the factory scene's 3D
view in Rendered shading with Whitted; its pixels on screen equal `whitted render` of the scene text the
viewport rendered, through the Standard view transform (sRGB), within 8-bit display quantisation; leaving
Rendered shading ends the render thread. Then the material preview (the icon Blender renders through the
engine from its preview scene): the engine's pixels equal `whitted render` of the preview scene text bit
for bit, Blender's icon equals them through the sRGB curve within its dither, the material's colour is
at the sphere's centre and follows an edit; a refused material and a missing module give an error and
no crash. Fails (does not skip) without Xvfb or a GL context.
Usage: test_window.py [SCREENSHOT_COPY [PREVIEW_COPY]]"""
import json, os, shutil, sys, tempfile
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from headless import fail, require_blender, run  # noqa: E402  (tests/blender/headless.py)
require_blender()
if shutil.which("xvfb-run") is None or shutil.which("Xvfb") is None:
    fail("xvfb-run/Xvfb not installed (apt-get install xvfb xauth): the window test cannot run")
import OpenImageIO as oiio
here = os.path.dirname(os.path.abspath(__file__))
out = tempfile.mkdtemp(prefix="whitted-blender-window-")
start = os.path.join(out, "start.blend")  # opening a file: no splash screen over the view
run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python-expr",
     f"import bpy; bpy.ops.wm.save_as_mainfile(filepath={start!r})"])
r = run(["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", "blender", "--factory-startup", start,
         "--python-exit-code", "1", "--python", os.path.join(here, "window_checks.py"), "--", out], expect=None, timeout=240)
result = os.path.join(out, "result.json")
if r.returncode != 0 or not os.path.exists(result):
    print(r.stdout[-3000:], r.stderr[-3000:])
    fail(f"windowed Blender exited {r.returncode} without a result (no X display or GL context?)")
res = json.load(open(result))
assert "error" not in res, res["error"]
assert res["gl_renderer"], res
run([os.environ["WHITTED"], "render", os.path.join(out, "view.json"), "-o", os.path.join(out, "cli.exr")])
screen = oiio.ImageBuf(os.path.join(out, "screen.png")).get_pixels(oiio.UINT8)[:, :, :3].astype(int)
rg = res["region"]
assert screen.shape[:2] == (res["window"]["height"], res["window"]["width"]), (screen.shape, res["window"])
H = screen.shape[0]
top = H - (rg["y"] + rg["height"])  # window coordinates count from the bottom; image rows from the top
view = screen[top:top + rg["height"], rg["x"]:rg["x"] + rg["width"]]
linear = oiio.ImageBuf(os.path.join(out, "cli.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
assert linear.shape == view.shape, (linear.shape, view.shape)
assert linear.max() > linear.min(), "flat image"
c = np.clip(linear, 0.0, 1.0)  # Standard: the sRGB curve, clipped
expect = np.rint(255 * np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)).astype(int)
mask = np.ones(view.shape[:2], bool)
mask[[0, -1], :] = False  # the area's 1-pixel border is drawn over the region's edge
# ... and at the left and right edges the arrows that reopen the hidden toolbar and sidebar
mask[:, :16] = mask[:, -16:] = False
for o in res["others"]:  # headers drawn over the view (region overlap)
    y0, y1 = max(o["y"], rg["y"]), min(o["y"] + o["height"], rg["y"] + rg["height"])
    x0, x1 = max(o["x"], rg["x"]), min(o["x"] + o["width"], rg["x"] + rg["width"])
    if y0 < y1 and x0 < x1:
        mask[rg["y"] + rg["height"] - y1:rg["y"] + rg["height"] - y0, x0 - rg["x"]:x1 - rg["x"]] = False
d = np.abs(view - expect).max(axis=2)[mask]
within = (d <= 2).mean()
no_cm = np.abs(view - np.rint(255 * c).astype(int)).max(axis=2)[mask]
if not (within >= 0.999 and d.max() <= 4):
    bad = np.argwhere((np.abs(view - expect).max(axis=2) > 4) & mask)
    fail(f"{100 * within:.3f}% within 2 codes, max {d.max()}; {len(bad)} pixels > 4, first (row, col) "
             f"{bad[:5].tolist()} of the view")
assert (no_cm > 8).mean() > 0.5, "the drawn pixels look linear: the display transform was not applied"
assert res["alive_before"] and not res["alive_after_solid"], res
if len(sys.argv) > 1:
    shutil.copyfile(os.path.join(out, "screen.png"), sys.argv[1])


def srgb_codes(linear):
    c = np.clip(linear, 0.0, 1.0)  # Standard: the sRGB curve, clipped
    return np.rint(255 * np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)).astype(int)


# The material preview. Blender's rows start at the bottom; whitted render's at the top.
pv = res["preview"]
assert list(pv) == ["red", "blue", "refused", "missing", "again"], pv
centre = {}
for name in ("red", "blue", "again"):
    p = pv[name]
    assert p["error"] is None, (name, p)
    run([os.environ["WHITTED"], "render", os.path.join(out, f"preview_{name}.json"), "-o", os.path.join(out, f"preview_{name}.exr")])
    cli = oiio.ImageBuf(os.path.join(out, f"preview_{name}.exr")).get_pixels(oiio.FLOAT)[:, :, :3]
    engine = np.load(os.path.join(out, f"preview_{name}.npy"))
    icon = np.load(os.path.join(out, f"preview_{name}_icon.npy"))
    assert engine.shape[:2] == cli.shape[:2] == icon.shape[:2] == tuple(p["icon_size"][::-1]), (engine.shape, cli.shape, icon.shape)
    assert np.array_equal(engine[::-1, :, :3], cli), f"{name}: {np.count_nonzero(engine[::-1, :, :3] != cli)} values differ"
    background = json.load(open(os.path.join(out, f"preview_{name}.json")))["image"]["background"]
    assert (np.abs(cli - background).max(axis=2) > 0.01).mean() > 0.2, f"{name}: the preview is mostly background"
    codes = np.abs(np.rint(255 * icon[:, :, :3]).astype(int) - srgb_codes(engine[:, :, :3])).max(axis=2)
    p["icon_within_2"], p["icon_max_diff"] = float((codes <= 2).mean()), int(codes.max())
    assert p["icon_within_2"] >= 0.999 and p["icon_max_diff"] <= 4, (name, p)
    h, w = cli.shape[:2]
    centre[name] = cli[h // 2, w // 2]
red, blue = centre["red"], centre["blue"]
assert red[0] > 2 * max(red[1], red[2]) and blue[2] > 2 * max(blue[0], blue[1]), centre  # the material's colour
assert np.array_equal(centre["again"], blue), centre  # after the errors, the same preview again
for name, words in (("refused", "negative component"), ("missing", "cannot import")):
    p = pv[name]
    assert p["error"] and words in p["error"] and "Traceback" not in p["error"], (name, p)
    # transparent, not the previous material's preview left in place
    assert p["icon_max"] == 0.0, (name, p)
if len(sys.argv) > 2:
    icon = np.load(os.path.join(out, "preview_red_icon.npy"))[::-1]
    buf = oiio.ImageBuf(oiio.ImageSpec(icon.shape[1], icon.shape[0], 4, oiio.UINT8))
    buf.set_pixels(oiio.ROI(), np.rint(255 * icon).astype(np.uint8))
    assert buf.write(sys.argv[2]), buf.geterror()
coarse = next(e for e in res["log"] if e[0] == "coarse")
full = next(e for e in res["log"] if e[0] == "full")
print(f"blender.window: {res['gl_renderer']}; view {rg['width']}x{rg['height']}: {100 * within:.3f}% of "
      f"{d.size} pixels within 2 codes of whitted render + sRGB, max {d.max()}; coarse {coarse[1]}x{coarse[2]} "
      f"after {coarse[3]:.3f} s, full after {full[3]:.3f} s; thread ended {res['stopped_after_seconds']:.2f} s "
      f"after leaving Rendered; material preview {pv['red']['icon_size'][0]}x{pv['red']['icon_size'][1]}: "
      f"identical to whitted render, icon within {max(pv[k]['icon_max_diff'] for k in ('red', 'blue', 'again'))} "
      "codes of it + sRGB; engine export/total " +
      ", ".join(f"{pv[k]['export_seconds']:.2f}/{pv[k]['seconds']:.2f} s" for k in ("red", "blue", "again")) +
      "; Blender's job " + ", ".join(f"{pv[k]['job_seconds']:.2f}" for k in pv) + " s; refused material and "
      "missing module: error, transparent icon")
