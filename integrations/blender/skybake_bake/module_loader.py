"""Finding the compiled skybake module.

Order: a plain `import skybake` (it is on Blender's sys.path already), then
the folder set in the add-on preferences, then the folders in the
environment variable SKYBAKE_PYTHONPATH (os.pathsep-separated). Each folder
is the one that holds the `skybake` package (build/python in a build tree).
The module is cached once found; a failure is retried after RETRY_SECONDS
(a rebuild may have left the .so half-written) or at once after reset()
(called when the preference changes). backends() caches the usable
visibility backends: probing them opens an OpenGL context, too slow for
every redraw of the panel.
"""

import importlib
import os
import sys
import time

ENV_VAR = "SKYBAKE_PYTHONPATH"
ADDON_ID = __package__
RETRY_SECONDS = 5.0

_module = None
_problem = None
_tried_at = None  # time.monotonic() of the last failed attempt
_backends = None


def _preference_path():
    import bpy

    addon = bpy.context.preferences.addons.get(ADDON_ID)
    if addon is None or addon.preferences is None:
        return ""
    return bpy.path.abspath(addon.preferences.module_path or "").strip()


def _forget_partial_import():
    for name in [n for n in sys.modules if n == "skybake" or n.startswith("skybake.")]:
        del sys.modules[name]


def _try_import(folder=None):
    """The module, or raises. With a folder, imports from there first."""
    if folder:
        folder = os.path.abspath(os.path.expanduser(folder))
        if not os.path.isdir(os.path.join(folder, "skybake")):
            raise ImportError(f"no 'skybake' package in {folder}")
        if folder in sys.path:
            sys.path.remove(folder)
        sys.path.insert(0, folder)
    _forget_partial_import()
    importlib.invalidate_caches()
    module = importlib.import_module("skybake")
    if not hasattr(module, "bake_ao"):
        raise ImportError(f"'skybake' at {getattr(module, '__file__', '?')} is not the skybake module")
    return module


def reset():
    global _module, _problem, _tried_at, _backends
    _module, _problem, _tried_at, _backends = None, None, None, None


def get():
    """The skybake module, or None (then problem() says why)."""
    global _module, _problem, _tried_at
    if _module is not None:
        return _module
    if _tried_at is not None and time.monotonic() - _tried_at < RETRY_SECONDS:
        return None
    attempts = [("import skybake", None)]
    pref = _preference_path()
    if pref:
        attempts.append((f"preference path {pref}", pref))
    for folder in filter(None, os.environ.get(ENV_VAR, "").split(os.pathsep)):
        attempts.append((f"{ENV_VAR} {folder}", folder))
    errors = []
    for label, folder in attempts:
        try:
            _module = _try_import(folder)
            _problem = None
            return _module
        except Exception as e:  # ImportError, OSError from a half-written .so, ...
            errors.append(f"{label}: {e}")
            _forget_partial_import()
    _module = None
    _problem = errors
    _tried_at = time.monotonic()
    return None


def backends():
    """[(name, available, problem, summary)] of the module's registered visibility backends, probed once;
    [] without the module."""
    global _backends
    sb = get()
    if sb is None:
        return []
    if _backends is None:
        try:
            _backends = [(b.name, b.available, b.problem, f"{b.summary} (on {b.device})")
                         for b in sb.backends()]
        except Exception as e:
            _backends = [("embree", True, "", ""), ("_error", False, str(e), "")]
    return _backends


def problem():
    """One line for the UI: what to set so that the module imports."""
    get()
    if _module is not None:
        return ""
    return ("skybake module not found: set Preferences > Add-ons > skybake > Module folder "
            f"(the folder holding the 'skybake' package, e.g. build/python) or {ENV_VAR}")


def problem_details():
    get()
    return "; ".join(_problem or [])
