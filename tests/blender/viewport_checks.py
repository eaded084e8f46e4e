# Run inside `blender -b --factory-startup --python tests/blender/viewport_checks.py -- OUTDIR`: drives the
# viewport logic (whitted_blender.viewport) with Blender's factory scene and a real depsgraph, writes
# OUTDIR/result.json, OUTDIR/view.json (the scene text the viewport rendered) and OUTDIR/view.npy
# (the float pixels it uploads to the GPU) for test_viewport.py to assert on.
import json, math, os, sys, time, types, bpy, mathutils
import numpy as np
out = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
import whitted_blender
from whitted_blender import viewport
from whitted_blender.export import scene_camera
whitted_blender.register()
sc = bpy.context.scene
sc.render.engine = 'WHITTED'
res = {}


def perspective(hfov_deg, aspect, near=0.1, far=100.0):
    """An OpenGL projection as Blender's window_matrix is: symmetric, horizontal fov."""
    p00 = 1 / math.tan(math.radians(hfov_deg) / 2)
    return mathutils.Matrix(((p00, 0, 0, 0), (0, p00 * aspect, 0, 0),
                             (0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)), (0, 0, -1, 0)))


def orthographic(width, aspect, near, far):
    return mathutils.Matrix(((2 / width, 0, 0, 0), (0, 2 * aspect / width, 0, 0),
                             (0, 0, -2 / (far - near), -(far + near) / (far - near)), (0, 0, 0, 1)))


def looking(eye, target, up_axis='Z'):
    """View matrix (world -> view) of an eye at `eye` looking at `target`, Blender's convention."""
    eye, target = mathutils.Vector(eye), mathutils.Vector(target)
    rot = (target - eye).to_track_quat('-Z', 'Y').to_matrix().to_4x4()
    return (mathutils.Matrix.Translation(eye) @ rot).inverted()


# 1. The camera derived from a region_data-like object with known matrices.
eye, target = (4.0, -3.0, 2.0), (0.0, 0.0, 0.5)
rd = types.SimpleNamespace(view_matrix=looking(eye, target), window_matrix=perspective(50.0, 16 / 9),
                           is_perspective=True)
res['persp'] = viewport.region_camera(rd)
rd_o = types.SimpleNamespace(view_matrix=looking(eye, target), window_matrix=orthographic(7.5, 4 / 3, -30.0, 30.0),
                             is_perspective=False)
res['ortho'] = viewport.region_camera(rd_o)
shifted = perspective(50.0, 1.0)
shifted[0][2] = 0.2  # an off-centre frustum (panned camera view)
try:
    viewport.view_camera(looking(eye, target), shifted, True)
    res['off_centre'] = None
except whitted_blender.MappingError as e:
    res['off_centre'] = str(e)
# Through the scene camera's own matrices (what the viewport's camera view uses): the same camera
# F12 renders with.
dg = bpy.context.evaluated_depsgraph_get()
cam = sc.camera
w, h = 64, 48
proj = cam.calc_matrix_camera(dg, x=w, y=h)
res['via_camera'] = viewport.view_camera(cam.matrix_world.inverted(), proj, True)
res['scene_camera'] = scene_camera(sc, w, h)

# 2. What a change re-does, and 3. the pixels, with the real module.
wm = whitted_blender._whitted()
s = viewport.ViewportSession(wm)
images = []
s.on_image = lambda: images.append((s.image_generation, s.image_full, s.image.shape))
s.update_scene(dg)
s.update_view(res['via_camera'], w, h)
res['first_ready'] = s.wait()
res['first'] = dict(exports=s.exports, restarts=s.restarts, images=list(images))
# A view move: new camera, no export.
rd2 = types.SimpleNamespace(view_matrix=looking((5.0, 2.0, 3.0), (0, 0, 0)), window_matrix=perspective(60.0, w / h),
                            is_perspective=True)
s.update_view(viewport.region_camera(rd2), w, h)
res['moved_ready'] = s.wait()
res['moved'] = dict(exports=s.exports, restarts=s.restarts)
# The same view drawn again (a redraw): nothing re-renders.
s.update_view(viewport.region_camera(rd2), w, h)
res['redrawn'] = dict(exports=s.exports, restarts=s.restarts)
# A depsgraph change that changes nothing Whitted renders (selection): exported, not re-rendered.
bpy.data.objects['Cube'].select_set(False)
s.update_scene(bpy.context.evaluated_depsgraph_get())
res['selected'] = dict(exports=s.exports, restarts=s.restarts)
# A material edit: re-exported and re-rendered.
mat = bpy.data.objects['Cube'].active_material
mat.node_tree.nodes['Principled BSDF'].inputs['Base Color'].default_value = (0.8, 0.1, 0.1, 1)
s.update_scene(bpy.context.evaluated_depsgraph_get())
res['material_ready'] = s.wait()
res['material'] = dict(exports=s.exports, restarts=s.restarts)
np.save(os.path.join(out, "view.npy"), viewport.display_rgba(s.image))
with open(os.path.join(out, "view.json"), "w") as f:
    f.write(s.scene_text())
# The F12 export of the same scene with the view's camera and size is the text the viewport rendered.
export = os.path.join(out, "export.json")
whitted_blender.export_render_depsgraph(sc, export)
d = json.load(open(export))
d['camera'] = viewport.region_camera(rd2)
d['image'] = dict(d['image'], width=w, height=h)
res['export_equals_view'] = whitted_blender.dumps(d) == s.scene_text()

# A newer change cancels the old render: a large render superseded after 50 ms never publishes.
images.clear()
s.update_view(res['via_camera'], 1600, 1200)
time.sleep(0.05)
t = time.monotonic()
s.update_view(viewport.region_camera(rd2), w, h)
res['superseded_ready'] = s.wait()
res['superseded_seconds'] = time.monotonic() - t
res['superseded_images'] = [list(i[2]) for i in images]
# stop() during a large render: cancelled within a progress call, the thread ends.
s.update_view(res['via_camera'], 1600, 1200)
time.sleep(0.05)
t = time.monotonic()
s.stop()
res['stop_seconds'] = time.monotonic() - t
res['stopped_alive'] = s._thread.is_alive()

# Timing: Blender's factory scene at the size the window test uses (960x540 region), a view change
# to the coarse and to the full image.
s = viewport.ViewportSession(wm)
s.update_scene(bpy.context.evaluated_depsgraph_get())
timings = []
for k in range(3):
    rd3 = types.SimpleNamespace(view_matrix=looking((6.0 + k, -5.0, 4.0), (0, 0, 0)),
                                window_matrix=perspective(55.0, 960 / 540), is_perspective=True)
    s.update_view(viewport.region_camera(rd3), 960, 540)
    assert s.wait()
    timings.append([list(e) for e in s.log if e[1] in (240, 960)][-2:])
    s.log.clear()
s.stop()
res['timings_960x540'] = timings
with open(os.path.join(out, "result.json"), "w") as f:
    json.dump(res, f, indent=1)
