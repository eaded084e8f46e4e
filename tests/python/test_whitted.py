# SPDX-License-Identifier: MIT
"""The Python module `whitted` (docs/library.md), from the build tree (PYTHONPATH=build/python).

Run by ctest as python.module (label python); $WHITTED is the `whitted` program of the same build,
$WHITTED_EXAMPLES the examples directory. EXR files are read back with Debian's
python3-openimageio, which knows nothing of Whitted.
"""
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import whitted

WHITTED = os.environ["WHITTED"]
EXAMPLES = os.environ["WHITTED_EXAMPLES"]
SHADOWS = os.path.join(EXAMPLES, "lecture", "02-shadows.yaml")


def read_exr(path):
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    assert inp, oiio.geterror()
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    inp.close()
    return spec, pixels


def child_python_env():
    """The environment for a child python3 that imports the module: in the sanitizer build the
    ASan runtime must be preloaded again (conftest.py took it out of this process's LD_PRELOAD)."""
    env = dict(os.environ)
    if os.environ.get("WHITTED_TEST_PYTHON_PRELOAD"):
        env["LD_PRELOAD"] = os.environ["WHITTED_TEST_PYTHON_PRELOAD"]
    return env


def big_scene(samples=8, size=2000):
    """Several hundred million camera rays: a minute or more, far longer than any test waits."""
    return (whitted.SceneBuilder().image(size, size, samples).camera([0, 0, 5], [0, 0, 0])
            .point_light([0, 0, 5], [1, 1, 1])
            .sphere([0, 0, 0], 1.5, {"kd": [0.5, 0.5, 0.5], "ks": [0.3, 0.3, 0.3], "p": 20})
            .build())


def test_version_is_the_programs():
    out = subprocess.run([WHITTED, "--version"], capture_output=True, text=True, check=True).stdout
    assert out.split()[:2] == ["whitted", whitted.__version__]
    assert whitted.version() == whitted.__version__


def test_render_equals_the_exr_whitted_render_writes_bit_for_bit(tmp_path):
    exr = tmp_path / "shadows.exr"
    subprocess.run([WHITTED, "render", SHADOWS, "-o", str(exr), "-q", "-t", "2"], check=True)
    spec, pixels = read_exr(str(exr))
    scene = whitted.load(SHADOWS)
    image = whitted.render(scene, threads=1)
    assert image.dtype == np.float32
    assert image.shape == (scene.height, scene.width, 3) == (spec.height, spec.width, 3)
    assert pixels.dtype == np.float32
    assert np.array_equal(image, pixels), f"{np.count_nonzero(image != pixels)} values differ"
    assert image.any(), "an all-black image would match trivially"
    # No copy: the array's memory is the rendered Image's, owned through its base object.
    assert not image.flags.owndata and image.base is not None


def test_write_image_round_trip(tmp_path):
    image = whitted.render(whitted.load(SHADOWS), threads=2)
    path = tmp_path / "again.exr"
    whitted.write_image(image, str(path))
    _, pixels = read_exr(str(path))
    assert np.array_equal(image, pixels)


def test_scene_built_in_code_closed_form():
    ka, kd, ia, light = np.array([0.2, 0.1, 0.05]), np.array([0.5, 0.25, 0.125]), 0.5, 0.8
    scene = (whitted.SceneBuilder().image(65, 65).background([0.25, 0.5, 0.75])
             .camera([0, 0, 5], [0, 0, 0], fov=30).ambient([ia] * 3).point_light([0, 0, 5], [light] * 3)
             .sphere([0, 0, 0], 1, {"ka": list(ka), "kd": list(kd)}).build())
    image = whitted.render(scene)
    # Lecture formula at the centre pixel, n = l = (0, 0, 1): L = ka*Ia + kd*I*max(0, n.l).
    np.testing.assert_allclose(image[32, 32], ka * ia + kd * light, atol=1e-6)
    assert list(image[0, 0]) == [np.float32(0.25), np.float32(0.5), np.float32(0.75)]


