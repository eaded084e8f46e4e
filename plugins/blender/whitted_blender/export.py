"""Build the Whitted scene description from Blender's evaluated depsgraph (needs bpy)."""
import math

import mathutils
import numpy as np

from .mapping import (MappingError, horizontal_fov, point_intensity, principled_to_lecture,
                      reference_distance, sun_intensity)


def _matrix_rows(m):
    return [float(m[i][j]) for i in range(4) for j in range(4)]


def _first_node(owner, node_type):
    """The first node of `node_type` in a material's or world's node tree, or None without nodes."""
    if not (owner.use_nodes and owner.node_tree):
        return None
    return next((n for n in owner.node_tree.nodes if n.type == node_type), None)


def _material(mat):
    """The lecture material of a Blender material; refuses one with a negative coefficient (a
    Principled Metallic above 1 or Specular below 0, which the node sockets accept from a script
    or a driver): the lecture's terms would subtract light."""
    m = _lecture_material(mat)
    for key in ('ka', 'kd', 'ks', 'km'):
        value = m.get(key, 0.0)
        if any(c < 0 for c in (value if isinstance(value, list) else [value])):
            raise MappingError(f"Whitted: material '{mat.name}': {key} {value} has a negative component "
                               f"(Principled Metallic must be in [0, 1], Specular at least 0)")
    return m


def _lecture_material(mat):
    if mat is None:
        return {'kd': 0.8, 'ka': 0.08}
    props = getattr(mat, 'whitted', None)
    if props is not None and props.use_whitted:
        return {'ka': list(props.ka), 'kd': list(props.kd), 'ks': list(props.ks),
                'p': props.p, 'km': list(props.km), 'highlight': props.highlight.lower()}
    node = _first_node(mat, 'BSDF_PRINCIPLED')
    if node is None:
        return principled_to_lecture(mat.diffuse_color, 0.5, mat.roughness, mat.metallic)
    i = node.inputs
    return principled_to_lecture(i['Base Color'].default_value, i['Specular'].default_value,
                                 i['Roughness'].default_value, i['Metallic'].default_value)


def _mesh(obj_eval):
    """Object-space triangles of the evaluated mesh; smooth ones with per-vertex normals.

    Normals are computed here, not taken from Blender: Blender's (split or vertex) normals are
    summed in parallel and differ in the last bit from one evaluation to the next (measured:
    809-1248 of 47616 normal components of a subdivided sphere between two render-depsgraph
    evaluations), which would make export and render differ. Here: the area-weighted sum of
    the triangle normals at each vertex, accumulated in triangle order (deterministic).
    """
    me = obj_eval.to_mesh()
    try:
        me.calc_loop_triangles()
        nt = len(me.loop_triangles)
        if nt == 0:
            return None
        co = np.empty(len(me.vertices) * 3, dtype=np.float32)
        me.vertices.foreach_get('co', co)
        co = co.reshape(-1, 3).astype(np.float64)
        tri_v = np.empty(nt * 3, dtype=np.int64)
        me.loop_triangles.foreach_get('vertices', tri_v)
        tri_v = tri_v.reshape(-1, 3)
        smooth = any(p.use_smooth for p in me.polygons)
        d = {'type': 'mesh', 'vertices': co.tolist(), 'triangles': tri_v.tolist()}
        if smooth:
            p0, p1, p2 = co[tri_v[:, 0]], co[tri_v[:, 1]], co[tri_v[:, 2]]
            fn = np.cross(p1 - p0, p2 - p0)  # length = 2 * area: area weighting
            vn = np.zeros_like(co)
            for k in range(3):
                np.add.at(vn, tri_v[:, k], fn)
            length = np.linalg.norm(vn, axis=1)
            length[length == 0] = 1.0
            d['normals'] = (vn / length[:, None]).tolist()
        return d
    finally:
        obj_eval.to_mesh_clear()


def scene_camera(scene, width, height):
    """The scene's active camera in Whitted's terms (what F12 renders through)."""
    cam_obj = scene.camera
    if cam_obj is None:
        raise MappingError("Whitted: the scene has no active camera")
    cam = cam_obj.data
    if cam.shift_x != 0 or cam.shift_y != 0:
        raise MappingError("Whitted: camera lens shift is not supported (set Shift X/Y to 0)")
    mw = cam_obj.matrix_world
    eye = mw.translation
    fwd = (mw.to_3x3() @ mathutils.Vector((0, 0, -1))).normalized()
    up = (mw.to_3x3() @ mathutils.Vector((0, 1, 0))).normalized()
    camera = {'eye': list(eye), 'look_at': list(eye + fwd), 'up': list(up)}
    if cam.type == 'ORTHO':
        camera['type'] = 'orthographic'
        camera['view_width'] = cam.ortho_scale if width >= height else cam.ortho_scale * width / height
    elif cam.type == 'PERSP':
        camera['fov'] = horizontal_fov(cam.lens, cam.sensor_width, cam.sensor_height,
                                       cam.sensor_fit, width, height)
    else:
        raise MappingError("Whitted: panoramic cameras are not supported")
    return camera


