"""Whitted as a Blender render engine (docs/blender.md)."""
bl_info = {
    "name": "Whitted renderer",
    "author": "Whitted",
    "version": (0, 2, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > Whitted",
    "description": "Renders with the lecture's Whitted model; checks against POV-Ray",
    "category": "Render",
}

import os
import sys
import tempfile
import time
import weakref

import bpy
import numpy as np

from .locate import ModuleNotFound, import_whitted
from .mapping import MappingError, dumps
from .viewport import ViewportSession, display_rgba, region_camera

# Every viewport session the engine started (weak: a freed engine's stopped session goes away);
# for tests and scripts that measure or wait on the viewport.
viewport_sessions = weakref.WeakSet()


def _whitted():
    """The `whitted` module (locate.py: WHITTED_PYTHONPATH, sys.path, then near the add-on);
    raises locate.ModuleNotFound naming every folder searched."""
    return import_whitted(__file__)


def scene_text(depsgraph, preview=False):
    from .export import describe
    return dumps(describe(depsgraph, preview=preview))


class WhittedSceneProps(bpy.types.PropertyGroup):
    samples: bpy.props.IntProperty(name="Samples", default=1, min=1, max=64)
    max_depth: bpy.props.IntProperty(name="Max depth", default=5, min=1, max=256)
    ambient: bpy.props.FloatVectorProperty(name="Ambient Ia", subtype='COLOR', default=(0.1, 0.1, 0.1), min=0)
    threads: bpy.props.IntProperty(name="Threads", default=0, min=0)


class WhittedMaterialProps(bpy.types.PropertyGroup):
    use_whitted: bpy.props.BoolProperty(name="Use these", default=False)
    ka: bpy.props.FloatVectorProperty(name="ka", subtype='COLOR', default=(0.05, 0.05, 0.05), min=0)
    kd: bpy.props.FloatVectorProperty(name="kd", subtype='COLOR', default=(0.5, 0.5, 0.5), min=0)
    ks: bpy.props.FloatVectorProperty(name="ks", subtype='COLOR', default=(0.3, 0.3, 0.3), min=0)
    p: bpy.props.FloatProperty(name="p", default=50.0, min=1e-3)
    km: bpy.props.FloatVectorProperty(name="km", subtype='COLOR', default=(0, 0, 0), min=0)
    highlight: bpy.props.EnumProperty(name="Highlight", items=[('BLINN', "Blinn-Phong", ""), ('PHONG', "Phong", "")])


class WhittedLightProps(bpy.types.PropertyGroup):
    use_intensity: bpy.props.BoolProperty(name="Override intensity", default=False)
    intensity: bpy.props.FloatVectorProperty(name="Intensity", subtype='COLOR', default=(1, 1, 1), min=0)


class WhittedRenderEngine(bpy.types.RenderEngine):
    bl_idname = "WHITTED"
    bl_label = "Whitted"
    # Blender calls render() on its preview scene (is_preview) for the material preview and the
    # material, light and world icons (docs/blender.md, Material preview).
    bl_use_preview = True

    # Set by the export operator: render() then writes the scene text there and renders
    # nothing. Why: Python cannot make a depsgraph evaluated for render itself, and a
    # viewport one differs (modifier levels, last-bit vertex differences), so export goes
    # through the very path render uses.
    export_path = None
    last_scene_text = None
    last_error = None
    last_cancelled = False
    # The last preview render: {'text', 'rgba' (Blender's row order), 'seconds'}; kept apart from
    # last_scene_text so that previews re-rendered on every material edit never replace F12's.
    last_preview = None

    def __init__(self):
        super().__init__()
        self._whitted_session = None   # the viewport's ViewportSession (Rendered shading only)
        self._whitted_texture = None   # ((generation, full), GPUTexture) last uploaded

    def should_break(self):
        """Blender's Esc/cancel; a plain Python method so a test can replace it (RNA methods
        such as test_break cannot be overridden from Python, and a background Blender never
        breaks by itself)."""
        return self.test_break()

    def _fail(self, message, depsgraph=None):
        WhittedRenderEngine.last_error = message
        self.report({'ERROR'}, message)
        if depsgraph is not None and self.is_preview:
            # Blender keeps the last preview's pixels for the next one: without a result of its
            # own, a refused material would show the previous material's preview. Transparent.
            r = depsgraph.scene.render
            width = int(r.resolution_x * r.resolution_percentage / 100)
            height = int(r.resolution_y * r.resolution_percentage / 100)
            result = self.begin_result(0, 0, width, height)
            result.layers[0].passes["Combined"].rect = np.zeros((width * height, 4), dtype=np.float32)
            self.end_result(result)

    def render(self, depsgraph):
        # A preview runs in Blender's preview job thread, possibly while an export waits on the
        # main thread: it never writes the export file nor replaces the F12 scene text.
        preview = self.is_preview
        started = time.monotonic()
        WhittedRenderEngine.last_error = None
        try:
            text = scene_text(depsgraph, preview=preview)
            if not preview:
                # Kept so a test (or a user) can compare with `whitted render` of exactly this text.
                WhittedRenderEngine.last_scene_text = text
                if WhittedRenderEngine.export_path is not None:
                    with open(WhittedRenderEngine.export_path, "w") as f:
                        f.write(text)
                    return
            wm = _whitted()
            scene = wm.loads(text, "<blender>.json")
        except (MappingError, ModuleNotFound) as e:  # messages that say "Whitted: ..." already
            self._fail(str(e), depsgraph)
            return
        except Exception as e:  # whitted.Error: a message, not a traceback
            self._fail(f"Whitted: {e}", depsgraph)
            return
        exported = time.monotonic()
        width, height = scene.width, scene.height
        WhittedRenderEngine.last_cancelled = False

        def progress(done, total):
            self.update_progress(done / total if total else 1.0)
            if self.should_break():
                raise KeyboardInterrupt("cancelled")

        result = self.begin_result(0, 0, width, height)
        try:
            img = wm.render(scene, threads=depsgraph.scene.whitted.threads, progress=progress)
        except KeyboardInterrupt:
            WhittedRenderEngine.last_cancelled = True
            self.report({'WARNING'}, "Whitted: render cancelled")
            self.end_result(result, cancel=True)
            return
        except Exception as e:
            self._fail(f"Whitted: {e}")
            self.end_result(result, cancel=True)
            return
        rgba = np.ones((height, width, 4), dtype=np.float32)
        rgba[:, :, :3] = img[::-1]  # Blender's rows start at the bottom
        result.layers[0].passes["Combined"].rect = rgba.reshape(-1, 4)
        self.end_result(result)
        if preview:
            WhittedRenderEngine.last_preview = {'text': text, 'rgba': rgba, 'export_seconds': exported - started,
                                                'seconds': time.monotonic() - started}

    # -- Rendered shading in the 3D viewport (viewport.py) --------------------------------------
    def _viewport(self, depsgraph):
        s = self._whitted_session
        if s is None:
            s = ViewportSession(_whitted(), threads=depsgraph.scene.whitted.threads)
            s.dirty = False

            def on_image():  # worker thread: only flag; the main thread's timer redraws
                s.dirty = True
            s.on_image = on_image
            bpy.app.timers.register(lambda: _redraw_when_ready(s), first_interval=0.01)
            self._whitted_session = s
            viewport_sessions.add(s)
        return s

    def view_update(self, context, depsgraph):
        try:
            s = self._viewport(depsgraph)
        except ModuleNotFound as e:
            self.update_stats("", str(e).split("\n")[0])
            return
        s.update_scene(depsgraph)

    def view_draw(self, context, depsgraph):
        s = self._whitted_session
        if s is None:
            return
        region = context.region
        try:
            s.update_view(region_camera(context.region_data), region.width, region.height)
        except MappingError as e:
            s._fail(str(e))
        if s.error is not None:
            self.update_stats("", s.error)
            return
        image, generation, full = s.image, s.image_generation, s.image_full
        if image is None:
            return
        self.update_stats("", "Whitted: " + ("done" if full and generation == s._generation else "rendering"))
        import gpu
        from gpu_extras.presets import draw_texture_2d
        key = (generation, full)
        if self._whitted_texture is None or self._whitted_texture[0] != key:
            h, w = image.shape[:2]
            buf = gpu.types.Buffer('FLOAT', w * h * 4, display_rgba(image).ravel())
            self._whitted_texture = (key, gpu.types.GPUTexture((w, h), format='RGBA32F', data=buf))
        gpu.state.blend_set('ALPHA_PREMULT')
        # Blender's view transform, look, exposure and display device apply to the linear pixels.
        self.bind_display_space_shader(depsgraph.scene)
        draw_texture_2d(self._whitted_texture[1], (0, 0), region.width, region.height)
        self.unbind_display_space_shader()
        gpu.state.blend_set('NONE')

    def __del__(self):
        # The viewport left Rendered mode (or the engine is freed): cancel and end the worker.
        try:
            s = self._whitted_session
        except Exception:  # the RNA side is gone already
            return
        if s is not None:
            s.stop()


def _redraw_when_ready(session):
    """A main-thread timer per viewport session: redraw the 3D views in Rendered shading when the
    worker has a better image. Why not engine.tag_redraw() from the worker: the engine may be
    freed while a render runs, and the worker must not hold it (its __del__ stops the worker)."""
    if session._stopped:
        return None
    rendered = [area for window in bpy.context.window_manager.windows for area in window.screen.areas
                if area.type == 'VIEW_3D' and area.spaces.active.shading.type == 'RENDERED']
    if not rendered:
        # No view in Rendered shading: stop now. Blender frees the engine (whose __del__ stops the
        # session too) only when Python collects it, measured up to 11 s later.
        session.stop(wait=False)
        return None
    if session.dirty:
        session.dirty = False
        for area in rendered:
            area.tag_redraw()
    return 0.01


def export_render_depsgraph(scene, filepath):
    """Write the scene text the engine would render to `filepath` (see export_path).

    Runs a render with the engine switched to export mode; writes to a temp file first so a
    failed export never clobbers an existing file. Raises MappingError with the engine's reason.
    """
    tmp = filepath + ".part"
    old_engine = scene.render.engine
    WhittedRenderEngine.export_path = tmp
    WhittedRenderEngine.last_scene_text = None
    WhittedRenderEngine.last_error = None
    try:
        scene.render.engine = 'WHITTED'
        try:
            bpy.ops.render.render(scene=scene.name)
        except RuntimeError as e:  # Blender's refusal (no camera) or the engine's report
            if os.path.exists(tmp):
                os.remove(tmp)
            raise MappingError(str(e).removeprefix("Error: ").strip()) from None
    finally:
        WhittedRenderEngine.export_path = None
        scene.render.engine = old_engine
    if WhittedRenderEngine.last_scene_text is None or not os.path.exists(tmp):
        if os.path.exists(tmp):
            os.remove(tmp)
        raise MappingError(WhittedRenderEngine.last_error or "Whitted: export failed")
    os.replace(tmp, filepath)


class EXPORT_SCENE_OT_whitted(bpy.types.Operator):
    bl_idname = "export_scene.whitted"
    bl_label = "Export Whitted scene"
    filepath: bpy.props.StringProperty(subtype='FILE_PATH')

    def execute(self, context):
        try:
            export_render_depsgraph(context.scene, self.filepath)
        except MappingError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        return {'FINISHED'}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}


