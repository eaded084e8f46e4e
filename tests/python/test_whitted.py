# SPDX-License-Identifier: MIT
"""The Python module `whitted` (docs/library.md), from the build tree (PYTHONPATH=build/python).

Run by ctest as python.module (label python); $WHITTED is the `whitted` program of the same build,
$WHITTED_EXAMPLES the examples directory. EXR files are read back with Debian's
python3-openimageio, which knows nothing of Whitted.
"""
import json
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


# Every failure of the module's functions is an exception, never a signal. The cases run one after
# another in one child interpreter (a crash there is a negative exit status, not a lost test run,
# and the case it was running is named); each prints the exception's type. OUT is a folder of the
# child's own; LINK a symbolic link in it to a file elsewhere, TEXT a text file named .png,
# EXR a 2x2 image.
NAN, HUGE = "float('nan')", "2**64"
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
    "write_image of None": ("whitted.write_image(None, OUT + '/n.exr')", "ValueError"),
    "write_image to /dev/full": ("whitted.write_image(np.zeros((2, 2, 3), np.float32), '/dev/full')", "Error"),
    "write_image into /proc": ("whitted.write_image(np.zeros((2, 2, 3), np.float32), '/proc/x.exr')", "Error"),
    "write_image to an empty path": ("whitted.write_image(np.zeros((2, 2, 3), np.float32), '')", "Error"),
    "write_image to a path with a NUL": ("whitted.write_image(np.zeros((2, 2, 3), np.float32), OUT + '/x.exr\\0.png')",
                                         "ValueError"),
    # as `whitted render -o`: the link is replaced by the image, never written through
    "write_image onto a symlink": ("whitted.write_image(np.zeros((2, 2, 3), np.float32), LINK + '.exr')", "NOTHING"),
    "render with threads=-1": ("whitted.render(SCENE, threads=-1)", "ValueError"),
    "render with threads=10**9": ("whitted.render(SCENE, threads=10**9)", "ValueError"),
    "render with threads=2**31-1": ("whitted.render(SCENE, threads=2**31 - 1)", "ValueError"),
    "render with threads=2**64": (f"whitted.render(SCENE, threads={HUGE})", "TypeError"),
    "render with threads=None": ("whitted.render(SCENE, threads=None)", "TypeError"),
    "render of None": ("whitted.render(None)", "TypeError"),
    "render_layers with threads=10**7": ("whitted.render_layers(SCENE, ['diffuse'], threads=10**7)", "ValueError"),
    "render_layers with an unknown layer": ("whitted.render_layers(SCENE, ['nope'])", "Error"),
    "render_layers with an empty layer name": ("whitted.render_layers(SCENE, [''])", "Error"),
    "render_layers with layers=[None]": ("whitted.render_layers(SCENE, [None])", "TypeError"),
    "load a missing scene": ("whitted.load(OUT + '/missing.yaml')", "Error"),
    "load an empty path": ("whitted.load('')", "Error"),
    "load a folder": ("whitted.load(OUT)", "Error"),
    "load None": ("whitted.load(None)", "TypeError"),
    "load with width=NaN": (f"whitted.load(SHADOWS, width={NAN})", "TypeError"),
    "load with width=2**64": (f"whitted.load(SHADOWS, width={HUGE})", "TypeError"),
    "load a path with a NUL": ("whitted.load(SHADOWS + '\\0.nff')", "ValueError"),
    "write_povray to an empty path": ("whitted.write_povray(SCENE, '')", "Error"),
    "write_povray into /proc": ("whitted.write_povray(SCENE, '/proc/x.pov')", "Error"),
    "write_povray into a missing folder": ("whitted.write_povray(SCENE, OUT + '/no/x.pov')", "Error"),
    "check with threads=-5": ("whitted.check(SHADOWS, threads=-5)", "ValueError"),
    "check a missing scene": ("whitted.check(OUT + '/missing.yaml')", "Error"),
    "check an empty path": ("whitted.check('')", "Error"),
    "check None": ("whitted.check(None)", "TypeError"),
    "check with an unknown layer": ("whitted.check(SHADOWS, layers=['nope'])", "Error"),
    "check with layers=None": ("whitted.check(SHADOWS, layers=None)", "TypeError"),
    "check with a missing POV-Ray image": ("whitted.check(SHADOWS, povray_image=OUT + '/missing.png')", "Error"),
    "check with a POV-Ray image that is text": ("whitted.check(SHADOWS, povray_image=TEXT)", "Error"),
    "check with exposure=NaN": (f"whitted.check(SHADOWS, povray_image=TEXT, exposure={NAN})", "ValueError"),
    "check with exposure=2": ("whitted.check(SHADOWS, povray_image=TEXT, exposure=2)", "ValueError"),
    "check with exposure=0": ("whitted.check(SHADOWS, povray_image=TEXT, exposure=0)", "ValueError"),
    "check with tolerance=NaN": (f"whitted.check(SHADOWS, tolerance={NAN})", "ValueError"),
    "check with min_fraction=1.5": ("whitted.check(SHADOWS, min_fraction=1.5)", "ValueError"),
    "check with max_error=-1": ("whitted.check(SHADOWS, max_error=-1)", "ValueError"),
    "check with a report folder in /proc": ("whitted.check(SHADOWS, report_dir='/proc/whitted-report')", "Error"),
    "check with a report path with a NUL": ("whitted.check(SHADOWS, report_dir=OUT + '/r\\0')", "ValueError"),
    "compare_image_files of a missing file": ("whitted.compare_image_files(EXR, OUT + '/missing.exr')", "Error"),
    "compare_image_files of empty paths": ("whitted.compare_image_files('', '')", "Error"),
    "compare_image_files of a text file": ("whitted.compare_image_files(TEXT, EXR)", "Error"),
    "compare_image_files of a folder": ("whitted.compare_image_files(EXR, OUT)", "Error"),
    "compare_image_files of None": ("whitted.compare_image_files(None, EXR)", "TypeError"),
    "compare_image_files of a number": ("whitted.compare_image_files(EXR, 5)", "TypeError"),
    "compare_image_files with tolerance=NaN": (f"whitted.compare_image_files(EXR, EXR, tolerance={NAN})", "ValueError"),
    "compare_image_files with tolerance=-1": ("whitted.compare_image_files(EXR, EXR, tolerance=-1)", "ValueError"),
    "compare_image_files with tolerance=10**400": ("whitted.compare_image_files(EXR, EXR, tolerance=10**400)",
                                                   "TypeError"),
    "compare_image_files with min_fraction=NaN": (f"whitted.compare_image_files(EXR, EXR, min_fraction={NAN})",
                                                  "ValueError"),
    "compare_image_files with min_fraction=-0.5": ("whitted.compare_image_files(EXR, EXR, min_fraction=-0.5)",
                                                   "ValueError"),
    "compare_image_files with max_error=NaN": (f"whitted.compare_image_files(EXR, EXR, max_error={NAN})",
                                               "ValueError"),
    "compare_image_files with a NUL": ("whitted.compare_image_files(EXR + '\\0', EXR)", "ValueError"),
    "explain a pixel left of the image": ("whitted.explain(SCENE, -1, 0)", "Error"),
    "explain a pixel below the image": ("whitted.explain(SCENE, 0, SCENE.height)", "Error"),
    "explain a pixel at 2**31-1": ("whitted.explain(SCENE, 2**31 - 1, 0)", "Error"),
    "explain a pixel at 2**64": (f"whitted.explain(SCENE, {HUGE}, 0)", "TypeError"),
    "explain a pixel at NaN": (f"whitted.explain(SCENE, {NAN}, 0)", "TypeError"),
    "explain a pixel of None": ("whitted.explain(SCENE, None, 0)", "TypeError"),
    "explain None": ("whitted.explain(None, 0, 0)", "TypeError"),
    "explain with threads=-1": ("whitted.explain(SCENE, 0, 0, threads=-1)", "ValueError"),
    "explain_text a pixel outside": ("whitted.explain_text(SCENE, SCENE.width, 0, summary=True)", "Error"),
    "explain_text with summary='yes'": ("whitted.explain_text(SCENE, 0, 0, summary='yes')", "TypeError"),
    "describe_colour_config of a missing config": ("whitted.describe_colour_config(OUT + '/missing.ocio')", "Error"),
    "describe_colour_config of a folder": ("whitted.describe_colour_config(OUT)", "Error"),
    "describe_colour_config of a text file": ("whitted.describe_colour_config(TEXT)", "Error"),
    "describe_colour_config of None": ("whitted.describe_colour_config(None)", "TypeError"),
    "describe_colour_config with a NUL": ("whitted.describe_colour_config(OUT + '\\0')", "ValueError"),
    "write_colour_config into a missing folder": ("whitted.write_colour_config(OUT + '/no/such/x.ocio')", "Error"),
    "write_colour_config through a symlink": ("whitted.write_colour_config(LINK)", "Error"),
    "write_colour_config onto a folder": ("whitted.write_colour_config(OUT)", "Error"),
    "write_colour_config to /dev/full": ("whitted.write_colour_config('/dev/full')", "Error"),
    "write_colour_config into /proc": ("whitted.write_colour_config('/proc/whitted.ocio')", "Error"),
    "write_colour_config to an empty path": ("whitted.write_colour_config('')", "Error"),
    "write_colour_config to None": ("whitted.write_colour_config(None)", "TypeError"),
    "write_colour_config to a number": ("whitted.write_colour_config(3)", "TypeError"),
    "write_colour_config with a NUL": ("whitted.write_colour_config(OUT + '/c.ocio\\0.txt')", "ValueError"),
}