# Blender's preview scene (the Material Properties' Preview panel and the material icons) hides its
# floor from camera rays with this material when the engine has ray visibility (Cycles' trick, so
# the floor shows only in reflections). Whitted has no per-ray visibility: the floor is left out.
PREVIEW_HIDDEN_FLOOR = 'FloorHidden'


def describe(depsgraph, camera=None, size=None, preview=False):
    """The scene description of `depsgraph`. By default through the scene's camera at the render
    resolution (F12); the viewport passes its own camera dict and (width, height) instead.
    `preview`: Blender's material preview scene (docs/blender.md, Material preview): its area
    lights become point lights at their centres and its camera-hidden floor is left out."""
    scene = depsgraph.scene
    r = scene.render
    if size is None:
        width = int(r.resolution_x * r.resolution_percentage / 100)
        height = int(r.resolution_y * r.resolution_percentage / 100)
    else:
        width, height = size
    if camera is None:
        camera = scene_camera(scene, width, height)
    props = scene.whitted
    world = scene.world
    bg = [0.0, 0.0, 0.0]
    if world is not None:
        bg = [float(c) for c in world.color]
        # With nodes (the default World), what the UI shows is the Background node's Color x
        # Strength, not world.color (the viewport colour).
        node = _first_node(world, 'BACKGROUND')
        if node is not None:
            strength = float(node.inputs['Strength'].default_value)
            bg = [float(c) * strength for c in node.inputs['Color'].default_value[:3]]
    desc = {'version': 1, 'camera': camera,
            'image': {'width': width, 'height': height, 'samples': props.samples, 'background': bg},
            'render': {'max_depth': props.max_depth}, 'ambient': list(props.ambient),
            'lights': [], 'materials': {}, 'prototypes': {}, 'objects': []}
    lights = []
    box_lo = [math.inf] * 3
    box_hi = [-math.inf] * 3
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type == 'LIGHT':
            # After the loop: a point light's exposure needs the bounds of all the geometry.
            lights.append((ob, inst.matrix_world.copy()))
        elif ob.type in {'MESH', 'CURVE', 'SURFACE', 'META', 'FONT'}:
            if preview and ob.active_material and ob.active_material.name == PREVIEW_HIDDEN_FLOOR:
                continue
            # Prototype key: the evaluated mesh. Objects without modifiers that share a mesh
            # datablock (linked duplicates, collection instances of one object) evaluate to
            # the same mesh; an object with modifiers has a mesh of its own.
            orig = ob.original
            if orig.modifiers or ob.data is None:
                name = 'object:' + orig.name
            else:
                name = 'mesh:' + orig.data.name
            if name not in desc['prototypes']:
                m = _mesh(ob)
                if m is None:
                    continue
                desc['prototypes'][name] = m
            mat = ob.active_material
            mname = mat.name if mat else '__default'
            desc['materials'].setdefault(mname, _material(mat))
            desc['objects'].append({'type': 'instance', 'prototype': name, 'material': mname,
                                    'transform': {'matrix': _matrix_rows(inst.matrix_world)}})
            for corner in ob.bound_box:
                p = inst.matrix_world @ mathutils.Vector(corner)
                for k in range(3):
                    box_lo[k] = min(box_lo[k], p[k])
                    box_hi[k] = max(box_hi[k], p[k])
    box = (box_lo, box_hi) if box_lo[0] <= box_hi[0] else None
    for ob, matrix in lights:
        desc['lights'].append(_light(ob, matrix, box, preview))
    return desc


def _light(ob, matrix, box, preview=False):
    """A Blender light in Whitted's terms: the intensity that gives a Lambertian surface the
    radiance Cycles/EEVEE give it (mapping.point_intensity, sun_intensity), unless the light's
    Whitted "Override intensity" gives it directly. In the preview scene (lit by two area lights)
    an area light is a point light of the same power at its centre."""
    light = ob.data
    lp = light.whitted
    if light.type == 'POINT' or (preview and light.type == 'AREA'):
        position = list(matrix.translation)
        intensity = list(lp.intensity) if lp.use_intensity else \
            point_intensity(light.energy, light.color, reference_distance(position, box))
        return {'type': 'point', 'position': position, 'intensity': intensity}
    if light.type == 'SUN':
        d = matrix.to_3x3() @ mathutils.Vector((0, 0, -1))
        intensity = list(lp.intensity) if lp.use_intensity else sun_intensity(light.energy, light.color)
        return {'type': 'directional', 'direction': list(d), 'intensity': intensity}
    raise MappingError(f"Whitted: light '{ob.name}' of type {light.type} is not supported")
