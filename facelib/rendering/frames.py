"""Rendering FAP animations of a face: frames in memory, MP4 with speech, GIF, PNG stills.

``render`` plays a :class:`~facelib.mpeg4.stream.FapStream`, an animation or a
:class:`~facelib.clip.Clip` (each made into a Clip at the entry: stream, face, audio, camera
moves) on a face and returns or writes the frames; ``render_still`` renders one pose.
OpenGL and pyrender load on first use, on the headless platform chosen by
:mod:`facelib.rendering.platform`.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from facelib.clip import Clip, make_clip, resolve_face
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import N_FAPS
from facelib.progress import ProgressCallback, progress_callback
from facelib.rendering.camera import CameraTrack, camera_of
from facelib.rendering.protocols import Deformable, HasFaps
from facelib.rendering.scene import FaceRenderer
from facelib.rendering.video import save_png, write_video

__all__ = ["face_or_default", "iter_frames", "render", "render_still", "save_png",
           "speech_audio_file", "stream_of"]

_CHUNK = 32  # frames deformed at once: bounds memory to 32 x V x 3 floats


def stream_of(source: FapStream | HasFaps | Clip) -> tuple[FapStream, Path | None, float]:
    """``(stream, audio path or None, audio offset in seconds)`` of a render source (see
    :func:`facelib.clip.make_clip`; kept for callers of earlier versions)."""
    clip = make_clip(source, storyboard_face=False, storyboard_hair=False)
    return clip.stream, clip.audio, clip.audio_offset


def speech_audio_file(clip: Clip, path: Path) -> Path | None:
    """Write ``clip.speech`` (synthesized speech) to ``path`` as 16-bit WAV and return it;
    None when the clip has none."""
    if clip.speech is None:
        return None
    import soundfile

    soundfile.write(str(path), clip.speech.samples, clip.speech.sample_rate,
                    subtype="PCM_16")
    return path


def face_or_default(face: Deformable | str | os.PathLike[str] | None,
                    source: object = None) -> Deformable:
    """``face``; a face definition JSON path loaded; None: the face the source's storyboard
    names (``face = "..."``), else facelib's default head."""
    if face is None and source is not None:
        return make_clip(source).face_or_default()
    return resolve_face(face)


def iter_frames(
    renderer: FaceRenderer, face: Deformable, stream: FapStream, *,
    progress: bool | ProgressCallback | None = False, camera: CameraTrack | None = None,
) -> Iterator[np.ndarray]:
    """Yield one ``(H, W, 3) uint8`` image per frame of ``stream`` deformed by ``face``.

    ``progress``: see :mod:`facelib.progress`; called with (frames done, n_frames).
    ``camera``: a camera per frame (storyboard camera cues), or None to keep the renderer's.
    """
    report = progress_callback(progress, "rendering", unit="frames")
    done = 0
    for start in range(0, stream.n_frames, _CHUNK):
        vertices = np.asarray(face.deform(stream[start : start + _CHUNK]), np.float32)
        for frame_vertices in vertices:
            if camera is not None:
                renderer.set_camera(camera.poses[done], znear=camera.znear[done],
                                    zfar=camera.zfar[done])
            # the frame's FAPs deepen the skin's wrinkles (facelib/rendering/skin_map.py)
            yield renderer.frame(frame_vertices, faps=stream.values[done])
            done += 1
            if report is not None:
                report(done, stream.n_frames)