def test_errors_carry_file_line_column(tmp_path):
    text = "version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: -4}\n"
    with pytest.raises(whitted.Error) as caught:
        whitted.loads(text, "bad.yaml")
    error = caught.value
    assert (error.file, error.line) == ("bad.yaml", 3)
    assert error.column > 0
    assert str(error).startswith(f"bad.yaml:3:{error.column}: ")
    assert error.kind == "bad_input"
    # A file: the same, with the path as given.
    path = tmp_path / "bad_file.yaml"
    path.write_text(text)
    with pytest.raises(whitted.Error, match=rf"^{path}:3:\d+: "):
        whitted.load(str(path))
    with pytest.raises(whitted.Error, match=r"^<SceneBuilder>:2:1: "):
        whitted.SceneBuilder().image(8, 8).camera([0, 0, 5], [0, 0, 5]).build()


def test_progress_callback_raising_cancels_the_render():
    scene = big_scene()
    calls = []

    def progress(done, total):
        calls.append((done, total))
        raise KeyboardInterrupt

    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        whitted.render(scene, threads=2, progress=progress)
    elapsed = time.monotonic() - start
    assert calls and calls[0][0] < calls[0][1], calls
    assert elapsed < 5, f"cancelling took {elapsed:.1f} s"


def test_progress_reports_completion():
    scene = whitted.load(SHADOWS)
    calls = []
    whitted.render(scene, threads=2, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1][0] == calls[-1][1] > 0


def seconds_to_stop_on_sigint(load_scene, wait, timeout):
    """Starts a child python3 that renders the scene `load_scene` (Python source) makes, sends it
    SIGINT after `wait` seconds, checks that it raised KeyboardInterrupt within `timeout` seconds,
    and returns how long it took to stop."""
    script = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {os.path.dirname(whitted.__file__)!r})
        import whitted
        scene = {load_scene}
        print("rendering", flush=True)
        try:
            whitted.render(scene, threads=2)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(42)
        print("finished", flush=True)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                            env=child_python_env())
    assert proc.stdout.readline().strip() == "rendering"
    time.sleep(wait)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    assert out.strip() == "interrupted" and proc.returncode == 42, (out, proc.returncode)
    return time.monotonic() - sent


def test_sigint_stops_a_render_within_a_second(tmp_path):
    took = seconds_to_stop_on_sigint(
        '(whitted.SceneBuilder().image(2000, 2000, 8).camera([0, 0, 5], [0, 0, 0])'
        '.point_light([0, 0, 5], [1, 1, 1]).sphere([0, 0, 0], 1.5, {"kd": [0.5, 0.5, 0.5]}).build())',
        wait=0.5, timeout=10)  # well inside the render
    assert took < 1.0, f"the render stopped {took:.2f} s after SIGINT"


def test_sigint_stops_even_a_tile_that_takes_minutes(tmp_path):
    """heavy_tile.yaml: one tile of 256 pixels at 0.34 s each on a core (two facing mirrors, depth
    256, 16x16 samples, 49 lights). The render heeds the stop between pixels, not only between
    tiles: before, Ctrl-C waited for the tile (146 s measured)."""
    heavy = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "robustness", "heavy_tile.yaml")
    took = seconds_to_stop_on_sigint(f"whitted.load({heavy!r})", wait=1.0, timeout=60)  # inside the tile
    assert took < 5.0, f"the render stopped {took:.2f} s after SIGINT"


def test_gil_is_released_while_rendering():
    scene = big_scene(samples=2, size=1000)
    done = threading.Event()
    counted = [0]

    def count():
        while not done.is_set():
            counted[0] += 1

    counter = threading.Thread(target=count)
    counter.start()
    start = time.monotonic()
    whitted.render(scene, threads=1)
    elapsed = time.monotonic() - start
    done.set()
    counter.join()
    # Had the render held the GIL, the counter would not have run at all meanwhile.
    assert elapsed > 0.2, f"render too quick ({elapsed:.2f} s) to tell"
    assert counted[0] > 10000, f"the other thread ran {counted[0]} times in {elapsed:.2f} s"


