"""Playing an animation in a desktop window (pyrender's pyglet viewer), in real time.

The window needs a display (X11 or Wayland) and the on-screen OpenGL platform, so ``view``
must run in a process that has not rendered offscreen yet (PyOpenGL binds one platform per
process). Without a display it raises :class:`~facelib.errors.RenderError` saying so.
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from facelib.errors import RenderError
from facelib.mpeg4.stream import FapStream
from facelib.rendering.frames import face_or_default, stream_of
from facelib.rendering.platform import import_pyrender
from facelib.rendering.protocols import Deformable, HasFaps
from facelib.rendering.scene import FaceRenderer

__all__ = ["has_display", "view"]


def has_display() -> bool:
    """Whether a window can be opened: Windows/macOS, or ``DISPLAY``/``WAYLAND_DISPLAY`` set."""
    if sys.platform in ("win32", "darwin"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def view(
    source: FapStream | HasFaps,
    *,
    face: Deformable | str | os.PathLike[str] | None = None,
    width: int = 800,
    height: int = 600,
    loop: bool = False,
) -> None:
    """Open a window that plays ``source`` (FapStream or animation with ``.faps``) on ``face``.

    Frames follow the wall clock (frames are skipped, never slowed, when rendering lags);
    the mouse orbits and zooms as in pyrender's viewer; closing the window stops playback.
    ``loop`` replays until the window is closed. Audio is not played. Blocks until the
    window closes or playback ends.
    """
    if not has_display():
        raise RenderError(
            "no display: DISPLAY and WAYLAND_DISPLAY are unset, so no window can open; "
            "render to a file instead, e.g. facelib.render(stream, out='clip.mp4') "
            "or 'facelib play FILE.fap -o clip.mp4'"
        )
    if os.environ.get("PYOPENGL_PLATFORM", "").lower() in ("egl", "osmesa") and (
        "OpenGL" in sys.modules
    ):
        raise RenderError(
            "this process already rendered offscreen (PyOpenGL is bound to "
            f"{os.environ['PYOPENGL_PLATFORM']!r}); open the viewer in a fresh process"
        )
    stream, _, _ = stream_of(source)
    face = face_or_default(face, source)
    pr = import_pyrender(offscreen=False)
    scene = FaceRenderer(face, width=width, height=height, mesh_update="swap", offscreen=False)
    try:
        viewer = pr.Viewer(
            scene.scene, viewport_size=(width, height), run_in_thread=True,
            window_title=f"facelib: {stream.n_frames} frames at {stream.fps:g} fps",
        )
    except Exception as exc:
        raise RenderError(f"could not open a window ({type(exc).__name__}: {exc})") from exc
    frames = np.asarray(face.deform(stream), np.float32) if stream.n_frames else None
    try:
        while frames is not None and viewer.is_active:
            start = time.perf_counter()
            shown = -1
            while viewer.is_active:
                index = int((time.perf_counter() - start) * stream.fps)
                if index >= stream.n_frames:
                    break
                if index != shown:
                    with viewer.render_lock:
                        scene.set_vertices(frames[index])
                    shown = index
                time.sleep(max(0.0, (index + 1) / stream.fps - (time.perf_counter() - start)))
            if not loop:
                break
        while viewer.is_active and not loop:
            time.sleep(0.05)
    finally:
        if viewer.is_active:
            viewer.close_external()
