"""The Clip (issue 30, item 2): one typed hand-off to every output, made once, with one
audio rule for rendering, the exports and the viewer."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest

from facelib.clip import CameraMove, Clip, Speech, make_clip
from facelib.cues import CameraCue
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream

FLAC = Path(__file__).parents[1] / "examples" / "hello" / "hello.flac"


def _stream(n: int = 10, fps: float = 25.0) -> FapStream:
    values = np.zeros((n, 84), np.float32)
    values[:, 2] = np.linspace(0, 300, n)
    return FapStream(fps, values)


def _animation(**kw: object) -> SimpleNamespace:
    """An animation as the outputs see one: ``faps`` and the optional attributes."""
    fields: dict[str, object] = {"faps": _stream(), "audio": None, "audio_offset": 0.0,
                                 "speech_audio": None,
                                 "storyboard": SimpleNamespace(face=None, camera=())}
    return SimpleNamespace(**{**fields, **kw})


class _FaceLike:
    """A face-like stand-in (only its identity matters here)."""

    vertices = np.zeros((3, 3), np.float32)
    triangles = np.zeros((1, 3), np.int64)
    parts: ClassVar[dict[str, object]] = {}

    def deform(self, stream: FapStream) -> np.ndarray:
        return np.zeros((stream.n_frames, 3, 3), np.float32)

    def deform_frame(self, values: np.ndarray) -> np.ndarray:
        return np.zeros((3, 3), np.float32)


def test_a_stream_makes_a_clip_without_audio_camera_or_face():
    stream = _stream(fps=30.0)
    clip = make_clip(stream)
    assert clip.stream is stream
    assert (clip.fps, clip.n_frames) == (30.0, 10)
    assert (clip.face, clip.audio, clip.speech, clip.audio_offset, clip.camera) == (
        None, None, None, 0.0, ())
    assert make_clip(clip) is clip  # made once: a Clip passes through


def test_an_animation_becomes_typed_fields():
    samples = np.linspace(-0.5, 0.5, 800, dtype=np.float32)
    cues = (CameraCue("head", 400, 0, ("story.fdl", 3)), CameraCue("bust", 100, 250))
    anim = _animation(audio=str(FLAC), audio_offset=1.25,
                      speech_audio=SimpleNamespace(samples=samples, sample_rate=16000),
                      storyboard=SimpleNamespace(face=None, camera=cues))
    clip = make_clip(anim)
    assert clip.audio == FLAC
    assert isinstance(clip.audio, Path)
    assert clip.audio_offset == 1.25
    assert clip.speech is not None
    assert clip.speech.sample_rate == 16000
    assert np.array_equal(clip.speech.samples, samples)
    assert clip.speech.samples.dtype == np.float32
    assert not clip.speech.samples.flags.writeable
    assert clip.camera == (CameraMove("head", 400, 0, ("story.fdl", 3)),
                           CameraMove("bust", 100, 250))
    assert all(type(move) is CameraMove for move in clip.camera)


def test_the_audio_rule():
    own = _animation(audio=FLAC, audio_offset=0.75)
    # the source's own file at its offset
    assert (make_clip(own).audio, make_clip(own).audio_offset) == (FLAC, 0.75)
    # an explicit file replaces it and keeps where the speech starts ...
    other = Path(__file__)
    clip = make_clip(own, audio=other)
    assert (clip.audio, clip.audio_offset) == (other, 0.75)
    # ... unless told otherwise
    assert make_clip(own, audio=other, audio_offset=0.1).audio_offset == 0.1
    # a stream has no speech: an explicit file starts at 0
    assert make_clip(_stream(), audio=FLAC).audio_offset == 0.0
    # synthesized speech rides along when there is no file
    spoken = _animation(audio_offset=0.5, speech_audio=SimpleNamespace(
        samples=np.zeros(10, np.float32), sample_rate=8000))
    clip = make_clip(spoken)
    assert (clip.audio, clip.audio_offset) == (None, 0.5)
    assert clip.speech is not None


def test_missing_audio_and_bad_sources_are_refused(tmp_path):
    missing = tmp_path / "gone.wav"
    with pytest.raises(ParameterError, match=r"audio file .*gone\.wav does not exist"):
        make_clip(_stream(), audio=missing)
    with pytest.raises(ParameterError, match=r"audio file .*gone\.wav does not exist"):
        make_clip(_animation(audio=missing))
    with pytest.raises(ParameterError, match="not str"):
        make_clip("clip.fap")
    with pytest.raises(ParameterError, match="not SimpleNamespace"):
        make_clip(SimpleNamespace(faps=np.zeros((3, 84))))
    with pytest.raises(ParameterError, match="stream is a FapStream"):
        Clip(np.zeros((3, 84)))  # type: ignore[arg-type]


def test_the_face_rule(tmp_path):
    named = _animation(storyboard=SimpleNamespace(face=tmp_path / "none.json", camera=()))
    face = _FaceLike()
    # an explicit face wins, and the storyboard's is then not even loaded
    assert make_clip(named, face=face).face is face
    # the exports ignore the storyboard's face: the bundled head (None)
    assert make_clip(named, storyboard_face=False).face is None
    # otherwise the storyboard's face is loaded (here it does not exist)
    from facelib.errors import FacelibError

    with pytest.raises(FacelibError, match=r"none\.json"):
        make_clip(named)
    clip = make_clip(_stream(), face=face)
    assert clip.face_or_default() is face
    assert make_clip(clip).face is face


def test_a_clip_is_frozen_and_resamples_keeping_audio_and_camera():
    clip = Clip(_stream(10, 25.0), audio=FLAC, audio_offset=0.4,
                camera=[CameraMove("head", 200)],  # type: ignore[arg-type]
                speech=Speech(np.zeros(4), 8000))
    with pytest.raises(dataclasses.FrozenInstanceError):
        clip.audio_offset = 1.0  # type: ignore[misc]
    assert isinstance(clip.camera, tuple)
    half = clip.resampled(12.5)
    assert half.fps == 12.5
    assert half.n_frames == _stream(10, 25.0).resample(12.5).n_frames
    assert (half.audio, half.audio_offset, half.camera, half.speech) == (
        clip.audio, clip.audio_offset, clip.camera, clip.speech)
    assert "frames=10" in repr(clip)
    assert "camera=1" in repr(clip)


def test_exports_and_rendering_take_the_same_audio_offset(tmp_path):
    # one rule: before the Clip, an explicit audio file made the glTF say it starts at 0 while
    # a render of the same animation started it where the speech starts
    pytest.importorskip("pygltflib")
    from facelib.export import export_gltf
    from facelib.rendering.frames import stream_of

    anim = _animation(audio=FLAC, audio_offset=0.6)
    result = export_gltf(anim, tmp_path / "a.glb", audio=FLAC)
    import pygltflib

    extras = pygltflib.GLTF2().load_binary(str(result.path)).asset.extras["facelib"]
    assert extras["audio_offset"] == pytest.approx(0.6)
    assert extras["audio"] == "a.flac"
    assert stream_of(anim)[1:] == (FLAC, 0.6)
