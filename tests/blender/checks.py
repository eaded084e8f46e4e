# Run inside `blender -b --factory-startup --python tests/blender/checks.py -- MODE OUTDIR`,
# MODE one of errors, cancel, check_pov. Writes OUTDIR/result.json for the driver to assert on.
import json, math, os, sys, time, bpy
mode, out = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
import whitted_blender
from whitted_blender import WhittedRenderEngine as E
whitted_blender.register()
sc = bpy.context.scene
sc.render.engine = 'WHITTED'
sc.render.resolution_percentage = 100
sc.view_settings.view_transform = 'Standard'
res = {}

def export_error(path):
    try:
        bpy.ops.export_scene.whitted(filepath=path)
    except RuntimeError as e:
        return str(e)
    return None

if mode == 'errors':
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    path = os.path.join(out, "keep.json")
    with open(path, "w") as f:
        f.write("old")
    cam = sc.camera
    cam.data.shift_x = 0.1
    res['shift'] = export_error(path)
    cam.data.shift_x = 0.0
    sc.camera = None
    res['no_camera'] = export_error(path)
    try:  # Blender itself refuses before the engine runs
        bpy.ops.render.render()
        res['render_no_camera'] = None
    except RuntimeError as e:
        res['render_no_camera'] = str(e)
    res['kept'] = open(path).read()
    res['part_left'] = os.path.exists(path + ".part")
    sc.camera = cam
    cam.data.type = 'ORTHO'
    cam.data.ortho_scale = 5.0
    e = os.path.join(out, "ortho.json")
    bpy.ops.export_scene.whitted(filepath=e)
    res['ortho_landscape'] = json.load(open(e))['camera']
    sc.render.resolution_x, sc.render.resolution_y = 48, 64
    bpy.ops.export_scene.whitted(filepath=e)
    res['ortho_portrait'] = json.load(open(e))['camera']
    cam.data.type = 'PERSP'
    cam.data.lens, cam.data.sensor_width, cam.data.sensor_fit = 50, 36, 'AUTO'
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    bpy.ops.export_scene.whitted(filepath=e)
    res['persp'] = json.load(open(e))['camera']
    bgn = sc.world.node_tree.nodes['Background']
    bgn.inputs['Color'].default_value = (0.25, 0.5, 0.75, 1.0)
    bgn.inputs['Strength'].default_value = 2.0
    bpy.ops.export_scene.whitted(filepath=e)
    res['background'] = json.load(open(e))['image']['background']
elif mode == 'cancel':
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
    bpy.ops.object.light_add(type='POINT', location=(3, 3, 3))
    sc.render.resolution_x, sc.render.resolution_y = 1600, 1200
    sc.whitted.samples = 4
    calls = {'break': 0}
    def should_break(self):
        calls['break'] += 1
        return calls['break'] > 1  # True from the second progress call on: the first ran
    E.should_break = should_break
    t = time.monotonic()
    bpy.ops.render.render()
    res['cancel_seconds'] = time.monotonic() - t
    res['cancelled'] = E.last_cancelled
    res['calls'] = calls
    # the same render uncancelled, at 1 sample and a quarter of the pixels, for scale
    E.should_break = lambda self: False
    sc.render.resolution_x, sc.render.resolution_y = 800, 600
    sc.whitted.samples = 1
    t = time.monotonic()
    bpy.ops.render.render()
    res['full_sixteenth_seconds'] = time.monotonic() - t
    res['cancelled_after_full'] = E.last_cancelled
elif mode == 'check_pov':
    bpy.ops.object.delete()  # the default cube: keep the scene small
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, location=(0, 0, 0))
    bpy.ops.object.light_add(type='POINT', location=(4, -4, 6))
    sc.render.resolution_x, sc.render.resolution_y = 64, 48
    passed, verdict, path, report = whitted_blender.check_pov(bpy.context)
    res.update(passed=passed, verdict=verdict, path=path, exists=os.path.exists(path),
               report=report, report_files=sorted(os.listdir(report)) if os.path.isdir(report) else None,
               note=sc.render.stamp_note_text, use_stamp_note=sc.render.use_stamp_note)
with open(os.path.join(out, "result.json"), "w") as f:
    json.dump(res, f, indent=1)