def test_to_povray_and_write_povray(tmp_path):
    scene = whitted.load(SHADOWS)
    sdl = whitted.to_povray(scene)
    assert "camera" in sdl and "light_source" in sdl
    ini = whitted.write_povray(scene, str(tmp_path / "s.pov"))
    assert ini.endswith("s.ini") and os.path.exists(ini)
    assert (tmp_path / "s.pov").read_text() == sdl


def test_to_povray_converts_the_scene_as_loaded(tmp_path):
    # The SDL is the loaded scene's even when its file has changed since (a different sphere now).
    path = tmp_path / "changing.yaml"
    with open(SHADOWS) as f:
        original = f.read()
    path.write_text(original)
    scene = whitted.load(str(path))
    path.write_text(original.replace("objects:", "objects:\n  - {type: sphere, center: [7, 7, 7], radius: 0.25, material: sphere}", 1))
    changed = whitted.to_povray(whitted.load(str(path)))
    path.write_text(original)
    loaded = whitted.to_povray(whitted.load(str(path)))
    assert changed != loaded, "the change does not show in the SDL: the test proves nothing"
    path.write_text(original.replace("objects:", "objects:\n  - {type: sphere, center: [7, 7, 7], radius: 0.25, material: sphere}", 1))
    assert whitted.to_povray(scene) == loaded
    whitted.write_povray(scene, str(tmp_path / "s.pov"))
    assert (tmp_path / "s.pov").read_text() == loaded


def test_check_against_povray():
    povray = os.environ.get("WHITTED_POVRAY") or "povray"
    if subprocess.run(["sh", "-c", f"command -v {povray}"], capture_output=True).returncode != 0:
        pytest.skip("POV-Ray is not installed (scripts/setup --with-test-tools installs it)")
    result = whitted.check(os.path.join(EXAMPLES, "lecture", "01-lambertian-sphere.yaml"), threads=2)
    assert result.passed and result, result.verdict
    assert result.verdict.startswith("PASS")
    assert 0.999 <= result.fraction_within <= 1
    with pytest.raises(whitted.Error):
        whitted.check("/nonexistent/scene.yaml")


# Every failure of the module's functions is an exception, never a signal: each case runs in a
# child interpreter (a crash there is a negative exit status, not a lost test run), which prints
# the exception's type and ends with exit 0.
ERROR_PATHS = {
    "write_image to an unknown format": (
        "whitted.write_image(np.zeros((2, 2, 3), np.float32), OUT + '/x.bmp')", "Error"),
    "write_image into a missing folder": (
        "whitted.write_image(np.zeros((2, 2, 3), np.float32), OUT + '/no/such/dir/x.png')", "Error"),
    "write_image with an unknown display": (
        "whitted.write_image(np.zeros((2, 2, 3), np.float32), OUT + '/x.png', display='Nope')", "Error"),
    "write_image of an empty array (0, 5, 3)": ("whitted.write_image(np.zeros((0, 5, 3), np.float32), OUT + '/e.png')",
                                                "ValueError"),
    "write_image of an empty array (5, 0, 3)": ("whitted.write_image(np.zeros((5, 0, 3), np.float32), OUT + '/e.exr')",
                                                "ValueError"),
    "write_image of an empty array (0, 0, 3)": ("whitted.write_image(np.zeros((0, 0, 3), np.float32), OUT + '/e.exr')",
                                                "ValueError"),
    "render with threads=-1": ("whitted.render(SCENE, threads=-1)", "ValueError"),
    "render with threads=10**9": ("whitted.render(SCENE, threads=10**9)", "ValueError"),
    "render with threads=2**31-1": ("whitted.render(SCENE, threads=2**31 - 1)", "ValueError"),
    "render_layers with threads=10**7": ("whitted.render_layers(SCENE, ['diffuse'], threads=10**7)", "ValueError"),
    "check with threads=-5": ("whitted.check(SHADOWS, threads=-5)", "ValueError"),
}


