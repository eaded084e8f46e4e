#!/usr/bin/python3
"""ctest blender.install_prefix / blender.install_missing: the add-on installed under a PREFIX
(PREFIX/share/blender/scripts/addons/whitted_blender), WHITTED_PYTHONPATH unset, finds the module
in PREFIX/lib/python3/dist-packages and renders; with no module anywhere, the render fails with
a message naming every folder searched and WHITTED_PYTHONPATH, no crash.
Usage: test_install.py prefix|missing MODULE_DIR (the build's python folder)"""
import glob, json, os, shutil, sys, tempfile
mode, module_dir = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from headless import blender, fail, require_blender  # noqa: E402  (tests/blender/headless.py)
require_blender()
here = os.path.dirname(os.path.abspath(__file__))
work = tempfile.mkdtemp(prefix=f"whitted-blender-install-{mode}-")
prefix = os.path.join(work, "prefix")
addon = os.path.join(prefix, "share", "blender", "scripts", "addons", "whitted_blender")
shutil.copytree(os.path.join(here, "..", "..", "plugins", "blender", "whitted_blender"), addon,
                ignore=shutil.ignore_patterns("__pycache__"))
site = os.path.join(prefix, "lib", "python3", "dist-packages")
os.makedirs(site)
if mode == "prefix":  # the module as the build made it (an extension file, or a package folder)
    modules = glob.glob(os.path.join(module_dir, "whitted*"))
    assert any(m.endswith(".so") or os.path.isdir(m) for m in modules), f"no whitted module in {module_dir}"
    for m in modules:
        (shutil.copytree if os.path.isdir(m) else shutil.copy)(m, os.path.join(site, os.path.basename(m)))
env = dict(os.environ)
env.pop("WHITTED_PYTHONPATH", None)
empty = os.path.join(work, "empty")
if mode == "missing":  # a WHITTED_PYTHONPATH folder without the module: it must be listed too
    os.makedirs(empty)
    env["WHITTED_PYTHONPATH"] = empty
r = blender("install.py", prefix, work, expect=None, env=env)
# A background Blender whose render reported an ERROR exits with 1 (measured: Blender 3.4.1, even
# when the script catches the RuntimeError), so "missing" expects 1 and a normal quit: no signal.
expected_rc = 0 if mode == "prefix" else 1
result = os.path.join(work, "result.json")
if r.returncode != expected_rc or not os.path.exists(result) or "Blender quit" not in r.stdout:
    fail(f"exit code {r.returncode} (expected {expected_rc}) {r.stdout[-3000:]} {r.stderr[-3000:]}")
res = json.load(open(result))
if res["dropped_from_sys_path"]:
    print(f"note: Blender's sys.path held the module in {res['dropped_from_sys_path']}; dropped for this test")
assert res["addon_file"].startswith(addon), res["addon_file"]  # the installed copy, not the source
if mode == "prefix":
    assert res["error"] is None, res["error"]
    assert res["module_file"].startswith(site + os.sep), res["module_file"]
    assert res["max"] > res["min"], "image is flat: nothing rendered"
    print(f"blender.install_prefix: add-on {res['addon_file']} imported {res['module_file']}, rendered "
          f"(values {res['min']:.3f}..{res['max']:.3f})")
elif mode == "missing":
    e = res["error"]
    assert e is not None, "rendered without a module"
    assert not res["module_loaded"]
    assert "Traceback" not in e, e
    assert "cannot import the 'whitted' Python module" in e, e
    v = f"python{sys.version_info.major}.{sys.version_info.minor}"  # Debian's Blender runs this Python
    folders = [empty, site, os.path.join(prefix, "lib", v, "dist-packages")] + res["sys_path"]
    missing = [f for f in folders if f not in e]
    assert not missing, f"not named in the message: {missing}\n{e}"
    assert "Set WHITTED_PYTHONPATH" in e and "install Whitted" in e, e
    print(f"blender.install_missing: render refused with:\n{e}")
else:
    sys.exit(f"unknown mode {mode}")
