# Run inside `blender -b --factory-startup --python tests/blender/install.py -- PREFIX OUTDIR`
# with the add-on copied to PREFIX/share/blender/scripts/addons/whitted_blender (see
# test_install.py). Enables it the way a user of that prefix would (Preferences > File Paths >
# Scripts = PREFIX/share/blender/scripts), renders the default scene at 64x48 and writes
# OUTDIR/result.json: where the add-on and the module came from, or the render's error.
import importlib.util, json, os, sys, bpy
prefix, out = sys.argv[sys.argv.index("--") + 1:][:2]
res = {'sys_path': [p for p in sys.path if p]}
# A machine with Whitted installed system-wide has the module on sys.path; drop those folders
# so the test sees what a machine without it sees (recorded, for the driver to print).
spec = importlib.util.find_spec("whitted")
res['dropped_from_sys_path'] = []
while spec is not None:
    folder = os.path.dirname(spec.origin if not spec.submodule_search_locations
                             else list(spec.submodule_search_locations)[0])
    sys.path[:] = [p for p in sys.path if os.path.realpath(p) != os.path.realpath(folder)]
    res['dropped_from_sys_path'].append(folder)
    importlib.invalidate_caches()
    spec = importlib.util.find_spec("whitted")
res['sys_path'] = [p for p in sys.path if p]
bpy.context.preferences.filepaths.script_directory = os.path.join(prefix, "share", "blender", "scripts")
bpy.utils.refresh_script_paths()
bpy.ops.preferences.addon_enable(module="whitted_blender")
import whitted_blender
res['addon_file'] = whitted_blender.__file__
sc = bpy.context.scene
sc.render.engine = 'WHITTED'
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 64, 48, 100
try:
    bpy.ops.render.render()
    res['error'] = None
    res['module_file'] = sys.modules['whitted'].__file__
    s = sc.render.image_settings
    s.file_format, s.color_depth = 'OPEN_EXR', '32'
    path = os.path.join(out, "render.exr")
    bpy.data.images["Render Result"].save_render(path)
    import numpy as np
    img = bpy.data.images.load(path)
    px = np.array(img.pixels[:]).reshape(-1, 4)[:, :3]
    res['min'], res['max'] = float(px.min()), float(px.max())
except RuntimeError as e:
    res['error'] = str(e)
    res['module_loaded'] = 'whitted' in sys.modules
with open(os.path.join(out, "result.json"), "w") as f:
    json.dump(res, f, indent=1)
