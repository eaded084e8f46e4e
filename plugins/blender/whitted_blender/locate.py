"""Find and import the `whitted` Python module for the add-on (docs/blender.md, Install).

No `bpy` here, so the search order can be tested with plain Python. The add-on and the module
are installed separately (the add-on in Blender's scripts folder, the module in a Python
folder), so the add-on looks, in order: in the WHITTED_PYTHONPATH folders; on sys.path; then
in the folders its own location implies (PREFIX/share/blender/scripts/addons/whitted_blender
-> PREFIX/lib/python3.X/..., a source checkout's plugins/blender/whitted_blender -> the
checkout's build*/python).
"""
import glob
import importlib.machinery
import importlib.util
import os
import sys

MODULE = "whitted"


class ModuleNotFound(ImportError):
    """The `whitted` module is not in any searched folder, or failed to load; the message says
    where the add-on looked and what to set or install."""


def _python_folders(prefix):
    """Where an install under `prefix` puts a Python module for the running Python."""
    v = f"python{sys.version_info.major}.{sys.version_info.minor}"
    lib = os.path.join(prefix, "lib")
    return [os.path.join(lib, v, "dist-packages"), os.path.join(lib, "python3", "dist-packages"),
            os.path.join(lib, v, "site-packages")]


def _near_addon(addon_dir):
    """Folders implied by where the add-on is: its install prefix's Python folders, or the
    build trees next to the source checkout it was run from."""
    folders = []
    parts = addon_dir.split(os.sep)
    # PREFIX/share/blender/scripts/addons/whitted_blender (the .deb, `cmake --install`)
    if len(parts) >= 5 and parts[-5:-1] == ["share", "blender", "scripts", "addons"]:
        folders += _python_folders(os.sep.join(parts[:-5]) or os.sep)
    # CHECKOUT/plugins/blender/whitted_blender: CHECKOUT/build*/python, sorted by the build
    # folder's name for a stable order (build before build-asan)
    if len(parts) >= 3 and parts[-3:-1] == ["plugins", "blender"]:
        checkout = os.sep.join(parts[:-3]) or os.sep
        folders += sorted(glob.glob(os.path.join(glob.escape(checkout), "build*", "python")),
                          key=lambda f: os.path.basename(os.path.dirname(f)))
    return folders


def search_folders(addon_file, environ=None, path=None):
    """[(what, [folders])] in search order: WHITTED_PYTHONPATH, sys.path, near the add-on.

    The add-on's location is taken both as given and with symlinks resolved (an add-on folder
    linked into Blender's user add-ons from a source checkout finds that checkout's build).
    """
    environ = os.environ if environ is None else environ
    path = sys.path if path is None else path
    env = [p for p in environ.get("WHITTED_PYTHONPATH", "").split(os.pathsep) if p]
    addon_dir = os.path.dirname(os.path.abspath(addon_file))
    near = []
    for d in (addon_dir, os.path.realpath(addon_dir)):
        for f in _near_addon(d):
            if f not in near:
                near.append(f)
    return [("WHITTED_PYTHONPATH", env), ("sys.path", [p for p in path if p]), ("near the add-on", near)]


def not_found_message(groups, failures=()):
    """What the user reads at F12 and in the add-on's preferences: every folder searched, and what
    to set or install."""
    v = f"{sys.version_info.major}.{sys.version_info.minor}"
    lines = [f"Whitted: cannot import the '{MODULE}' Python module (Blender runs Python {v}; the "
             f"module must be built for it)."]
    for path, error in failures:
        lines.append(f"Found {path} but importing it failed: {error}")
    for what, folders in groups:
        if what == "WHITTED_PYTHONPATH" and not folders:
            lines.append("Looked in WHITTED_PYTHONPATH: not set.")
        else:
            lines.append(f"Looked in {what}: " + (", ".join(folders) if folders else "(none)") + ".")
    lines.append("Set WHITTED_PYTHONPATH to the folder holding whitted*.so (a build tree's "
                 "build/python) before starting Blender, or install Whitted (the .deb, or "
                 "`cmake --install` to the prefix whose share/blender/scripts/addons holds this add-on).")
    return "\n".join(lines)


def import_whitted(addon_file, environ=None, path=None):
    """The `whitted` module, searched for in search_folders' order; raises ModuleNotFound.

    Each group is searched with PathFinder (sys.path is left as it is: a prefix's whole
    dist-packages is not added to Blender's path, only this one module is loaded from it).
    """
    if MODULE in sys.modules:
        return sys.modules[MODULE]
    groups = search_folders(addon_file, environ, path)
    failures = []
    for _, folders in groups:
        spec = importlib.machinery.PathFinder.find_spec(MODULE, folders)
        if spec is None:
            continue
        module = importlib.util.module_from_spec(spec)
        sys.modules[MODULE] = module
        try:
            spec.loader.exec_module(module)
        except Exception as e:  # a module built for another Python, a missing libwhitted.so, NumPy
            del sys.modules[MODULE]
            failures.append((spec.origin, f"{type(e).__name__}: {e}"))
            continue
        return module
    raise ModuleNotFound(not_found_message(groups, failures))
