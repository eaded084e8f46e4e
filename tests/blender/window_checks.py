# Run inside a windowed Blender (`xvfb-run blender --factory-startup FILE.blend --python tests/blender/window_checks.py
# -- OUTDIR`; FILE.blend the factory scene saved, so that no splash screen covers the view):
# puts the factory scene's 3D view in Rendered shading with Whitted, waits for the full image, takes a
# screenshot, then leaves Rendered shading and checks the render thread ended. Then the material
# preview: Blender renders its preview scene through the engine (is_preview) in its preview job, which
# a background Blender cannot run (it has no preview scene), hence here. Writes OUTDIR/result.json,
# OUTDIR/screen.png, OUTDIR/view.json (the scene text the viewport rendered) and per preview case
# OUTDIR/preview_CASE.json (its scene text) and .npy (the engine's float pixels and Blender's icon).
import json, os, sys, time, traceback, bpy
import numpy as np
out = sys.argv[sys.argv.index("--") + 1]
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "plugins", "blender"))
import whitted_blender
whitted_blender.register()
import gpu
sc = bpy.context.scene
sc.render.engine = 'WHITTED'
sc.view_settings.view_transform = 'Standard'
sc.view_settings.look = 'None'
sc.view_settings.exposure, sc.view_settings.gamma = 0.0, 1.0
sc.render.dither_intensity = 0.0  # the display shader's noise would hide the comparison
res = {'gl_renderer': gpu.platform.renderer_get(), 'gl_vendor': gpu.platform.vendor_get(),
       'gl_version': gpu.platform.version_get()}
window = bpy.context.window_manager.windows[0]
area = max((a for a in window.screen.areas if a.type == 'VIEW_3D'), key=lambda a: a.width * a.height)
space = area.spaces.active
space.overlay.show_overlays = False
space.show_gizmo = False
space.show_region_toolbar = False
space.show_region_ui = False
space.shading.type = 'RENDERED'
region = next(r for r in area.regions if r.type == 'WINDOW')
state = {'t0': time.monotonic(), 'phase': 'render', 'session': None, 'shot_at': None}


def finish(error=None):
    if error:
        res['error'] = error
    with open(os.path.join(out, "result.json"), "w") as f:
        json.dump(res, f, indent=1)
    bpy.ops.wm.quit_blender()
    return None


def tick():
    try:
        now = time.monotonic() - state['t0']
        if now > 120:
            return finish(f"timed out in phase {state['phase']}: sessions {len(whitted_blender.viewport_sessions)}")
        if state['phase'] == 'render':
            sessions = list(whitted_blender.viewport_sessions)
            if not sessions:
                area.tag_redraw()
                return 0.05
            s = sessions[0]
            state['session'] = s
            if s.error:
                return finish("viewport error: " + s.error)
            if not (s.image_full and s.image_generation == s._generation):
                return 0.05
            if state['shot_at'] is None:  # one more redraw so the full image is on screen
                state['shot_at'] = now
                area.tag_redraw()
                return 0.3
            res['region'] = dict(x=region.x, y=region.y, width=region.width, height=region.height)
            res['window'] = dict(width=window.width, height=window.height)
            # The header and tool header are drawn over the view (region overlap): the test masks them.
            res['others'] = [dict(type=r.type, x=r.x, y=r.y, width=r.width, height=r.height)
                             for r in area.regions if r.type != 'WINDOW' and r.width > 1 and r.height > 1]
            res['log'] = [list(e) for e in s.log]
            res['exports'], res['restarts'] = s.exports, s.restarts
            with open(os.path.join(out, "view.json"), "w") as f:
                f.write(s.scene_text())
            with bpy.context.temp_override(window=window, area=area, region=region):
                bpy.ops.screen.screenshot(filepath=os.path.join(out, "screen.png"))
            res['alive_before'] = s._thread.is_alive()
            space.shading.type = 'SOLID'  # leaves Rendered: Blender frees the engine
            area.tag_redraw()
            state['phase'] = 'solid'
            state['solid_at'] = now
            return 0.3
        if state['phase'] == 'solid':
            s = state['session']
            if s._thread.is_alive() and now - state['solid_at'] < 20:
                area.tag_redraw()
                return 0.1
            res['alive_after_solid'] = s._thread.is_alive()
            res['stopped_after_seconds'] = now - state['solid_at']
            state['phase'] = 'preview'
            return 0.05
        if state['phase'] == 'preview':
            return preview_tick(now)
    except Exception:
        return finish(traceback.format_exc())


E = whitted_blender.WhittedRenderEngine
material = bpy.data.objects['Cube'].active_material
principled = material.node_tree.nodes['Principled BSDF'].inputs
real_whitted = whitted_blender._whitted


def missing_module():
    raise whitted_blender.ModuleNotFound("Whitted: cannot import the 'whitted' Python module (test)")


# (case, what to change before the preview renders); each case's preview is a fresh icon render.
preview_cases = [
    ('red', lambda: principled['Base Color'].__setattr__('default_value', (0.8, 0.05, 0.05, 1))),
    ('blue', lambda: principled['Base Color'].__setattr__('default_value', (0.05, 0.05, 0.8, 1))),
    ('refused', lambda: principled['Metallic'].__setattr__('default_value', 1.5)),  # kd < 0
    ('missing', lambda: (principled['Metallic'].__setattr__('default_value', 0.0),
                         setattr(whitted_blender, '_whitted', missing_module))),
    ('again', lambda: setattr(whitted_blender, '_whitted', real_whitted)),
]
res['preview'] = {}


def preview_tick(now):
    """One preview case per call sequence: change, request the icon render, wait for its job."""
    p = state.setdefault('preview', {'case': 0, 'requested': None})
    if now - state['solid_at'] > 110:
        return finish(f"timed out in preview case {p['case']}")
    if p['case'] == len(preview_cases):
        return finish()
    name, change = preview_cases[p['case']]
    if p['requested'] is None:
        change()
        E.last_preview, E.last_error = None, None
        with bpy.context.temp_override(id=material):
            bpy.ops.ed.lib_id_generate_preview()
        p['requested'] = now
        return 0.05
    if bpy.app.is_job_running('RENDER_PREVIEW') or (E.last_preview is None and E.last_error is None):
        return 0.05
    icon = np.array(material.preview.image_pixels_float[:], dtype=np.float32)
    size = tuple(material.preview.image_size)
    r = {'error': E.last_error, 'icon_size': size, 'icon_max': float(icon.max()),
         'job_seconds': now - p['requested']}
    if E.last_preview is not None:
        r['seconds'], r['export_seconds'] = E.last_preview['seconds'], E.last_preview['export_seconds']
        with open(os.path.join(out, f"preview_{name}.json"), "w") as f:
            f.write(E.last_preview['text'])
        np.save(os.path.join(out, f"preview_{name}.npy"), E.last_preview['rgba'])
    np.save(os.path.join(out, f"preview_{name}_icon.npy"), icon.reshape(size[1], size[0], 4))
    res['preview'][name] = r
    p['case'] += 1
    p['requested'] = None
    return 0.05


bpy.app.timers.register(tick, first_interval=0.5)