@pytest.fixture(scope="module")
def error_path_outcomes(tmp_path_factory):
    """{case: (exception type name, is a RuntimeError, message)}; runs every case of ERROR_PATHS
    in one child python3, and checks what they left behind."""
    out = tmp_path_factory.mktemp("error_paths")
    elsewhere = tmp_path_factory.mktemp("elsewhere")
    victim = elsewhere / "victim.txt"
    victim.write_text("precious: written through a symbolic link if this changes\n")
    os.symlink(victim, out / "link")
    os.symlink(victim, out / "link.exr")
    (out / "text.png").write_text("not an image\n")
    lines = ["import numpy as np, sys, whitted",
             f"OUT, SHADOWS = {str(out)!r}, {SHADOWS!r}",
             "LINK, TEXT, EXR = OUT + '/link', OUT + '/text.png', OUT + '/two.exr'",
             "SCENE = whitted.load(SHADOWS)",
             "whitted.write_image(np.ones((2, 2, 3), np.float32), EXR)",
             "def run(case, call):",
             "    print('CASE', case, flush=True)",
             "    try:",
             "        call()",
             "    except Exception as e:",
             "        print('RAISED', type(e).__name__, isinstance(e, RuntimeError), str(e).replace(chr(10), ' '), flush=True)",
             "    else:",
             "        print('RAISED NOTHING', flush=True)"]
    for case, (call, _) in ERROR_PATHS.items():
        lines.append(f"run({case!r}, lambda: {call})")
    result = subprocess.run([sys.executable, "-c", "\n".join(lines)], capture_output=True, text=True, timeout=300,
                            env=child_python_env())
    outcomes, case = {}, None
    for line in result.stdout.splitlines():
        if line.startswith("CASE "):
            case = line[5:]
        elif line.startswith("RAISED ") and case:
            kind, _, rest = line[7:].partition(" ")
            is_runtime, _, message = rest.partition(" ")
            outcomes[case] = (kind, is_runtime == "True", message)
            case = None
    if case is not None:  # the child died in the middle of this case
        outcomes[case] = (f"CRASHED (exit {result.returncode}): {result.stderr[-1500:]}", False, "")
    assert victim.read_text() == "precious: written through a symbolic link if this changes\n"
    assert os.path.islink(out / "link") and not os.path.islink(out / "link.exr")
    # Nothing half-written is left behind.
    leftovers = [p for p in os.listdir(out) if p not in ("link", "link.exr", "text.png", "two.exr")]
    assert leftovers == [], leftovers
    return outcomes