def check_pov(context=None):
    """Export (render depsgraph) to a temp dir and run whitted.check (Whitted vs POV-Ray).

    Returns (passed, verdict, scene_path, report_dir); the verdict and figures go into the
    render stamp note (scene.render.stamp_note_text).
    """
    context = context or bpy.context
    d = tempfile.mkdtemp(prefix="whitted-check-")
    path = os.path.join(d, "scene.json")
    report = os.path.join(d, "report")
    export_render_depsgraph(context.scene, path)
    res = _whitted().check(path, threads=context.scene.whitted.threads, report_dir=report)
    note = (f"whitted check: {'PASS' if res.passed else 'FAIL'}; "
            f"{100 * res.fraction_within:.3f}% of pixels within tolerance, "
            f"max error {res.max_error_codes:g} codes, PSNR {res.psnr:.1f} dB; report {report}")
    context.scene.render.use_stamp_note = True
    context.scene.render.stamp_note_text = note
    return res.passed, res.verdict, path, report


class WHITTED_OT_check_pov(bpy.types.Operator):
    bl_idname = "whitted.check_pov"
    bl_label = "Check against POV-Ray"

    def execute(self, context):
        try:
            passed, verdict, path, report = check_pov(context)
        except (ModuleNotFound, MappingError) as e:  # their messages say "Whitted: ..." already
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        except Exception as e:
            self.report({'ERROR'}, f"Whitted: {e}")
            return {'CANCELLED'}
        self.report({'INFO'} if passed else {'WARNING'}, f"{verdict} — report {report}")
        return {'FINISHED'}


