"""Choosing the OpenGL platform, and the clear errors when none is usable.

These run in fresh interpreters: PyOpenGL fixes its platform at first import.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.render

ROOT = Path(__file__).resolve().parents[2]


def _run(code: str, **env: str) -> subprocess.CompletedProcess:
    environ = {k: v for k, v in os.environ.items() if k != "PYOPENGL_PLATFORM"}
    environ.update(env)
    environ["PYTHONPATH"] = str(ROOT)
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, env=environ, cwd=ROOT, timeout=120, check=False)


def test_no_platform_library_gives_install_hint():
    result = _run("""
        import numpy as np
        from facelib.rendering import platform as render_backend
        from facelib.errors import RenderError
        render_backend._loads = lambda name: False
        from facelib.rendering.frames import render_still
        try:
            render_still(object(), np.zeros((3, 3)))
        except RenderError as exc:
            print("RenderError:", exc)
        """)
    assert result.returncode == 0, result.stderr
    assert "RenderError: neither libEGL nor libOSMesa" in result.stdout
    assert "libosmesa6" in result.stdout
    assert "Traceback" not in result.stdout + result.stderr


def test_on_screen_platform_is_refused_for_offscreen():
    result = _run("""
        from facelib.rendering.platform import choose_platform
        from facelib.errors import RenderError
        try:
            choose_platform()
        except RenderError as exc:
            print("RenderError:", exc)
        """, PYOPENGL_PLATFORM="glx")
    assert "RenderError: PYOPENGL_PLATFORM='glx' cannot render offscreen" in result.stdout


def test_missing_pyrender_names_the_extra():
    result = _run("""
        import sys
        sys.modules["pyrender"] = None  # as if pyrender2 were not installed
        from facelib.rendering.platform import import_pyrender
        from facelib.errors import MissingExtraError
        try:
            import_pyrender()
        except MissingExtraError as exc:
            print("MissingExtraError:", exc)
        """)
    assert "MissingExtraError:" in result.stdout
    assert "facelib[render]" in result.stdout and "pyrender2" in result.stdout


@pytest.mark.parametrize("platform", ["osmesa", "egl"])
def test_explicit_platform_is_respected(platform):
    result = _run("""
        import os
        from facelib.rendering.platform import import_pyrender, choose_platform
        import_pyrender()
        import OpenGL.platform
        print(choose_platform(), type(OpenGL.platform.PLATFORM).__name__)
        """, PYOPENGL_PLATFORM=platform)
    assert result.returncode == 0, result.stderr
    chosen, binding = result.stdout.split()
    assert chosen == platform and platform in binding.lower()


def test_import_facelib_render_modules_stays_light():
    result = _run("""
        import sys
        import facelib, facelib.rendering.frames, facelib.rendering.video
        heavy = [m for m in ("OpenGL", "pyrender", "pyglet", "imageio_ffmpeg")
                 if m in sys.modules]
        print("heavy:", heavy, "platform:", __import__("os").environ.get("PYOPENGL_PLATFORM"))
        """)
    assert result.returncode == 0, result.stderr
    assert "heavy: [] platform: None" in result.stdout


def test_view_without_display_says_so():
    result = _run("""
        import os
        from facelib.rendering.viewer import view
        from facelib.errors import RenderError
        from facelib.mpeg4.stream import FapStream
        try:
            view(FapStream.zeros(3, fps=25), face=object())
        except RenderError as exc:
            print("RenderError:", exc)
        """, DISPLAY="", WAYLAND_DISPLAY="")
    assert "RenderError: no display" in result.stdout, result.stderr
    assert "clip.mp4" in result.stdout