@pytest.mark.parametrize("case", sorted(ERROR_PATHS))
def test_every_error_path_raises(case, error_path_outcomes):
    _, expected = ERROR_PATHS[case]
    assert case in error_path_outcomes, f"{case}: never ran (an earlier case ended the interpreter?)"
    kind, is_runtime, message = error_path_outcomes[case]
    assert kind == expected, f"{case}: {kind} {message}"
    if expected == "Error":
        assert is_runtime, "whitted.Error is a RuntimeError"
        assert message, f"{case}: an Error with no message"


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


def run_whitted(*args, expect=0):
    result = subprocess.run([WHITTED, *args], capture_output=True, text=True, timeout=120)
    assert result.returncode == expect, (args, result.returncode, result.stderr)
    return result


def test_explain_is_the_programs_explain():
    scene = whitted.load(SHADOWS)
    image = whitted.render(scene, threads=2)
    lit = np.unravel_index(np.argmax(image.sum(axis=2)), image.shape[:2])
    # The brightest pixel (every term of the slide at work) and one of the background.
    for y, x in [tuple(int(v) for v in lit), (0, 0)]:
        pixel = f"{x},{y}"
        document = whitted.explain(scene, x, y, threads=1)
        assert (document["x"], document["y"], document["width"]) == (x, y, scene.width)
        np.testing.assert_allclose(document["rgb"], image[y, x], rtol=1e-6)
        assert document == json.loads(run_whitted("explain", SHADOWS, "--pixel", pixel, "--json", "-t", "1").stdout)
        assert whitted.explain_text(scene, x, y) == run_whitted("explain", SHADOWS, "--pixel", pixel).stdout
        assert whitted.explain_text(scene, x, y, summary=True) == run_whitted(
            "explain", SHADOWS, "--pixel", pixel, "--summary").stdout
    assert max(image[lit]) > 0.1, "the brightest pixel is dark: the test proves little"


