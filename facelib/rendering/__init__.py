"""Rendering a deformed face: headless OpenGL platform, scene, frame loop, video, viewer.

Everything here needs the ``render`` extra (pyrender, PyOpenGL, imageio-ffmpeg); it is never
imported by ``import facelib`` and loads on first use of ``facelib.render`` and friends.

- :mod:`~facelib.rendering.platform`: OSMesa or EGL, chosen once; clear errors if missing.
- :mod:`~facelib.rendering.scene`: :class:`FaceRenderer`, the look, lights and camera framing.
- :mod:`~facelib.rendering.frames`: ``render`` and ``render_still`` (frames, MP4, GIF, PNGs).
- :mod:`~facelib.rendering.video`: encoding with the bundled ffmpeg, PNG stills.
- :mod:`~facelib.rendering.viewer`: a window that plays a stream (needs a display).
"""

from facelib.rendering.frames import iter_frames, render, render_still, save_png, stream_of
from facelib.rendering.protocols import Deformable, HasFaps
from facelib.rendering.scene import FaceRenderer

__all__ = ["Deformable", "FaceRenderer", "HasFaps", "iter_frames", "render", "render_still",
           "save_png", "stream_of"]