@pytest.mark.parametrize("case", sorted(ERROR_PATHS))
def test_every_error_path_raises(case, tmp_path):
    call, expected = ERROR_PATHS[case]
    program = textwrap.dedent(f"""
        import numpy as np, whitted
        OUT = {str(tmp_path)!r}
        SHADOWS = {SHADOWS!r}
        SCENE = whitted.load(SHADOWS)
        try:
            {call}
        except Exception as e:
            print(type(e).__name__, isinstance(e, RuntimeError) if type(e).__name__ == 'Error' else '', e)
        else:
            print('NOTHING RAISED')
    """)
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=120,
                            env=child_python_env())
    assert result.returncode == 0, f"{case}: exit {result.returncode}\n{result.stderr[-2000:]}"
    kind = result.stdout.split()[0] if result.stdout.split() else ""
    assert kind == expected, f"{case}: {result.stdout}{result.stderr[-2000:]}"
    if expected == "Error":
        assert result.stdout.split()[1] == "True", "whitted.Error is a RuntimeError"
    # Nothing half-written is left behind.
    assert not [p for p in os.listdir(tmp_path) if "tmp" in p], os.listdir(tmp_path)


def test_overrides_act_as_the_files_own_settings():
    with open(SHADOWS) as f:
        text = f.read()
    scene = whitted.load(SHADOWS)
    w, h = scene.width, scene.height
    # One side alone keeps the aspect ratio, rounded to the nearest pixel (half away from zero).
    narrow = whitted.load(SHADOWS, width=101, samples=2, max_depth=2, intersection="povray")
    assert (narrow.width, narrow.height) == (101, int(101 * h / w + 0.5))
    assert (narrow.samples, narrow.max_depth) == (2, 2)
    tall = whitted.loads(text, "shadows.yaml", height=77)
    assert (tall.width, tall.height) == (int(77 * w / h + 0.5), 77)
    # The same pixels as the scene with those values written into it.
    import yaml
    written = yaml.safe_load(text)
    written["image"].update({"width": 101, "height": narrow.height, "samples": 2})
    written.setdefault("render", {}).update({"max_depth": 2, "intersection": "povray"})
    same = whitted.loads(yaml.safe_dump(written), SHADOWS)
    assert np.array_equal(whitted.render(narrow), whitted.render(same))


@pytest.mark.parametrize("overrides, fragment", [
    ({"width": 0}, "image.width must be at least 1"),
    ({"height": 70000}, "the limit is 65536 per side"),
    ({"samples": 17}, "image.samples must be between 1 and 16"),
    ({"max_depth": 0}, "render.max_depth must be between 1 and 256"),
    ({"intersection": "fast"}, "intersection must be 'exact' or 'povray'"),
])
def test_a_bad_override_is_an_error_naming_it(overrides, fragment):
    with pytest.raises(whitted.Error) as raised:
        whitted.load(SHADOWS, **overrides)
    assert fragment in str(raised.value)
    assert raised.value.file == "SceneOverrides" and raised.value.kind == "bad_input"


def test_crop_is_the_whole_renders_window_bit_for_bit():
    scene = whitted.load(SHADOWS, width=130, samples=2)
    whole = whitted.render(scene, threads=2)
    for x, y, w, h in [(0, 0, scene.width, scene.height), (129, scene.height - 1, 1, 1), (7, 33, 60, 41)]:
        part = whitted.render(scene, threads=1, crop=(x, y, w, h))
        assert part.shape == (h, w, 3)
        assert np.array_equal(part, whole[y:y + h, x:x + w])
    layers = whitted.render_layers(scene, ["diffuse", "Z"], crop=(7, 33, 60, 41))
    all_layers = whitted.render_layers(scene, ["diffuse", "Z"])
    for name in ("beauty", "diffuse", "Z"):
        assert np.array_equal(layers[name], all_layers[name][33:74, 7:67])


