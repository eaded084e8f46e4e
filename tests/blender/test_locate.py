#!/usr/bin/python3
"""ctest blender.locate: the add-on's search for the `whitted` module (locate.py has no bpy; plain
Python): the folders derived from where the add-on is, the search order, and the message."""
import os, sys, tempfile
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "plugins", "blender", "whitted_blender"))
import locate

v = f"python{sys.version_info.major}.{sys.version_info.minor}"

def near(addon_init, environ=None, path=()):
    groups = locate.search_folders(addon_init, environ or {}, list(path))
    assert [g[0] for g in groups] == ["WHITTED_PYTHONPATH", "sys.path", "near the add-on"], groups
    return groups

# The .deb: /usr/share/blender/scripts/addons (Debian's Blender's system add-ons) -> /usr/lib/...
g = near("/usr/share/blender/scripts/addons/whitted_blender/__init__.py")
assert g[2][1] == [f"/usr/lib/{v}/dist-packages", "/usr/lib/python3/dist-packages",
                   f"/usr/lib/{v}/site-packages"], g
# Another prefix
g = near("/opt/w/share/blender/scripts/addons/whitted_blender/__init__.py")
assert "/opt/w/lib/python3/dist-packages" in g[2][1] and f"/opt/w/lib/{v}/dist-packages" in g[2][1], g
# Blender's user add-ons folder implies no prefix
g = near(os.path.expanduser("~/.config/blender/3.4/scripts/addons/whitted_blender/__init__.py"))
assert g[2][1] == [], g
# WHITTED_PYTHONPATH folders come first, in their order; sys.path next, as given
g = near("/x/whitted_blender/__init__.py", {"WHITTED_PYTHONPATH": os.pathsep.join(["/a", "", "/b"])}, ["/s1", "", "/s2"])
assert g[0][1] == ["/a", "/b"] and g[1][1] == ["/s1", "/s2"], g

# A source checkout: its build*/python folders, sorted; also through a symlink from Blender's
# user add-ons folder to the checkout (realpath)
with tempfile.TemporaryDirectory() as d:
    addon = os.path.join(d, "src", "plugins", "blender", "whitted_blender")
    os.makedirs(addon)
    for b in ("build-asan", "build"):
        os.makedirs(os.path.join(d, "src", b, "python"))
    os.makedirs(os.path.join(d, "src", "buildnothing"))  # no python folder: not listed
    expect = [os.path.join(d, "src", "build", "python"), os.path.join(d, "src", "build-asan", "python")]
    g = near(os.path.join(addon, "__init__.py"))
    assert g[2][1] == expect, g
    user = os.path.join(d, "config", "scripts", "addons")
    os.makedirs(user)
    os.symlink(addon, os.path.join(user, "whitted_blender"))
    g = near(os.path.join(user, "whitted_blender", "__init__.py"))
    assert g[2][1] == expect, g

    # Not found anywhere: ModuleNotFound names every folder and WHITTED_PYTHONPATH
    env_dir = os.path.join(d, "env")
    os.makedirs(env_dir)
    sys.modules.pop("whitted", None)
    try:
        locate.import_whitted(os.path.join(addon, "__init__.py"), {"WHITTED_PYTHONPATH": env_dir}, ["/nonexistent"])
        raise AssertionError("imported a module that is nowhere")
    except locate.ModuleNotFound as e:
        msg = str(e)
    for f in [env_dir, "/nonexistent"] + expect:
        assert f in msg, (f, msg)
    assert "Set WHITTED_PYTHONPATH" in msg and f"Python {v[6:]}" in msg, msg
    # A module that is found but fails to load (built for another Python, a missing library):
    # the message says which file and why, and the search goes on
    with open(os.path.join(env_dir, "whitted.py"), "w") as f:
        f.write("raise ImportError('libwhitted.so.0: cannot open shared object file')\n")
    try:
        locate.import_whitted(os.path.join(addon, "__init__.py"), {"WHITTED_PYTHONPATH": env_dir}, [])
        raise AssertionError("a failing module was accepted")
    except locate.ModuleNotFound as e:
        msg = str(e)
    assert f"Found {os.path.join(env_dir, 'whitted.py')} but importing it failed: ImportError: libwhitted.so.0" in msg, msg
    assert "whitted" not in sys.modules
    # ... and a loadable one later in the order is taken: the first build tree's
    with open(os.path.join(expect[0], "whitted.py"), "w") as f:
        f.write("WHERE = 'build'\n")
    m = locate.import_whitted(os.path.join(addon, "__init__.py"), {"WHITTED_PYTHONPATH": env_dir}, [])
    assert m.WHERE == "build" and sys.modules["whitted"] is m, m
    sys.modules.pop("whitted")
print("blender.locate: prefix, user folder, build tree (also via symlink) and search order checked")
