"""Rendering a scene (a storyboard with characters): the two-shot and the close shots.

Each character has its own :class:`~facelib.rendering.scene.FaceRenderer` at the full image
size. A close shot is that character's renderer with its camera on the shot's framing. The
two-shot puts the characters side by side, left to right, each in a column of the image:
a column of width ``w`` is the centre of a full-width render whose camera frames the
character for the aspect ``w / height`` (with the same vertical field of view, the centre
``w`` columns of a wider image are what a ``w``-wide image would show). A character off
screen is not rendered (its stream still runs: it is alive when the camera comes back).
"""

from __future__ import annotations

import itertools
import os
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from facelib import data
from facelib.clip import SceneClip, make_scene_clip
from facelib.errors import ParameterError
from facelib.progress import ProgressCallback, progress_callback
from facelib.rendering.protocols import Deformable
from facelib.rendering.scene import FaceRenderer, frame_camera, framing_points
from facelib.rendering.video import open_writer

__all__ = ["columns", "iter_scene_frames", "render_scene"]

_CHUNK = 32  # frames deformed at once per character


def columns(width: int, count: int) -> list[tuple[int, int]]:
    """``[(first, stop), ...]``: the pixel columns of ``count`` side-by-side characters in
    an image ``width`` pixels wide, left to right."""
    edges = [round(k * width / count) for k in range(count + 1)]
    return list(itertools.pairwise(edges))


Camera = tuple[np.ndarray, float, float]


def _camera(renderer: FaceRenderer, face: Deformable, framing: str, aspect: float) -> Camera:
    """The camera (pose, znear, zfar) framing ``framing`` on ``face`` for ``aspect``."""
    if framing not in renderer.look.framings:
        raise ParameterError(f"framing {framing!r} is not one of "
                             f"{tuple(renderer.look.framings)}")
    return frame_camera(framing_points(face, framing, look=renderer.look), aspect=aspect,
                        yfov=float(np.radians(renderer.look.yfov_deg)),
                        margin=renderer.look.margin,
                        scene_vertices=np.asarray(face.vertices, np.float32))


def _two_shot_camera(renderer: FaceRenderer, face: Deformable, aspect: float) -> Camera:
    """The camera framing ``face`` in a two-shot column of ``aspect`` (``render_shots.json``:
    its face framing's box, grown and moved down, so every character has the same scale)."""
    rule = data.json_data("render_shots.json")["two_shot"]
    points = framing_points(face, str(rule["points"]), look=renderer.look)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0 * float(rule["scale"])
    centre[1] -= float(rule["drop"]) * (hi[1] - lo[1])
    box = np.stack([centre - half, centre + half]).astype(np.float32)
    return frame_camera(box, aspect=aspect, yfov=float(np.radians(renderer.look.yfov_deg)),
                        margin=1.0, scene_vertices=np.asarray(face.vertices, np.float32))


def _deformed(scene: SceneClip, faces: Sequence[Deformable]) -> Iterator[list[np.ndarray]]:
    """Per frame, every character's ``(V, 3) float32`` vertices (deformed in chunks)."""
    for start in range(0, scene.n_frames, _CHUNK):
        chunks = [np.asarray(face.deform(clip.stream[start:start + _CHUNK]), np.float32)
                  for face, clip in zip(faces, scene.clips, strict=True)]
        for k in range(chunks[0].shape[0]):
            yield [chunk[k] for chunk in chunks]


