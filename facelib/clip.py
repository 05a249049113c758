"""The one typed hand-off to every output: a :class:`Clip`.

Rendering, the viewer and the exports (glTF, ARKit curves, the web player) play a Clip: a
FAP stream, the face it plays on, the speech audio with the time it starts at, and the
storyboard's camera moves. :func:`make_clip` makes one, once, at an output's entry, from
what the public functions take (a :class:`~facelib.mpeg4.stream.FapStream`, an animation
such as :func:`facelib.run_fdl`'s, or a Clip), so no output reads an animation's attributes
by name and every output follows the same audio rule:

- ``audio`` given: that file (it must exist), starting ``audio_offset`` seconds into the
  clip, by default where the source's speech starts (0 for a FapStream);
- else the source's own recording (``animation.audio``) at its offset;
- else the source's synthesized speech (``animation.speech_audio``: samples, no file) at
  its offset;
- a FapStream has no audio.

An output plays what it can carry: video muxes the file or the synthesized samples; a glTF
and the web page copy a file (synthesized speech has none to copy); the viewer plays either.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np

from facelib.checks import did_you_mean
from facelib.errors import FaceModelError, FdlError, ParameterError
from facelib.mpeg4.stream import FapStream

__all__ = [
    "CameraMove",
    "Clip",
    "Deformable",
    "SceneClip",
    "Shot",
    "Speech",
    "check_hair",
    "face_for",
    "is_scene",
    "make_clip",
    "make_scene_clip",
    "resolve_face",
    "storyboard_definition",
    "styled_face",
]


@runtime_checkable
class Deformable(Protocol):
    """A face mesh that FAPs deform (:class:`facelib.engine.Face` is one).

    ``vertices``: ``(V, 3) float32`` neutral positions; ``triangles``: ``(F, 3)`` vertex ids;
    ``parts``: part name -> object with ``triangles``; ``vertex_colors``: ``(V, 3)`` sRGB in
    [0, 1] or None.
    """

    @property
    def vertices(self) -> np.ndarray: ...

    @property
    def triangles(self) -> np.ndarray: ...

    @property
    def parts(self) -> Mapping[str, Any]: ...

    def deform(self, stream: FapStream) -> np.ndarray:
        """``(n_frames, V, 3) float32`` vertex positions for every frame of ``stream``."""
        ...

    def deform_frame(self, values: np.ndarray) -> np.ndarray:
        """``(V, 3) float32`` positions for one frame of 84 FAP values."""
        ...


@dataclass(frozen=True, slots=True)
class CameraMove:
    """A storyboard camera cue: re-frame on ``framing`` (a look's framing name) at
    ``start_ms``, a cut when ``duration_ms`` is 0, else a move arriving ``duration_ms``
    later. ``origin``: the cue's storyboard ``(file, line)``, or None."""

    framing: str
    start_ms: int
    duration_ms: int = 0
    origin: tuple[str | None, int | None] | None = None


@dataclass(frozen=True, eq=False)
class Speech:
    """Synthesized speech without a file: ``samples (n,)`` float (float32 as synthesized)
    in [-1, 1] at ``sample_rate`` Hz (a read-only view, dtype kept)."""

    samples: np.ndarray
    sample_rate: int

    def __post_init__(self) -> None:
        samples = np.asarray(self.samples).view()
        samples.flags.writeable = False
        object.__setattr__(self, "samples", samples)
        object.__setattr__(self, "sample_rate", int(self.sample_rate))


@dataclass(frozen=True, eq=False)
class Clip:
    """What every output plays.

    stream: the FAP stream (its ``fps`` is the clip's frame rate).
    face: the face it plays on, or None for facelib's bundled head (loaded by the output
        that needs a mesh).
    audio: the speech audio file, or None.
    speech: synthesized speech samples to play when there is no ``audio`` file, or None.
    audio_offset: seconds into the clip at which the audio (or speech) starts.
    camera: the storyboard's camera moves, by start.
    """

    stream: FapStream
    face: Deformable | None = None
    audio: Path | None = None
    speech: Speech | None = None
    audio_offset: float = 0.0
    camera: tuple[CameraMove, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.stream, FapStream):
            raise ParameterError(f"a Clip's stream is a FapStream, not "
                                 f"{type(self.stream).__name__}")
        object.__setattr__(self, "audio", None if self.audio is None else Path(self.audio))
        object.__setattr__(self, "audio_offset", float(self.audio_offset))
        object.__setattr__(self, "camera", tuple(self.camera))

    @property
    def fps(self) -> float:
        """Frames per second (the stream's)."""
        return float(self.stream.fps)

    @property
    def n_frames(self) -> int:
        return int(self.stream.n_frames)

    def resampled(self, fps: float) -> Clip:
        """The clip with its stream resampled to ``fps`` (audio and camera keep their
        times in seconds and milliseconds)."""
        return replace(self, stream=self.stream.resample(fps))

    def face_or_default(self) -> Deformable:
        """The clip's face, or facelib's bundled head when it has none."""
        return resolve_face(self.face)

    def __repr__(self) -> str:
        audio = f", audio={self.audio.name!r}" if self.audio is not None else ""
        speech = ", speech=synthesized" if self.speech is not None else ""
        return (f"Clip(frames={self.n_frames}, fps={self.fps:g}, "
                f"face={'bundled' if self.face is None else type(self.face).__name__}"
                f"{audio}{speech}, audio_offset={self.audio_offset:g}, "
                f"camera={len(self.camera)})")


FaceArg = Deformable | str | os.PathLike[str] | None


def resolve_face(face: FaceArg) -> Deformable:
    """``face``; a face definition JSON path or a bundled character's name (``"ben"``)
    loaded; None: facelib's bundled head."""
    from facelib.engine import default_face, load_face

    if isinstance(face, (str, os.PathLike)):
        return load_face(face)
    return default_face() if face is None else face


def styled_face(definition: str | os.PathLike[str] | None, hair: str | None) -> Deformable:
    """The face definition JSON ``definition`` (None: the bundled head) loaded wearing the
    hair style ``hair`` (``"none"``: bald; None: the definition's own). ParameterError
    naming the definition's styles, with a did-you-mean, for a style it does not have."""
    from facelib.engine import load_face

    if hair is None:
        return resolve_face(definition)
    where = None if definition is None else Path(definition)
    check_hair(where, hair)
    return load_face(where, hair=hair)


def check_hair(definition: str | os.PathLike[str] | None, hair: str, *,
               path: str | Path | None = None, line: int | None = None) -> None:
    """Check that ``hair`` is a style of the face definition ``definition`` (None: the
    bundled head) without loading the face: ParameterError naming its styles, with a
    did-you-mean, or FdlError at ``path``:``line`` when a storyboard file is given."""
    from facelib.engine import hair_style_names

    where = None if definition is None else Path(definition)
    styles = hair_style_names(where)
    if hair in styles:
        return
    name = "the bundled head" if where is None else where.name
    message = (f"hair style {hair!r} is not one of {name}'s ({', '.join(styles)})"
               f"{did_you_mean(hair, styles)}")
    raise ParameterError(message) if path is None else FdlError(message, path=path, line=line)


def face_for(source: object, definition: str | os.PathLike[str] | None,
             hair: str | None) -> FaceArg:
    """What an output of ``source`` is given as its face for a face definition
    ``definition`` (None: none named) and a hair style ``hair``: ``definition`` itself when
    ``hair`` is None (the storyboard's face and hair then apply as :func:`make_clip` says);
    else that definition, or the face ``source``'s storyboard names, or the bundled head,
    loaded wearing ``hair`` (:func:`styled_face`)."""
    if hair is None:
        return definition
    if definition is None:
        definition = storyboard_definition(getattr(source, "storyboard", None))
    return styled_face(definition, hair)


def make_clip(
    source: Clip | FapStream | object,
    *,
    face: FaceArg = None,
    audio: str | os.PathLike[str] | None = None,
    audio_offset: float | None = None,
    storyboard_face: bool = True,
    storyboard_hair: bool = True,
) -> Clip:
    """The :class:`Clip` of ``source``: a Clip, a FapStream, or an animation (an object with
    a ``faps`` FapStream and optionally ``audio``, ``audio_offset``, ``speech_audio`` and a
    ``storyboard`` with ``face`` and ``camera``, such as :class:`facelib.Animation`).

    face: the face to play on (a face-like object or a face definition JSON path, loaded);
        None keeps a Clip's face, else takes the face the storyboard names (unless
        ``storyboard_face`` is False), else None: the bundled head. Without ``face``, a
        storyboard's ``hair`` style is worn by that face (or by the bundled head when
        ``storyboard_face`` is False) unless ``storyboard_hair`` is False (FdlError naming
        the storyboard's line for a style the face lacks); a given ``face`` keeps its own.
    audio, audio_offset: the audio rule of the module docstring; an explicit ``audio`` must
        be an existing file (ParameterError otherwise), as must the source's own.
    """
    clip = (source if isinstance(source, Clip)
            else _from_source(source, storyboard_face=storyboard_face and face is None,
                              storyboard_hair=storyboard_hair and face is None))
    if face is not None:
        clip = replace(clip, face=resolve_face(face) if isinstance(face, (str, os.PathLike))
                       else face)
    if audio is not None:
        clip = replace(clip, audio=Path(audio))
    if audio_offset is not None:
        clip = replace(clip, audio_offset=float(audio_offset))
    if clip.audio is not None and not clip.audio.is_file():
        raise ParameterError(f"audio file {clip.audio} does not exist")
    return clip


def storyboard_definition(storyboard: object) -> Path | None:
    """The face definition file a storyboard's ``face`` names (a path, or a bundled
    character's name resolved by :func:`facelib.engine.characters.face_definition`), or
    None; FdlError at the storyboard's ``face`` line for an unknown character."""
    from facelib.engine.characters import face_definition

    named = getattr(storyboard, "face", None)
    try:
        return face_definition(named)
    except FaceModelError as exc:
        lines = getattr(storyboard, "setting_lines", None) or {}
        raise FdlError(exc.message, path=getattr(storyboard, "path", None) or "<storyboard>",
                       line=lines.get("face")) from None


def _storyboard_face(storyboard: object, *, use_face: bool,
                     use_hair: bool) -> Deformable | None:
    """The face a storyboard names (if ``use_face``) wearing its ``hair`` (if ``use_hair``),
    or None for the bundled head as it is."""
    named = storyboard_definition(storyboard) if use_face else None
    hair = getattr(storyboard, "hair", None) if use_hair else None
    if hair is None:
        return None if named is None else resolve_face(named)
    lines = getattr(storyboard, "setting_lines", None) or {}
    check_hair(named, hair, path=getattr(storyboard, "path", None) or "<storyboard>",
               line=lines.get("hair"))
    return styled_face(named, hair)


def _from_source(source: object, *, storyboard_face: bool, storyboard_hair: bool) -> Clip:
    """A Clip of a FapStream or an animation (read by attribute name here, and only here)."""
    if isinstance(source, FapStream):
        return Clip(source)
    stream = getattr(source, "faps", None)
    if not isinstance(stream, FapStream):
        raise ParameterError(f"an output needs a FapStream, a Clip or an animation with a "
                             f".faps FapStream, not {type(source).__name__}")
    storyboard = getattr(source, "storyboard", None)
    own = getattr(source, "audio", None)
    samples = getattr(source, "speech_audio", None)
    speech = (None if samples is None
              else Speech(np.asarray(samples.samples), int(samples.sample_rate)))
    camera = tuple(
        CameraMove(str(cue.framing), int(cue.start_ms), int(cue.duration_ms),
                   getattr(cue, "origin", None))
        for cue in (getattr(storyboard, "camera", ()) or ()))
    return Clip(stream, face=_storyboard_face(storyboard, use_face=storyboard_face,
                                              use_hair=storyboard_hair),
                audio=None if own is None else Path(own), speech=speech,
                audio_offset=float(getattr(source, "audio_offset", 0.0) or 0.0),
                camera=camera)


TWO_SHOT = "two_shot"
"""The framing of a shot that shows every character of a scene side by side (the
storyboard layer's :data:`facelib.cues.TWO_SHOT`)."""


@dataclass(frozen=True, slots=True)
class Shot:
    """A cut of a scene at ``start_ms``: to the character ``who`` framed by ``framing``
    (a look's framing name; None: the render's), or with ``who`` None to the two-shot.
    ``origin``: the camera cue's storyboard ``(file, line)``, or None."""

    who: str | None
    start_ms: int
    framing: str | None = None
    origin: tuple[str | None, int | None] | None = None


@dataclass(frozen=True, eq=False)
class SceneClip:
    """What an output of a storyboard with characters plays.

    names: the characters, left to right as the two-shot shows them.
    clips: each character's :class:`Clip` (its stream, its face wearing its hair, its own
        speech), in the order of ``names``; every stream has the same frames.
    shots: the camera's cuts, by start (before the first: the two-shot).
    speech: every character's speech mixed into one soundtrack from time 0, or None.
    """

    names: tuple[str, ...]
    clips: tuple[Clip, ...]
    shots: tuple[Shot, ...] = ()
    speech: Speech | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "clips", tuple(self.clips))
        object.__setattr__(self, "shots", tuple(sorted(self.shots, key=lambda s: s.start_ms)))
        if not self.clips or len(self.names) != len(self.clips):
            raise ParameterError(f"a scene needs one clip per character; got "
                                 f"{len(self.names)} names and {len(self.clips)} clips")
        frames = {(c.n_frames, c.fps) for c in self.clips}
        if len(frames) != 1:
            raise ParameterError(f"a scene's clips must have the same frames and fps; got "
                                 f"{sorted(frames)}")
        for shot in self.shots:
            if shot.who is not None and shot.who not in self.names:
                raise ParameterError(f"shot of {shot.who!r}: not one of the characters "
                                     f"({', '.join(self.names)})"
                                     f"{did_you_mean(shot.who, self.names)}")

    @property
    def fps(self) -> float:
        return self.clips[0].fps

    @property
    def n_frames(self) -> int:
        return self.clips[0].n_frames

    def clip_of(self, name: str) -> Clip:
        """The clip of character ``name``."""
        if name not in self.names:
            raise ParameterError(f"no character {name!r} in the scene ({', '.join(self.names)})"
                                 f"{did_you_mean(name, self.names)}")
        return self.clips[self.names.index(name)]

    def shot_per_frame(self) -> np.ndarray:
        """``(n_frames,) int``: which shot each frame shows, ``-1`` for the two-shot before
        the first cut, else the index into ``shots``."""
        times = np.arange(self.n_frames) * 1000.0 / self.fps
        starts = np.array([s.start_ms for s in self.shots], np.float64)
        return np.searchsorted(starts, times + 1e-6, side="right") - 1