def test_compare_image_files_is_the_programs_compare(tmp_path):
    image = whitted.render(whitted.load(SHADOWS, width=64), threads=2)
    first, png = str(tmp_path / "a.exr"), str(tmp_path / "a.png")
    whitted.write_image(image, first)
    whitted.write_image(image, png)
    off = image.copy()
    off[3, 5] += 0.01  # 655 codes: breaks the cap, not the share
    whitted.write_image(off, str(tmp_path / "off.exr"))
    whitted.write_image(image[:10], str(tmp_path / "short.exr"))
    cases = [(first, first, {}, []), (first, str(tmp_path / "off.exr"), {}, []),
             (first, str(tmp_path / "off.exr"), {"max_error": 1000.0}, ["--max-error", "1000"]),
             (first, png, {"clip": True}, ["--clip"]),
             (first, png, {"tolerance": 300.0, "min_fraction": 0.5, "max_error": 1000.0, "clip": True},
              ["--tolerance", "300", "--min-fraction", "0.5", "--max-error", "1000", "--clip"]),
             (first, str(tmp_path / "short.exr"), {}, [])]
    verdicts = []
    for index, (a, b, keywords, flags) in enumerate(cases):
        compared = whitted.compare_image_files(a, b, **keywords)
        if index in (1, 4, 5):  # the program once for a failure, a pass and a size mismatch
            cli = run_whitted("compare", a, b, *flags, expect=0 if compared.passed else 1)
            lines = cli.stdout.splitlines()
            assert lines[-1] == compared.verdict
            if compared.first_meaning:
                assert lines[:2] == [f"{a}: {compared.first_meaning}", f"{b}: {compared.second_meaning}"]
        assert bool(compared) == compared.passed and compared.passed == (compared.failures == [])
        verdicts.append(compared.passed)
    assert verdicts == [True, False, True, False, True, False], verdicts
    off_by = whitted.compare_image_files(first, str(tmp_path / "off.exr"))
    assert off_by.failures == [f for f in off_by.failures if f.startswith("cap")] and off_by.failures
    assert 600 < off_by.max_error_codes < 700 and off_by.fraction_within > 0.999 and off_by.rms_error > 0
    # Images of different sizes are a result that names the sizes, not an exception.
    short = whitted.compare_image_files(first, str(tmp_path / "short.exr"))
    assert short.first_meaning == "" and any("size" in f for f in short.failures), short.failures


