"""Which OpenGL platform renders offscreen, and importing pyrender on it.

PyOpenGL picks its platform (GLX, EGL, OSMesa) once, when ``OpenGL`` is first imported, from
the ``PYOPENGL_PLATFORM`` environment variable. This module decides that variable for
offscreen rendering *before* anything imports OpenGL, and nowhere else in facelib touches
it:

1. a ``PYOPENGL_PLATFORM`` the user already set (``egl`` or ``osmesa``) is respected;
2. EGL when ``libEGL`` loads and a GPU render node exists (``/dev/dri/renderD*`` or
   ``/dev/nvidia*``): hardware rendering without a display;
3. OSMesa when ``libOSMesa`` loads (Debian/Ubuntu: ``libosmesa6``): software rendering on any
   CPU machine;
4. EGL through Mesa's software driver when only ``libEGL`` loads;
5. otherwise :class:`~facelib.errors.RenderError` naming the packages to install.

The pyrender fork is ``pyrender2`` (imports as ``pyrender``); see ``docs/rendering.md`` for
why it was chosen over upstream pyrender and ``pyrender-maintained``.
"""

from __future__ import annotations

import ctypes.util
import os
import sys
from pathlib import Path
from types import ModuleType

from facelib.errors import RenderError
from facelib.optional import missing_extra, require

__all__ = ["INSTALL_HINT", "choose_platform", "import_pyrender"]

INSTALL_HINT = (
    "install an OpenGL platform for headless rendering: on Debian/Ubuntu "
    "'apt-get install libosmesa6' (software, any machine) or 'libegl1' with a GPU driver; "
    "then 'pip install \"facelib[render]\"'"
)
_PLATFORMS = ("egl", "osmesa")


def _loads(name: str) -> bool:
    """Whether the shared library ``lib<name>`` can be found and loaded."""
    path = ctypes.util.find_library(name)
    candidates = [path] if path else []
    candidates += [f"lib{name}.so.1", f"lib{name}.so.8", f"lib{name}.so"]
    for candidate in candidates:
        try:
            ctypes.CDLL(candidate)
        except OSError:
            continue
        return True
    return False


def _has_gpu_node() -> bool:
    dev = Path("/dev")
    return any(dev.glob("dri/renderD*")) or any(dev.glob("nvidia[0-9]*"))


def choose_platform() -> str:
    """The headless OpenGL platform to use: ``'egl'`` or ``'osmesa'`` (see module docs).

    Sets ``PYOPENGL_PLATFORM`` when it is not set yet and OpenGL is not imported yet.
    Raises :class:`RenderError` naming what to install when no platform is usable.
    """
    if "OpenGL" in sys.modules:
        current = _imported_platform()
        if current not in _PLATFORMS:
            raise RenderError(
                f"OpenGL was already imported on the {current!r} platform, which cannot "
                "render offscreen; render in a fresh process, or set PYOPENGL_PLATFORM=egl "
                "or osmesa before anything imports OpenGL"
            )
        return current
    chosen = os.environ.get("PYOPENGL_PLATFORM", "").strip().lower()
    if chosen:
        if chosen not in _PLATFORMS:
            raise RenderError(
                f"PYOPENGL_PLATFORM={chosen!r} cannot render offscreen; unset it or use "
                "'egl' or 'osmesa'"
            )
        return chosen
    has_egl, has_osmesa = _loads("EGL"), _loads("OSMesa")
    if has_egl and _has_gpu_node():
        chosen = "egl"
    elif has_osmesa:
        chosen = "osmesa"
    elif has_egl:
        chosen = "egl"
    else:
        raise RenderError(f"neither libEGL nor libOSMesa can be loaded; {INSTALL_HINT}")
    os.environ["PYOPENGL_PLATFORM"] = chosen
    return chosen


def _imported_platform() -> str:
    platform = sys.modules.get("OpenGL.platform")
    name = type(getattr(platform, "PLATFORM", None)).__name__.lower()
    for known in ("egl", "osmesa", "glx", "wgl", "darwin"):
        if known in name:
            return known
    return os.environ.get("PYOPENGL_PLATFORM", "glx").lower() or "glx"


def import_pyrender(*, offscreen: bool = True) -> ModuleType:
    """Import and return ``pyrender`` (after :func:`choose_platform` when ``offscreen``).

    Raises :class:`MissingExtraError` when pyrender or PyOpenGL is not installed and
    :class:`RenderError` when the OpenGL platform libraries are missing.
    """
    if offscreen:
        choose_platform()
    require("opengl")  # PyOpenGL, the platform binding
    try:
        import pyrender
    except ImportError as exc:
        if "pyrender" in str(exc) and getattr(exc, "name", "") == "pyrender":
            raise missing_extra("pyrender") from exc
        raise RenderError(f"pyrender could not load its OpenGL platform ({exc}); {INSTALL_HINT}") \
            from exc
    except Exception as exc:  # PyOpenGL raises plain errors when a platform library is absent
        raise RenderError(f"pyrender could not load its OpenGL platform ({exc}); {INSTALL_HINT}") \
            from exc
    return pyrender