def is_scene(source: object) -> bool:
    """Whether ``source`` is a scene (a :class:`SceneClip`, or an animation of a storyboard
    with characters such as :class:`facelib.Scene`: an object with ``parts``)."""
    return isinstance(source, SceneClip) or isinstance(getattr(source, "parts", None), Mapping)


def make_scene_clip(source: SceneClip | object) -> SceneClip:
    """The :class:`SceneClip` of ``source``: a SceneClip, or a scene animation (an object
    with ``parts``, name -> animation, a ``storyboard`` with ``camera`` cuts naming ``who``
    and ``framing``, and ``speech_audio``, such as :class:`facelib.Scene`). Each part's clip
    is :func:`make_clip`'s: its storyboard's face wearing its hair."""
    if isinstance(source, SceneClip):
        return source
    parts = getattr(source, "parts", None)
    if not isinstance(parts, Mapping) or not parts:
        raise ParameterError(f"a scene output needs a SceneClip or a scene with .parts, not "
                             f"{type(source).__name__}")
    storyboard = getattr(source, "storyboard", None)
    shots = tuple(
        Shot(None if cue.who is None else str(cue.who), int(cue.start_ms),
             None if cue.framing in (None, TWO_SHOT) else str(cue.framing),
             getattr(cue, "origin", None))
        for cue in (getattr(storyboard, "camera", ()) or ()))
    samples = getattr(source, "speech_audio", None)
    speech = (None if samples is None
              else Speech(np.asarray(samples.samples), int(samples.sample_rate)))
    return SceneClip(tuple(str(n) for n in parts), tuple(make_clip(a) for a in parts.values()),
                     shots=shots, speech=speech)
