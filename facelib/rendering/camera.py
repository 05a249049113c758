"""Camera moves over a render: a storyboard's ``camera`` cues as one camera pose per frame.

A cue names a framing of the look (``face``, ``head``, ``bust``) and a start; the camera cuts
there, or with a duration moves from where it was to the new framing, easing in and out
(smoothstep of the elapsed share). Every framed camera looks along -z, so a move is the
camera position's path; the clipping planes span both ends of the move. The cues come typed
with the :class:`~facelib.clip.Clip` (:class:`~facelib.clip.CameraMove`), so this module
needs neither the storyboard layer nor Lua.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from facelib.clip import CameraMove, Clip
from facelib.errors import ParameterError
from facelib.rendering.scene import FaceRenderer, frame_camera, framing_points

__all__ = ["CameraTrack", "camera_of", "camera_track"]


@dataclass(frozen=True, eq=False)
class CameraTrack:
    """Per-frame camera: ``poses (n, 4, 4) float64`` (camera to face coordinates),
    ``znear``, ``zfar`` ``(n,) float64`` clipping distances in the face's units."""

    poses: np.ndarray
    znear: np.ndarray
    zfar: np.ndarray


def _framed(renderer: FaceRenderer, face: Any, framing: str | np.ndarray
            ) -> tuple[np.ndarray, float, float]:
    """The camera that frames ``framing`` (a look's framing name, or ``(k, 3)`` points to
    frame) on ``face``: ``(4, 4)`` pose (camera to face coordinates), znear, zfar."""
    points = (framing_points(face, framing, look=renderer.look) if isinstance(framing, str)
              else np.asarray(framing, np.float32))
    return frame_camera(points, aspect=renderer.width / renderer.height,
                        yfov=float(np.radians(renderer.look.yfov_deg)),
                        margin=renderer.look.margin,
                        scene_vertices=np.asarray(face.vertices, np.float32))


def _targets(renderer: FaceRenderer, face: Any, cues: Sequence[CameraMove]
             ) -> dict[str, tuple[np.ndarray, float, float]]:
    """The framed camera (pose, znear, zfar) of each framing the ``cues`` name;
    ParameterError, with the cue's storyboard file and line where it has them, for a
    framing the look does not have."""
    targets: dict[str, tuple[np.ndarray, float, float]] = {}
    for cue in cues:
        name = str(cue.framing)
        if name not in renderer.look.framings:
            path, line = cue.origin or (None, None)
            raise ParameterError(f"camera cue framing {name!r} is not one of "
                                 f"{tuple(renderer.look.framings)}", path=path, line=line)
        targets.setdefault(name, _framed(renderer, face, name))
    return targets


def camera_track(renderer: FaceRenderer, face: Any, cues: Sequence[CameraMove], *,
                 n_frames: int, fps: float, framing: str | np.ndarray) -> CameraTrack:
    """One camera per frame of an ``n_frames`` render at ``fps``: ``framing`` until the
    first cue, then each cue's cut or move (see the module docstring)."""
    start = _framed(renderer, face, framing)
    targets = _targets(renderer, face, cues)
    times = np.arange(n_frames) * 1000.0 / fps
    pos = np.tile(start[0][:3, 3], (n_frames, 1))
    near = np.full(n_frames, start[1])
    far = np.full(n_frames, start[2])
    for cue in sorted(cues, key=lambda c: int(c.start_ms)):
        pose, znear, zfar = targets[str(cue.framing)]
        begin, length = float(cue.start_ms), float(cue.duration_ms)
        live = times >= begin
        if not live.any():
            continue
        origin = pos[np.argmax(live)].copy()
        share = (np.clip((times[live] - begin) / length, 0.0, 1.0) if length > 0
                 else np.ones(int(live.sum())))
        ease = (share * share * (3.0 - 2.0 * share))[:, None]
        pos[live] = origin + ease * (pose[:3, 3] - origin)
        moving = share < 1.0
        near[live] = np.where(moving, np.minimum(near[live], znear), znear)
        far[live] = np.where(moving, np.maximum(far[live], zfar), zfar)
    poses = np.tile(np.eye(4), (n_frames, 1, 1))
    poses[:, :3, 3] = pos
    return CameraTrack(poses, near, far)


def camera_of(clip: Clip, renderer: FaceRenderer, face: Any, *,
              framing: str | np.ndarray) -> CameraTrack | None:
    """The camera track of ``clip``'s camera moves over its stream; None without moves."""
    if not clip.camera:
        return None
    return camera_track(renderer, face, clip.camera, n_frames=clip.n_frames, fps=clip.fps,
                        framing=framing)