def test_colour_config_is_the_programs_colour(tmp_path):
    assert whitted.describe_colour_config() == run_whitted("colour", "--list").stdout
    ours, theirs = tmp_path / "ours.ocio", tmp_path / "theirs.ocio"
    assert whitted.write_colour_config(str(ours)) is None
    run_whitted("colour", "--write-config", str(theirs))
    assert ours.read_bytes() == theirs.read_bytes() and b"displays" in ours.read_bytes()
    assert whitted.describe_colour_config(str(ours)) == run_whitted(
        "colour", "--list", "--ocio-config", str(ours)).stdout
    # An existing file is replaced by a complete one.
    ours.write_text("old\n")
    whitted.write_colour_config(str(ours))
    assert ours.read_bytes() == theirs.read_bytes()


def test_a_failed_write_leaves_an_existing_output_as_it_was(tmp_path):
    existing = tmp_path / "kept.png"
    existing.write_bytes(b"an earlier image\n")
    with pytest.raises(whitted.Error, match="Nope"):
        whitted.write_image(np.zeros((2, 2, 3), np.float32), str(existing), display="Nope")
    with pytest.raises(whitted.Error, match="symbolic link"):
        os.symlink(existing, tmp_path / "link.ocio")
        whitted.write_colour_config(str(tmp_path / "link.ocio"))
    assert existing.read_bytes() == b"an earlier image\n"
    assert sorted(os.listdir(tmp_path)) == ["kept.png", "link.ocio"]


def test_check_errors_name_the_file_and_the_kind(tmp_path):
    with pytest.raises(whitted.Error) as raised:
        whitted.check(str(tmp_path / "missing.yaml"))
    assert raised.value.kind == "bad_input" and "not found" in str(raised.value)
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: -4}\n")
    with pytest.raises(whitted.Error, match=rf"^{bad}:3:\d+: ") as raised:
        whitted.check(str(bad))
    assert raised.value.line == 3 and raised.value.kind == "bad_input"