def iter_scene_frames(
    scene: SceneClip, renderers: Sequence[FaceRenderer], faces: Sequence[Deformable], *,
    framing: str = "face", progress: bool | ProgressCallback | None = False,
) -> Iterator[np.ndarray]:
    """Yield one ``(H, W, 3) uint8`` image per frame of ``scene``: the shot of the frame
    (:meth:`SceneClip.shot_per_frame`) made of the characters' renders. ``renderers`` and
    ``faces``: one per character, in ``scene.names`` order, all the same size; ``framing``:
    the framing of the two-shot and of close shots that name none."""
    width, height = renderers[0].width, renderers[0].height
    cols = columns(width, len(renderers))
    two_shot = [_two_shot_camera(r, f, (stop - first) / height)
                for r, f, (first, stop) in zip(renderers, faces, cols, strict=True)]
    close: dict[tuple[str, str], Camera] = {}
    for shot in scene.shots:
        if shot.who is not None:
            k = scene.names.index(shot.who)
            key = (shot.who, shot.framing or framing)
            if key not in close:
                close[key] = _camera(renderers[k], faces[k], key[1], width / height)
    shot_of = scene.shot_per_frame()
    report = progress_callback(progress, "rendering", unit="frames")
    image = np.empty((height, width, 3), np.uint8)
    for i, vertices in enumerate(_deformed(scene, faces)):
        who = None if shot_of[i] < 0 else scene.shots[shot_of[i]].who
        if who is None:
            for k, (first, stop) in enumerate(cols):
                pose, znear, zfar = two_shot[k]
                renderers[k].set_camera(pose, znear=znear, zfar=zfar)
                full = renderers[k].frame(vertices[k], faps=scene.clips[k].stream.values[i])
                left = (width - (stop - first)) // 2
                image[:, first:stop] = full[:, left:left + stop - first]
        else:
            shot = scene.shots[shot_of[i]]
            k = scene.names.index(who)
            pose, znear, zfar = close[(who, shot.framing or framing)]
            renderers[k].set_camera(pose, znear=znear, zfar=zfar)
            # the frame's FAPs deepen the skin's wrinkles, as in a render of one face
            image[:] = renderers[k].frame(vertices[k], faps=scene.clips[k].stream.values[i])
        yield image.copy()
        if report is not None:
            report(i + 1, scene.n_frames)


def render_scene(
    source: SceneClip | object,
    *,
    out: str | os.PathLike[str] | None = None,
    width: int = 640,
    height: int = 480,
    framing: str = "face",
    background: Sequence[float] | None = None,
    progress: bool | ProgressCallback | None = True,
) -> np.ndarray | Path:
    """Render a scene: a :class:`~facelib.clip.SceneClip` or an animation of a storyboard
    with characters (:func:`facelib.animate_scene`'s :class:`~facelib.Scene`).

    The camera shows the two-shot (every character side by side, left to right) until
    the first cut, then each cut's shot (module docstring). ``framing`` frames the
    two-shot and the close shots that name none. ``out``: None returns ``(n_frames,
    height, width, 3) uint8`` frames; ``.mp4`` (with every character's speech mixed into
    its soundtrack), ``.gif`` or a folder of PNG frames writes them (see
    :func:`facelib.render`). Returns the frames or the written path.
    """
    scene = make_scene_clip(source)
    faces = [clip.face_or_default() for clip in scene.clips]
    suffix = "" if out is None else Path(out).suffix.lower()
    if suffix == ".png":
        raise ParameterError("a scene renders to .mp4, .gif or a folder of PNG frames, not "
                             "one .png")
    with ExitStack() as stack:
        folder = stack.enter_context(tempfile.TemporaryDirectory(prefix="facelib-scene-"))
        renderers = [stack.enter_context(FaceRenderer(face, width=width, height=height,
                                                      background=background,
                                                      framing=framing))
                     for face in faces]
        frames = iter_scene_frames(scene, renderers, faces, framing=framing,
                                   progress=progress)
        if out is None:
            result = np.empty((scene.n_frames, height, width, 3), np.uint8)
            for i, image in enumerate(frames):
                result[i] = image
            return result
        sound = None
        if suffix == ".mp4" and scene.speech is not None:
            import soundfile

            sound = Path(folder) / "speech.wav"
            soundfile.write(str(sound), scene.speech.samples, scene.speech.sample_rate,
                            subtype="PCM_16")
        writer = open_writer(out, fps=scene.fps, width=width, height=height, audio=sound,
                             duration=scene.clips[0].stream.duration)
        try:
            for image in frames:
                writer.write(image)
        except BaseException:
            writer.abort()
            raise
        return writer.commit()