class WhittedPanel:
    """What every Whitted properties panel shares (a mixin, as Blender's own add-ons write it)."""
    bl_label = "Whitted"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    COMPAT_ENGINES = {"WHITTED"}


class WHITTED_PT_material(WhittedPanel, bpy.types.Panel):
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.material is not None and context.engine == "WHITTED"

    def draw(self, context):
        p = context.material.whitted
        self.layout.prop(p, "use_whitted")
        for k in ("ka", "kd", "ks", "p", "km", "highlight"):
            self.layout.prop(p, k)


def draw_module_status(layout):
    """Where the `whitted` module was found or, when it was not, every folder searched and what
    to do (the same text F12 reports), one label per line: Blender's labels do not wrap."""
    try:
        m = _whitted()
    except ModuleNotFound as e:
        box = layout.box()
        for i, line in enumerate(str(e).split("\n")):
            if line.startswith("Looked in ") and ": " in line:
                what, folders = line.split(": ", 1)
                box.label(text=what + ":")
                for f in folders.rstrip(".").split(", "):
                    box.label(text="    " + f)
            else:
                box.label(text=line, icon='ERROR' if i == 0 else 'NONE')
        return False
    layout.label(text=f"whitted module: {getattr(m, '__file__', m.__name__)}", icon='CHECKMARK')
    return True


class WhittedAddonPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    def draw(self, context):
        draw_module_status(self.layout)


class WHITTED_PT_render(WhittedPanel, bpy.types.Panel):
    bl_context = "render"

    @classmethod
    def poll(cls, context):
        return context.engine == "WHITTED"

    def draw(self, context):
        if "whitted" not in sys.modules:  # only say something when it is wrong
            draw_module_status(self.layout)
        p = context.scene.whitted
        for k in ("samples", "max_depth", "ambient", "threads"):
            self.layout.prop(p, k)
        self.layout.operator("whitted.check_pov")


class WHITTED_PT_light(WhittedPanel, bpy.types.Panel):
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return context.light is not None and context.engine == "WHITTED"

    def draw(self, context):
        light = context.light
        self.layout.prop(light, "type")
        self.layout.prop(light, "color")
        self.layout.prop(light, "energy")
        self.layout.prop(light.whitted, "use_intensity")
        self.layout.prop(light.whitted, "intensity")


def _compat_panels():
    """Blender's own panels that EEVEE shows (material surface and preview, world, output, ...), so
    they show with Whitted too: the add-on reads Principled BSDF inputs and world colour from them,
    and renders the material preview."""
    for name in dir(bpy.types):
        panel = getattr(bpy.types, name)
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if isinstance(engines, set) and "BLENDER_EEVEE" in engines \
                and name.startswith(("MATERIAL_PT", "WORLD_PT", "EEVEE_MATERIAL_PT_context_material",
                                     "EEVEE_MATERIAL_PT_surface", "EEVEE_WORLD_PT_surface",
                                     "RENDER_PT_format", "RENDER_PT_color_management",
                                     "DATA_PT_camera", "DATA_PT_lens", "DATA_PT_context")):
            yield panel


def _menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_whitted.bl_idname, text="Whitted scene (.json)")


_classes = (WhittedAddonPreferences, WhittedSceneProps, WhittedMaterialProps, WhittedLightProps, WhittedRenderEngine,
            EXPORT_SCENE_OT_whitted, WHITTED_OT_check_pov, WHITTED_PT_material, WHITTED_PT_render, WHITTED_PT_light)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.whitted = bpy.props.PointerProperty(type=WhittedSceneProps)
    bpy.types.Material.whitted = bpy.props.PointerProperty(type=WhittedMaterialProps)
    bpy.types.Light.whitted = bpy.props.PointerProperty(type=WhittedLightProps)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.add("WHITTED")


def unregister():
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.discard("WHITTED")
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    del bpy.types.Scene.whitted, bpy.types.Material.whitted, bpy.types.Light.whitted
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