def test_check_with_a_stored_povray_image_and_layers(tmp_path, capfd):
    """check(povray_image=...) compares with a stored image instead of running POV-Ray, written
    here with tests/validation's 16-bit PNG writer (every pixel the scene's background)."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "validation"))
    scene = tmp_path / "empty.yaml"
    scene.write_text("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\n"
                     "image: { width: 16, height: 12, background: [0.5, 0.25, 0.125] }\n"
                     "lights: []\nmaterials: {}\nobjects: []\n")
    import images
    stored, black = str(tmp_path / "povray.png"), str(tmp_path / "black.png")
    images.png16(stored, 16, 12, [32768, 16384, 8192], {}, 3)  # the background in 16-bit codes
    images.png16(black, 16, 12, [0, 0, 0], {}, 3)
    passed = whitted.check(str(scene), povray_image=stored, layers=["diffuse", "background"])
    assert passed and passed.verdict.startswith("PASS"), passed.verdict
    assert passed.verdict in capfd.readouterr().out
    cli = subprocess.run([WHITTED, "check", str(scene), "-q", "--povray-image", stored, "--layers", "diffuse,background"],
                         capture_output=True, text=True, timeout=120)
    assert cli.returncode == 0 and cli.stdout.splitlines()[-1] == passed.verdict
    # A stored image of another colour fails: a result, not an exception.
    failed = whitted.check(str(scene), povray_image=black)
    assert not failed and failed.verdict.startswith("FAIL") and failed.failures, failed.verdict


def test_ctrl_c_cancels_a_check_and_ends_povray(tmp_path):
    """SIGINT while POV-Ray runs (a stand-in that hangs): KeyboardInterrupt within 5 s, POV-Ray
    ended, and nothing of the check's left in $TMPDIR."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "validation"))
    import fake_povray
    scene = tmp_path / "empty.yaml"
    scene.write_text("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\n"
                     "image: { width: 16, height: 12 }\nlights: []\nmaterials: {}\nobjects: []\n")
    private_tmp, pidfile = tmp_path / "tmp", tmp_path / "povray.pid"
    private_tmp.mkdir()
    env = dict(child_python_env(), WHITTED_POVRAY=fake_povray.install(str(tmp_path)), FAKE_POVRAY_MODE="hang",
               FAKE_POVRAY_PIDFILE=str(pidfile), TMPDIR=str(private_tmp))
    script = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {os.path.dirname(whitted.__file__)!r})
        import whitted
        try:
            whitted.check({str(scene)!r})
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(42)
        print("finished", flush=True)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=env)
    deadline = time.monotonic() + 60
    while not pidfile.exists():
        assert proc.poll() is None and time.monotonic() < deadline, "POV-Ray never started"
        time.sleep(0.05)
    povray_pid = int(pidfile.read_text())
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        os.kill(povray_pid, signal.SIGKILL)
        raise
    took = time.monotonic() - sent
    assert out.strip() == "interrupted" and proc.returncode == 42, (out, proc.returncode)
    assert took < 5, f"the check stopped {took:.1f} s after SIGINT"
    try:
        os.kill(povray_pid, 0)
        alive = not open(f"/proc/{povray_pid}/stat").read().split()[2] == "Z"
    except ProcessLookupError:
        alive = False
    assert not alive, "POV-Ray is still running"
    assert os.listdir(private_tmp) == [], os.listdir(private_tmp)


def test_embree_is_loaded_by_the_first_bvh_and_its_absence_raises(tmp_path):
    """Embree is loaded when a scene first needs a BVH (renderer/src/render/embree_library.cpp):
    with a file that is not Embree first on the library path, a scene of one sphere still
    renders (traced without a BVH), and one of a triangle raises RuntimeError naming Embree and
    its Debian package, in a child interpreter that goes on afterwards."""
    (tmp_path / "libembree3.so.3").write_text("not a library\n")
    code = textwrap.dedent("""
        import whitted
        light = ([0, 0, 5], [1, 1, 1])
        material = {"kd": [0.5, 0.5, 0.5]}
        sphere = (whitted.SceneBuilder().image(8, 6).camera([0, 0, 5], [0, 0, 0]).point_light(*light)
                  .sphere([0, 0, 0], 1, material).build())
        print("SPHERE", whitted.render(sphere).shape, flush=True)
        triangle = (whitted.SceneBuilder().image(8, 6).camera([0, 0, 5], [0, 0, 0]).point_light(*light)
                    .triangle([-1, -1, 0], [1, -1, 0], [0, 1, 0], material).build())
        try:
            whitted.render(triangle)
            print("TRIANGLE rendered", flush=True)
        except RuntimeError as e:
            print("TRIANGLE RuntimeError", str(e), flush=True)
        print("SPHERE AGAIN", whitted.render(sphere).shape, flush=True)
    """)
    env = child_python_env()
    env["LD_LIBRARY_PATH"] = str(tmp_path) + ":" + env.get("LD_LIBRARY_PATH", "")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    assert result.returncode == 0, result.stderr[-2000:]
    lines = result.stdout.splitlines()
    assert lines[0] == "SPHERE (6, 8, 3)", result.stdout
    assert lines[1].startswith("TRIANGLE RuntimeError"), result.stdout
    assert "cannot load Embree" in lines[1] and "libembree3-3" in lines[1], lines[1]
    assert lines[2] == "SPHERE AGAIN (6, 8, 3)", result.stdout
