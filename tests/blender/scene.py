# Run inside `blender -b --factory-startup --python tests/blender/scene.py -- OUTDIR`:
# builds a scene by script, renders it through the add-on, saves the raw float result as EXR,
# the scene text the engine rendered, and exports via File > Export's operator.
import json, os, sys, bpy
out = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
import whitted_blender
whitted_blender.register()
sc = bpy.context.scene
sc.render.engine = 'WHITTED'
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 64, 48, 100
sc.view_settings.view_transform = 'Standard'
bpy.ops.mesh.primitive_uv_sphere_add(location=(2, 0, 0))
bpy.ops.object.shade_smooth()
sphere = bpy.context.object
m = sphere.modifiers.new("subdivision", "SUBSURF")
m.levels, m.render_levels = 1, 2  # why: viewport and render differ -> export must use render
# A second object sharing the sphere's mesh, with no modifier: must not share its prototype.
plain = sphere.copy(); plain.modifiers.clear(); plain.location = (2, 2.5, 0)
sc.collection.objects.link(plain)
bpy.ops.mesh.primitive_monkey_add(location=(-2, 0, 1), size=0.7)
monkey = bpy.context.object
for k in range(2):  # linked duplicates: share the mesh datablock -> one prototype
    dup = monkey.copy(); dup.location = (-2 + k * 1.2, -2, 1); sc.collection.objects.link(dup)
# A collection instance of monkeys: they come through object_instances with is_instance.
troop = bpy.data.collections.new("troop")
for k in range(2):
    t = monkey.copy(); t.location = (k * 1.0, 0, 0); troop.objects.link(t)
empty = bpy.data.objects.new("troop_instance", None)
empty.instance_type, empty.instance_collection = 'COLLECTION', troop
empty.location = (0, 2, 0.5)
sc.collection.objects.link(empty)
bpy.ops.mesh.primitive_plane_add(size=12, location=(0, 0, -1))
mirror = bpy.data.materials.new("mirror"); mirror.whitted.use_whitted = True
mirror.whitted.km = (0.5, 0.5, 0.5); bpy.context.object.data.materials.append(mirror)
bpy.ops.object.light_add(type='SUN')
bpy.ops.object.light_add(type='POINT', location=(3, 3, 3))
bpy.context.view_layer.update()
n_instances = sum(1 for i in bpy.context.evaluated_depsgraph_get().object_instances
                  if i.is_instance and i.object.type == 'MESH')
bpy.ops.render.render()
s = sc.render.image_settings
s.file_format, s.color_depth, s.exr_codec = 'OPEN_EXR', '32', 'ZIP'
bpy.data.images["Render Result"].save_render(os.path.join(out, "blender.exr"))
with open(os.path.join(out, "rendered.json"), "w") as f:
    f.write(whitted_blender.WhittedRenderEngine.last_scene_text)
bpy.ops.export_scene.whitted(filepath=os.path.join(out, "export.json"))
with open(os.path.join(out, "facts.json"), "w") as f:
    json.dump({"is_instance_meshes": n_instances}, f)
