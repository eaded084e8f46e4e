"""Rendered shading in the 3D viewport: the view's camera in Whitted's terms, what a change re-does,
and the background render with progressive refinement (docs/blender.md, Viewport).

Kept free of `bpy` so the logic can be driven by a test with a plain depsgraph and a
region_data-like object; the engine (__init__.py) only wires it to view_update/view_draw.
"""
import math
import threading
import time

import numpy as np

from .mapping import MappingError, dumps

# The coarse image is this many times smaller in each direction (1/16 of the pixels, 1 sample).
COARSE_DIVISOR = 4


def _m(matrix, i, j):
    return float(matrix[i][j])


def view_camera(view_matrix, window_matrix, is_perspective):
    """Whitted camera dict for a 3D view: `view_matrix` world -> view, `window_matrix` the
    projection (RegionView3D's matrices, or any 4x4 indexable [row][col]).

    Perspective: fov = 2 atan(1 / P[0][0]) (horizontal, as Whitted's fov). Orthographic:
    view_width = 2 / P[0][0], and the eye moved back to the near clip plane: Blender's
    orthographic views clip at -clip_end/2 (in front of *and behind* the view point), Whitted's
    orthographic rays start at the eye. Off-centre projections (a panned camera view, lens
    shift) have no Whitted camera and are refused.
    """
    inv = [[0.0] * 4 for _ in range(4)]
    # The view matrix is a rigid transform: its inverse is R^T and -R^T t.
    r = [[_m(view_matrix, i, j) for j in range(3)] for i in range(3)]
    t = [_m(view_matrix, i, 3) for i in range(3)]
    for i in range(3):
        for j in range(3):
            inv[i][j] = r[j][i]
        inv[i][3] = -sum(r[k][i] * t[k] for k in range(3))
    eye = [inv[i][3] for i in range(3)]
    fwd = [-inv[i][2] for i in range(3)]
    up = [inv[i][1] for i in range(3)]
    p00 = _m(window_matrix, 0, 0)
    if is_perspective:
        if abs(_m(window_matrix, 0, 2)) > 1e-9 or abs(_m(window_matrix, 1, 2)) > 1e-9:
            raise MappingError("Whitted: an off-centre view (a panned camera view or lens shift) is not "
                               "supported; centre the camera view (Home)")
        return {'eye': eye, 'look_at': [e + f for e, f in zip(eye, fwd)], 'up': up,
                'fov': math.degrees(2 * math.atan(1 / p00))}
    if abs(_m(window_matrix, 0, 3)) > 1e-9 or abs(_m(window_matrix, 1, 3)) > 1e-9:
        raise MappingError("Whitted: an off-centre view (a panned camera view or lens shift) is not "
                           "supported; centre the camera view (Home)")
    p22, p23 = _m(window_matrix, 2, 2), _m(window_matrix, 2, 3)
    far_minus_near = -2 / p22
    near = (-p23 * far_minus_near - far_minus_near) / 2
    eye = [e + near * f for e, f in zip(eye, fwd)]
    return {'type': 'orthographic', 'eye': eye, 'look_at': [e + f for e, f in zip(eye, fwd)], 'up': up,
            'view_width': 2 / p00}


def region_camera(region_data):
    """view_camera of a RegionView3D (or an object with view_matrix, window_matrix, is_perspective)."""
    return view_camera(region_data.view_matrix, region_data.window_matrix, region_data.is_perspective)


def display_rgba(image):
    """The float32 RGBA pixels the viewport uploads: `image` (H x W x 3, rows from the top, as
    whitted.render returns it) with rows from the bottom (OpenGL's order) and alpha 1."""
    h, w = image.shape[:2]
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = image[::-1]
    return rgba


class _Superseded(Exception):
    """Raised from the progress callback: a newer view or scene replaced this render."""