def render(
    source: FapStream | HasFaps | Clip,
    *,
    face: Deformable | str | os.PathLike[str] | None = None,
    out: str | os.PathLike[str] | None = None,
    width: int = 640,
    height: int = 480,
    audio: str | os.PathLike[str] | None = None,
    audio_offset: float | None = None,
    background: Sequence[float] | None = None,
    progress: bool | ProgressCallback | None = True,
    fps: float | None = None,
    framing: str | np.ndarray = "face",
) -> np.ndarray | Path:
    """Render an animation of ``face`` driven by ``source``.

    Parameters
    ----------
    source: a :class:`FapStream`, an animation with ``.faps`` (and optional ``.audio``,
        ``.audio_offset``, ``.speech_audio``), or a :class:`~facelib.clip.Clip`.
    face: the face to deform (``Face``-like: ``vertices``, ``triangles``, ``vertex_colors``,
        ``parts``, ``deform``) or a face definition JSON path; None takes the face the
        storyboard names (``face = "..."``), else the default head.
    out: None returns the frames; a path writes them by suffix: ``.mp4`` (H.264, with the
        audio), ``.gif``, or a folder (no suffix) of ``frame_NNNNNN.png``; ``.png`` writes a
        single-frame source as one still.
    width, height: image size in pixels (even for ``.mp4``).
    audio: speech to mux into an ``.mp4`` (overrides ``source.audio``); it starts
        ``audio_offset`` seconds into the video (default ``source.audio_offset`` or 0):
        the audio rule of :mod:`facelib.clip`.
    background: sRGB colour behind the face (None: the look's). framing: see FaceRenderer.
    progress: True reports on stderr, None/False is silent, a callable gets ``(frames_done,
        n_frames)``. fps: resample the stream to this rate first (None keeps the stream's).

    Returns ``(n_frames, height, width, 3) uint8`` RGB frames when ``out`` is None, else the
    written path. The camera frames the neutral face; storyboard camera cues move it.
    """
    own = make_clip(source, face=face)
    clip = make_clip(own, audio=audio, audio_offset=audio_offset)
    clip = clip if fps is None else clip.resampled(fps)
    stream, face = clip.stream, clip.face_or_default()
    if out is not None and Path(out).suffix.lower() == ".png":
        return _one_png(face, stream, out, width=width, height=height, background=background,
                        framing=framing)
    if out is None and audio is not None and own.audio is None:
        raise ParameterError("audio is only used when writing an .mp4 (give out=...)")
    mp4 = out is not None and Path(out).suffix.lower() == ".mp4"
    with tempfile.TemporaryDirectory(prefix="facelib-speech-") as folder:
        sound = clip.audio
        if sound is None and mp4:
            sound = speech_audio_file(clip, Path(folder) / "speech.wav")
        with FaceRenderer(face, width=width, height=height, background=background,
                          framing=framing) as renderer:
            frames = iter_frames(renderer, face, stream, progress=progress,
                                 camera=camera_of(clip, renderer, face, framing=framing))
            if out is None:
                return _collect(frames, stream.n_frames, renderer.height, renderer.width)
            return write_video(frames, out, fps=stream.fps, width=width, height=height,
                               audio=sound if mp4 else None, audio_offset=clip.audio_offset,
                               duration=stream.duration)


def _collect(frames: Iterator[np.ndarray], n_frames: int, height: int, width: int
             ) -> np.ndarray:
    """``(n_frames, height, width, 3) uint8``: the frames in one preallocated array."""
    result = np.empty((n_frames, height, width, 3), np.uint8)
    for i, image in enumerate(frames):
        result[i] = image
    return result


def _one_png(
    face: Deformable, stream: FapStream, out: str | os.PathLike[str], *, width: int,
    height: int, background: Sequence[float] | None, framing: str | np.ndarray = "face",
) -> Path:
    """A single-frame stream rendered to the PNG ``out``."""
    if stream.n_frames != 1:
        raise ParameterError(
            f"{Path(out).name!r} is one PNG but the stream has {stream.n_frames} frames; "
            "give a folder to write one PNG per frame"
        )
    return save_png(render_still(face, stream.values[0], width=width, height=height,
                                 background=background, framing=framing), out)


def render_still(
    face: Deformable,
    pose: np.ndarray | None = None,
    *,
    width: int = 640,
    height: int = 480,
    background: Sequence[float] | None = None,
    framing: str | np.ndarray = "face",
) -> np.ndarray:
    """One ``(height, width, 3) uint8`` image of ``face`` (``framing`` as in :func:`render`).

    ``pose`` is an ``(84,)`` FAP vector (deformed with ``face.deform_frame``), a ``(V, 3)``
    vertex array, or None for the neutral face. For many stills of one face, keep a
    :class:`~facelib.rendering.scene.FaceRenderer` open instead (one OpenGL context).
    """
    face = face_or_default(face)
    faps = None
    if pose is None:
        vertices = np.asarray(face.vertices, np.float32)
    else:
        pose = np.asarray(pose, np.float32)
        if pose.shape == (N_FAPS,):
            vertices = np.asarray(face.deform_frame(pose), np.float32)
            faps = pose
        elif pose.ndim == 2 and pose.shape[1] == 3:
            vertices = pose
        else:
            raise ParameterError(
                f"pose must be ({N_FAPS},) FAP values or (V, 3) vertices, got {pose.shape}"
            )
    with FaceRenderer(face, width=width, height=height, background=background,
                      framing=framing) as renderer:
        return renderer.frame(vertices, faps=faps)
