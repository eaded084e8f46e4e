# Run inside `blender -b --factory-startup --python tests/blender/checks.py -- MODE OUTDIR`,
# MODE one of errors, cancel, check_pov, exposure. Writes OUTDIR/result.json for the driver to assert on.
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
elif mode == 'exposure':
    import numpy as np

    def render(engine, name):
        """Render the scene with `engine`; the float result (rows from the top), straight from
        a 32-bit EXR (no view transform: Standard, and EXR is scene-referred)."""
        sc.render.engine = engine
        t = time.monotonic()
        bpy.ops.render.render()
        res[name + '_seconds'] = time.monotonic() - t
        s = sc.render.image_settings
        s.file_format, s.color_depth = 'OPEN_EXR', '32'
        path = os.path.join(out, name + '.exr')
        bpy.data.images["Render Result"].save_render(path)
        img = bpy.data.images.load(path)
        return np.array(img.pixels[:]).reshape(img.size[1], img.size[0], 4)[::-1]

    def cube_stats(name):
        """The factory scene at 10 % (192x108): Cycles (16 samples, no denoiser, transparent film
        so its alpha marks the cube) and Whitted; the mean of the cube's pixels in each."""
        c = render('CYCLES', name + '_cycles')
        w = render('WHITTED', name + '_whitted')
        cube = c[:, :, 3] > 0.999
        res[name] = dict(pixels=int(cube.sum()), cycles_mean=float(c[cube][:, :3].mean()),
                         whitted_mean=float(w[cube][:, :3].mean()),
                         clipped=float((w[cube][:, :3] >= 1.0).any(axis=1).mean()),
                         lights=json.loads(E.last_scene_text)['lights'])

    sc.render.resolution_percentage = 10
    sc.render.film_transparent = True
    sc.cycles.samples, sc.cycles.use_denoising, sc.cycles.seed = 16, False, 0
    cube_stats('factory')
    # Direct light only: no World light in Cycles, no ambient in Whitted
    background = sc.world.node_tree.nodes['Background'].inputs['Strength']
    background.default_value = 0.0
    sc.whitted.ambient = (0.0, 0.0, 0.0)
    cube_stats('direct')
    res['light'] = dict(location=list(bpy.data.objects['Light'].location), energy=bpy.data.lights['Light'].energy)
    # The derivation's premise: a white Lambertian plane (Diffuse BSDF; Whitted kd 1) seen head
    # on, a point light of P W at d straight above, then a sun of strength S straight down.
    bpy.data.objects.remove(bpy.data.objects['Cube'])
    bpy.data.objects.remove(bpy.data.objects['Light'])
    bpy.ops.mesh.primitive_plane_add(size=2)
    m = bpy.data.materials.new("lambert")
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.remove(nodes['Principled BSDF'])
    diffuse = nodes.new('ShaderNodeBsdfDiffuse')
    diffuse.inputs['Color'].default_value = (1, 1, 1, 1)
    m.node_tree.links.new(diffuse.outputs[0], nodes['Material Output'].inputs['Surface'])
    m.whitted.use_whitted = True
    m.whitted.ka, m.whitted.kd, m.whitted.ks = (0, 0, 0), (1, 1, 1), (0, 0, 0)
    bpy.context.object.data.materials.append(m)
    cam = sc.camera
    cam.location, cam.rotation_euler = (0, 0, 5), (0, 0, 0)
    cam.data.type, cam.data.ortho_scale = 'ORTHO', 0.1
    sc.render.resolution_x = sc.render.resolution_y = 16
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    for kind, energy in (('POINT', 100.0), ('SUN', 2.0)):
        bpy.ops.object.light_add(type=kind, location=(0, 0, 2))
        light = bpy.context.object
        light.data.energy = energy
        if kind == 'POINT':
            light.data.shadow_soft_size = 0.0
        else:
            light.data.angle = 0.0
        res['plane_' + kind] = dict(
            energy=energy, height=2.0,
            cycles=float(render('CYCLES', 'plane_cycles')[:, :, :3].mean()),
            whitted=float(render('WHITTED', 'plane_whitted')[:, :, :3].mean()),
            intensity=json.loads(E.last_scene_text)['lights'][0]['intensity'])
        bpy.data.objects.remove(light)
with open(os.path.join(out, "result.json"), "w") as f:
    json.dump(res, f, indent=1)
