"""Playing an animation in a desktop window (pyrender's pyglet viewer), in real time.

The window needs a display (X11 or Wayland) and the on-screen OpenGL platform, so ``view``
must run in a process that has not rendered offscreen yet (PyOpenGL binds one platform per
process). Without a display it raises :class:`~facelib.errors.RenderError` saying so.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from facelib.clip import Clip, make_clip
from facelib.errors import RenderError
from facelib.mpeg4.stream import FapStream
from facelib.rendering.platform import import_pyrender
from facelib.rendering.protocols import Deformable, HasFaps
from facelib.rendering.scene import FaceRenderer, install_program_cache

__all__ = ["Playback", "has_display", "view"]


def has_display() -> bool:
    """Whether a window can be opened: Windows/macOS, or ``DISPLAY``/``WAYLAND_DISPLAY`` set."""
    if sys.platform in ("win32", "darwin"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


@dataclass
class Playback:
    """Where playback stands: the frame shown, paused or running, and the wall-clock time
    frame 0 would have been shown at (moved on pause, resume and steps). Mutated only by
    the viewer's key callbacks and its playback loop, both under ``view``'s control."""

    fps: float
    n_frames: int
    paused: bool = False
    index: int = 0
    origin: float = field(default_factory=time.perf_counter)

    def toggle(self) -> None:
        """Space: pause, or resume from the frame shown."""
        self.paused = not self.paused
        if not self.paused:
            self.origin = time.perf_counter() - self.index / self.fps

    def step(self, frames: int) -> None:
        """Arrow keys: pause and move ``frames`` (clamped to the stream)."""
        self.paused = True
        self.index = min(max(self.index + frames, 0), self.n_frames - 1)

    def due(self) -> int:
        """The frame to show now (the index itself while paused)."""
        if not self.paused:
            self.index = int((time.perf_counter() - self.origin) * self.fps)
        return self.index


def _keys(state: Playback) -> dict[Any, Any]:
    """pyrender's ``registered_keys`` by pyglet key symbol: space pauses, left/right step one
    frame, up/down ten (pyrender keeps its own: q quits, z resets the view)."""
    from pyglet.window import key

    return {
        key.SPACE: (lambda viewer: state.toggle()),
        key.LEFT: (lambda viewer: state.step(-1)),
        key.RIGHT: (lambda viewer: state.step(1)),
        key.DOWN: (lambda viewer: state.step(-10)),
        key.UP: (lambda viewer: state.step(10)),
    }


def _sound(clip: Clip) -> Any:
    """A pyglet player holding the clip's audio (its file, read with soundfile so any
    format it reads plays, or its synthesized speech), or None without audio. Without an
    audio device pyglet's silent driver takes it, so playback and its clock run the same
    way, without sound."""
    if clip.audio is None and clip.speech is None:
        return None
    try:
        import io

        import pyglet.media
        import soundfile

        if clip.audio is not None:
            samples, rate = soundfile.read(str(clip.audio), dtype="int16", always_2d=True)
        else:
            assert clip.speech is not None
            samples, rate = clip.speech.samples, clip.speech.sample_rate
        wav = io.BytesIO()
        soundfile.write(wav, samples, rate, format="WAV", subtype="PCM_16")
        wav.seek(0)  # pyglet decodes WAV itself; other formats would need its FFmpeg codec
        source = pyglet.media.load("speech.wav", file=wav, streaming=False)
        player = pyglet.media.Player()
        player.queue(source)
        return player
    except Exception:  # no driver, unreadable audio: play without sound  # noqa: BLE001
        return None


def view(
    source: FapStream | HasFaps | Clip,
    *,
    face: Deformable | str | os.PathLike[str] | None = None,
    width: int = 800,
    height: int = 600,
    loop: bool = False,
    sound: bool = True,
) -> None:
    """Open a window that plays ``source`` (FapStream, animation with ``.faps``, or Clip) on
    ``face`` (None: the clip's, the storyboard's, else the bundled head).

    Frames follow the wall clock (frames are skipped, never slowed, when rendering lags);
    the mouse orbits and zooms as in pyrender's viewer. Space pauses and resumes, the left
    and right arrows step one frame (up/down: ten), q closes. With ``sound`` the speech
    audio of an animation (its file or its synthesized speech) plays in sync through
    pyglet where an audio device exists (silently otherwise); it stops on pause. The
    window closes at the end unless ``loop`` (replays until closed). Blocks until then."""
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
    clip = make_clip(source, face=face)
    stream, face, offset = clip.stream, clip.face_or_default(), clip.audio_offset
    pr = import_pyrender(offscreen=False)
    scene = FaceRenderer(face, width=width, height=height, mesh_update="swap", offscreen=False)
    state = Playback(stream.fps, stream.n_frames)
    try:
        viewer = pr.Viewer(
            scene.scene, viewport_size=(width, height), run_in_thread=True,
            window_title=f"facelib: {stream.n_frames} frames at {stream.fps:g} fps",
        )
    except Exception as exc:
        raise RenderError(f"could not open a window ({type(exc).__name__}: {exc})") from exc
    with viewer.render_lock:  # shade with facelib's face shader, as offscreen frames are
        install_program_cache(pr, viewer._renderer, scene.look)
    # set after construction: pyrender's constructor only maps ASCII characters, the
    # property takes pyglet key symbols (arrows included)
    viewer.registered_keys = {**viewer.registered_keys, **_keys(state)}
    frames = np.asarray(face.deform(stream), np.float32) if stream.n_frames else None
    player = _sound(clip) if sound else None
    try:
        while frames is not None and viewer.is_active:
            _play_once(viewer, scene, frames, state, player=player, offset=offset)
            if not loop:
                break
    finally:
        if player is not None:
            player.pause()
        if viewer.is_active:
            viewer.close_external()


def _play_once(viewer: Any, scene: FaceRenderer, frames: np.ndarray, state: Playback, *,
               player: Any, offset: float) -> None:
    """Show ``frames`` from the first to the last, following ``state``'s clock."""
    state.index, state.paused, state.origin = 0, False, time.perf_counter()
    shown = -1
    audio_started = False
    while viewer.is_active:
        index = state.due()
        if index >= len(frames):
            return
        if player is not None:
            at = index / state.fps - offset
            if state.paused and audio_started:
                player.pause()
                audio_started = False
            elif not state.paused and not audio_started and at >= 0:
                player.seek(at)
                player.play()
                audio_started = True
        if index != shown:
            with viewer.render_lock:
                scene.set_vertices(frames[index])
            shown = index
        time.sleep(0.01 if state.paused else
                   max(0.0, (index + 1) / state.fps - (time.perf_counter() - state.origin)))