class ViewportSession:
    """One viewport's state: the scene description (exported on scene changes only), the view's
    camera and size, and a worker thread that renders coarse then full and keeps the latest image.

    `on_image` (set by the engine) is called from the worker thread when a better image is ready;
    it must only flag a redraw. The worker holds no reference to the engine, so the engine can be
    freed (and stop() the session from its __del__) while a render runs.
    """

    def __init__(self, whitted_module, threads=0, on_image=None):
        self.wm = whitted_module
        self.threads = threads
        self.on_image = on_image
        self.exports = 0          # scene exports (view_update with changes)
        self.restarts = 0         # renders started (scene or view changes)
        self.log = []             # (kind, width, height, seconds since the change, render seconds)
        self.error = None         # a MappingError / whitted.Error message, shown instead of an image
        self._desc = None         # the description; its camera and size are the view's
        self._scene_key = None    # its text: equal text, nothing to re-render
        self._view = None         # (camera dict, width, height)
        self._cv = threading.Condition()
        self._generation = 0
        self._job = None
        self._stopped = False
        self.image = None         # latest H x W x 3 float32 image, rows from the top
        self.image_generation = -1
        self.image_full = False
        self._thread = threading.Thread(target=self._run, name="whitted-viewport", daemon=True)
        self._thread.start()

    # -- what changed decides the work -------------------------------------------------------
    def update_scene(self, depsgraph):
        """A depsgraph change (view_update): re-export; re-render only if the scene text changed
        (selecting an object, say, changes nothing Whitted renders)."""
        from .export import describe
        self.exports += 1
        try:
            desc = describe(depsgraph, camera={}, size=(1, 1))
        except MappingError as e:
            self._fail(str(e))
            return
        key = dumps(dict(desc, camera=None))
        if key != self._scene_key:
            self._desc, self._scene_key = desc, key
            self._restart()

    def update_view(self, camera, width, height):
        """The view as drawn (view_draw): re-render with the new camera only when it moved or the
        region was resized; the scene is not re-exported."""
        view = (camera, int(width), int(height))
        if view != self._view:
            self._view = view
            self._restart()

    def scene_text(self):
        """The Whitted scene text the current view renders (the full-resolution one)."""
        camera, width, height = self._view
        desc = dict(self._desc)  # camera and image replaced in place: the key order of F12's text
        desc['camera'] = camera
        desc['image'] = dict(desc['image'], width=width, height=height)
        return dumps(desc)

    # -- the worker ---------------------------------------------------------------------------
    def _fail(self, message):
        with self._cv:
            self._generation += 1
            self.error = message
            self._job = None
        if self.on_image:
            self.on_image()

    def _restart(self):
        if self._desc is None or self._view is None:
            return
        with self._cv:
            self._generation += 1
            self.restarts += 1
            self.error = None
            self._job = (self._generation, self.scene_text(), self._view[1], self._view[2], time.monotonic())
            self._cv.notify()

    def _publish(self, generation, image, full, kind, started, t0):
        with self._cv:
            if generation != self._generation:
                return False
            self.image, self.image_generation, self.image_full = image, generation, full
            now = time.monotonic()
            self.log.append((kind, image.shape[1], image.shape[0], now - started, now - t0))
        if self.on_image:
            self.on_image()
        return True

    def _run(self):
        while True:
            with self._cv:
                while self._job is None and not self._stopped:
                    self._cv.wait()
                if self._stopped:
                    return
                generation, text, width, height, started = self._job
                self._job = None

            def progress(done, total, generation=generation):
                if self._generation != generation or self._stopped:
                    raise _Superseded()

            try:
                cw, ch = max(1, width // COARSE_DIVISOR), max(1, height // COARSE_DIVISOR)
                for kind, options in (("coarse", dict(width=cw, height=ch, samples=1)), ("full", {})):
                    if kind == "coarse" and (cw, ch) == (width, height):
                        continue
                    t0 = time.monotonic()
                    scene = self.wm.loads(text, "<blender viewport>.json", **options)
                    image = self.wm.render(scene, threads=self.threads, progress=progress)
                    if not self._publish(generation, image, kind == "full", kind, started, t0):
                        break
            except _Superseded:
                continue
            except Exception as e:  # whitted.Error: a message for the viewport, not a traceback
                with self._cv:
                    if generation == self._generation:
                        self.error = f"Whitted: {e}"
                if self.on_image:
                    self.on_image()

    def wait(self, timeout=60.0):
        """Block until the full image of the latest change is ready (or an error); True if it is.
        For tests and scripts; the viewport never waits."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            with self._cv:
                if self.error is not None:
                    return False
                if self.image_full and self.image_generation == self._generation:
                    return True
            time.sleep(0.005)
        return False

    def stop(self, wait=True):
        """Cancel the running render (at its next progress call) and end the thread; with
        wait=False, do not wait for the thread (the UI's timer must not block)."""
        with self._cv:
            self._stopped = True
            self._generation += 1
            self._cv.notify()
        if wait and self._thread is not threading.current_thread():
            self._thread.join()