@pytest.mark.parametrize("crop", [(0, 0, 0, 1), (-1, 0, 2, 2), (120, 0, 11, 5), (0, 0, 1, 10**6)])
def test_a_crop_outside_the_image_is_an_error(crop):
    scene = whitted.load(SHADOWS, width=130)
    with pytest.raises(whitted.Error, match="does not lie inside the 130x"):
        whitted.render(scene, crop=crop)


@pytest.mark.parametrize("crop", [(1, 2, 3), "0,0,1,1", (0.5, 0, 1, 1), (0, 0, 1, 10**12)])
def test_a_crop_that_is_not_four_whole_numbers_is_a_value_error(crop):
    with pytest.raises(ValueError, match="crop: expected"):
        whitted.render(whitted.load(SHADOWS), crop=crop)


@pytest.mark.parametrize("call, fragment", [
    (lambda b: b.background([float("nan"), 0, 0]), "image.background"),
    (lambda b: b.ambient([0, float("inf"), 0]), "ambient"),
    (lambda b: b.point_light([float("nan"), 0, 0], [1, 1, 1]), "point_light.position"),
    (lambda b: b.point_light([0, 0, 5], [1, float("inf"), 1]), "point_light.intensity"),
    (lambda b: b.directional_light([0, float("nan"), 0], [1, 1, 1]), "directional_light.direction"),
    (lambda b: b.sphere([float("inf"), 0, 0], 1, {"kd": 1}), "sphere.center"),
    (lambda b: b.sphere([0, 0, 0], float("nan"), {"kd": 1}), "sphere.radius"),
    (lambda b: b.sphere([0, 0, 0], 1, {"kd": [float("nan"), 0, 0]}), "material.kd"),
    (lambda b: b.sphere([0, 0, 0], 1, {"kd": 1, "p": float("inf")}), "material.p"),
    (lambda b: b.plane([0, 0, 0], [float("nan"), 1, 0], {"kd": 1}), "plane.normal"),
    (lambda b: b.box([0, 0, 0], [1, float("inf"), 1], {"kd": 1}), "box.max"),
    (lambda b: b.triangle([0, 0, 0], [1, 0, 0], [0, float("nan"), 0], {"kd": 1}), "triangle.vertices"),
])
def test_scene_builder_refuses_numbers_that_are_not_finite_as_a_file_does(call, fragment):
    builder = whitted.SceneBuilder().image(8, 8).camera([0, 0, 5], [0, 0, 0])
    call(builder)
    with pytest.raises(whitted.Error, match=f"{fragment}: must be a finite number") as raised:
        builder.build()
    assert raised.value.file == "<SceneBuilder>" and raised.value.line == 3


def test_scene_builder_camera_that_is_not_finite_is_named():
    with pytest.raises(whitted.Error, match="camera.eye: must be a finite number"):
        whitted.SceneBuilder().image(8, 8).camera([float("nan"), 0, 5], [0, 0, 0]).build()


def test_a_material_colour_may_be_one_number_for_a_grey_and_nothing_else():
    def pixel(kd):
        return whitted.render(whitted.SceneBuilder().image(9, 9).camera([0, 0, 5], [0, 0, 0])
                              .point_light([0, 0, 5], [1, 1, 1]).sphere([0, 0, 0], 1, {"kd": kd}).build())[4, 4]
    assert np.array_equal(pixel(0.5), pixel([0.5, 0.5, 0.5]))
    for bad in ("red", [1, 2], None):
        with pytest.raises(ValueError, match="kd must be a number or three numbers"):
            pixel(bad)
