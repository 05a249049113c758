"""Reading a rendered frame back: the colour only.

pyrender's offscreen renderer reads back the depth buffer with every frame: it resolves the
multisampled depth into a second framebuffer, reads it as floats and turns it into linear
depth with numpy (several full-frame passes), only for :class:`~facelib.rendering.scene.
FaceRenderer` to throw it away. :func:`install_colour_readback` makes one pyrender renderer
resolve and read the colour alone; its ``render`` then returns ``(colour, None)``.
"""

from __future__ import annotations

import types
from typing import Any

import numpy as np

__all__ = ["install_colour_readback"]


def _read_colour(renderer: Any, scene: Any, flags: int) -> tuple[np.ndarray, None]:
    """``(H, W, 3) uint8`` RGB of the multisampled main framebuffer, top row first."""
    from OpenGL import GL

    width, height = renderer._main_fb_dims
    GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, renderer._main_fb_ms)
    GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, renderer._main_fb)
    GL.glBlitFramebuffer(0, 0, width, height, 0, 0, width, height,
                         GL.GL_COLOR_BUFFER_BIT, GL.GL_LINEAR)
    GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, renderer._main_fb)
    return _pixels(width, height), None


def _pixels(width: int, height: int) -> np.ndarray:
    from OpenGL import GL

    GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
    raw = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
    return np.frombuffer(raw, np.uint8).reshape(height, width, 3)[::-1]


def install_colour_readback(offscreen: Any) -> None:
    """Make ``offscreen`` (a ``pyrender.OffscreenRenderer``) read back colour only.

    Where its platform renders into framebuffers (EGL, or OSMesa with MSAA on), the
    multisampled colour is resolved and read, and the depth neither resolved nor read;
    elsewhere (OSMesa's own buffer) the depth read is skipped. The images are the same as
    pyrender's, bit for bit.
    """
    inner = offscreen._renderer
    inner._read_main_framebuffer = types.MethodType(_read_colour, inner)
    inner.read_depth_buf = lambda: None
