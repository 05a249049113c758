"""``Storyboard``: what a storyboard asks for, as plain timed cues.

Times are integer milliseconds from the start of the animation (no float drift). Every cue
keeps ``origin`` (file, line) of the script line that made it, so later stages can name it
in errors.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

__all__ = [
    "MAX_FRAMES", "MAX_SPEECH_TEXT_CHARS", "TWO_SHOT", "CameraCue", "Character", "ExpressionCue",
    "GazeCue", "MoodCue", "Origin", "SpeechSpec", "Storyboard", "VisemeCue",
]

MAX_FRAMES = 360_000
"""Most frames an animation may have unless the caller raises it (``animate(max_frames=)``):
four hours at 25 fps. Checked before any per-frame array is allocated."""
MAX_SPEECH_TEXT_CHARS = 100_000
"""Longest text of one speech cue (about two hours of speech)."""

Origin = tuple[str, int]
"""(file, 1-based line) of the script text a cue came from."""

TWO_SHOT = "two_shot"
"""The camera framing of a storyboard with characters that shows them all side by side."""


@dataclass(frozen=True, slots=True)
class ExpressionCue:
    """Show expression ``name`` from ``start_ms`` for ``duration_ms``.

    ``intensity`` scales the expression's full-intensity FAP values (1.0 = as defined).
    ``ramp_in_ms`` / ``ramp_out_ms`` of None leave the ramps to the expression generator.
    """

    name: str
    start_ms: int
    duration_ms: int
    intensity: float = 1.0
    ramp_in_ms: int | None = None
    ramp_out_ms: int | None = None
    origin: Origin | None = None

    @property
    def end_ms(self) -> int:
        return self.start_ms + self.duration_ms


@dataclass(frozen=True, slots=True)
class MoodCue:
    """From ``start_ms`` on, the character is in mood ``name`` (a row of
    ``facelib/data/moods/moods.csv``) at ``intensity`` (0-1), until the next mood cue.

    The face eases into it over ``ease_ms`` (None: the mood's own ``ease_ms``), crossfading
    from the mood before.
    """

    name: str
    start_ms: int
    intensity: float = 1.0
    ease_ms: int | None = None
    origin: Origin | None = None


@dataclass(frozen=True, slots=True)
class GazeCue:
    """Run eye behaviour ``behaviour`` (``"lookTo"``, ``"default"``, ...) with ``args`` (the
    eye-script tuple's values between the name and the duration) from ``start_ms``."""

    behaviour: str
    args: tuple[str | float, ...]
    start_ms: int
    duration_ms: int
    origin: Origin | None = None

    @property
    def end_ms(self) -> int:
        return self.start_ms + self.duration_ms


@dataclass(frozen=True, slots=True)
class CameraCue:
    """Re-frame the camera on the named ``framing`` (``"face"``, ``"head"``, ``"bust"``:
    the renderer's framings) at ``start_ms``: a cut when ``duration_ms`` is 0, else a
    smooth move that arrives ``duration_ms`` later.

    In a storyboard with characters every camera cue is a cut: to the character ``who``
    (framed by ``framing``, None: the render's framing) or, with ``who`` None and
    ``framing`` :data:`TWO_SHOT`, to all of them side by side."""

    framing: str | None
    start_ms: int
    duration_ms: int = 0
    origin: Origin | None = None
    who: str | None = None

    @property
    def end_ms(self) -> int:
        return self.start_ms + self.duration_ms


@dataclass(frozen=True, slots=True)
class VisemeCue:
    """One entry of a stored viseme script (the thesis's ``Sentence``): viseme ``viseme``
    as written in the script (``"silence"``, ``"A"``, ``"kg"``, ...)."""

    viseme: str
    start_ms: int
    duration_ms: int
    origin: Origin | None = None

    @property
    def end_ms(self) -> int:
        return self.start_ms + self.duration_ms


@dataclass(frozen=True, slots=True)
class SpeechSpec:
    """What the character says, starting at ``start_ms``: audio and/or transcript text, or a
    stored viseme script (used as it is, without speech processing).

    ``lang`` is the language (None: the storyboard's); ``voice``, ``rate`` (1.0 = 175 words
    per minute) and ``pitch`` (0-100, 50 = the voice's own) shape synthesized speech for
    text without audio (``voice`` None: the language's espeak-ng voice). ``style`` says how
    strongly it is articulated: a style name (``"mumble"``, ``"normal"``, ``"emphatic"``)
    or a number for both the jaw and the lip level (:mod:`facelib.visemes.articulation`).
    """

    audio: Path | None = None
    text: str | None = None
    visemes: tuple[VisemeCue, ...] | None = None
    start_ms: int = 0
    origin: Origin | None = None
    lang: str | None = None
    voice: str | None = None
    rate: float = 1.0
    pitch: float = 50.0
    style: str | float = "normal"


@dataclass(frozen=True, slots=True)
class Character:
    """A character of a storyboard that names several (``characters { ada = {...} }``).

    name: what cues call it (``who = "ada"``).
    face: the face definition it is played on, a bundled character's name (``"ada"``), or
        None (the bundled head); a :func:`facelib.clip.styled_face` definition.
    hair: the hair style it wears, or None (the face definition's own).
    part: its own one-character storyboard: its speech, expressions, eye behaviours and
        moods, the shared definitions, its face and hair, no camera cues.
    origin: where the storyboard names it.
    """

    name: str
    part: Storyboard
    face: Path | str | None = None
    hair: str | None = None
    origin: Origin | None = None


def _frozen_map(value: Mapping[str, Any]) -> Mapping[str, Any]:
    return MappingProxyType(dict(value))


@dataclass(frozen=True, slots=True)
class Storyboard:
    """A loaded storyboard.

    Attributes
    ----------
    path: the storyboard file, or None when built in memory.
    fps: frame rate of the animation (frames per second).
    seed: seed of every random process (saccades, blinks, head noise).
    speech: what is said, or None.
    expressions, gaze: the expression and eye-behaviour cues, in time order.
    expression_defs: expressions the storyboard defines or overrides:
        name -> {FAP name or id: value at full intensity, in FAP units}.
    gaze_defs: eye behaviours the storyboard defines or overrides: name -> parameters.
    expression_mixes: expressions defined by mixing library expressions:
        name -> {library expression name: weight}; the expression generator resolves them
        against its library and adds ``expression_defs[name]`` (FAP overrides) on top.
        Mixes of expressions the storyboard itself defines are resolved at load time.
    output: where the storyboard asks the ``.fap`` to go, or None.
    face: the face definition JSON the storyboard is played on, a bundled character's name
        (``face = "ben"``, a ``str``; resolved by
        :func:`facelib.engine.characters.face_definition` when the face is loaded), or None
        (the default head).
    hair: the hair style the face wears (``hair = "long"``; ``"none"``: bald), or None (the
        face definition's own); checked when the face is loaded (:func:`facelib.clip.make_clip`).
    setting_lines: the line of a setting the file sets, for errors found after loading
        (``{"hair": 3}``: an unknown hair style is found when the face is loaded; ``face``
        likewise for an unknown character).
    language: the storyboard's language (``language = "pt"``), used by speech that names
        none; None means English.
    camera: the camera cues, in time order (the renderer re-frames at each).
    moods: the mood cues, in time order (each lasts until the next).
    characters: the characters of a storyboard that names several, left to right as the
        two-shot shows them (each with its own part, :class:`Character`); then ``speech``,
        ``expressions``, ``gaze`` and ``moods`` are empty and ``camera`` cuts between them.
        Empty for a storyboard of one face.
    turns: what the face says after ``speech``, in time order: the later ``say`` calls of
        a character (its turns in a dialogue; a storyboard of one face has one ``say``).
    """

    path: Path | None = None
    fps: float = 25.0
    seed: int = 0
    speech: SpeechSpec | None = None
    expressions: tuple[ExpressionCue, ...] = ()
    gaze: tuple[GazeCue, ...] = ()
    expression_defs: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    gaze_defs: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    output: Path | None = None
    expression_mixes: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    face: Path | str | None = None
    hair: str | None = None
    setting_lines: Mapping[str, int] = field(default_factory=dict)
    language: str | None = None
    camera: tuple[CameraCue, ...] = ()
    moods: tuple[MoodCue, ...] = ()
    characters: tuple[Character, ...] = ()
    turns: tuple[SpeechSpec, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "expression_defs", _frozen_map(self.expression_defs))
        object.__setattr__(self, "gaze_defs", _frozen_map(self.gaze_defs))
        object.__setattr__(self, "expression_mixes", _frozen_map(self.expression_mixes))
        object.__setattr__(self, "setting_lines", _frozen_map(self.setting_lines))

    @property
    def cues_end_ms(self) -> int:
        """End of the last expression, gaze, camera or stored-viseme cue, or start of the
        last mood (speech audio may last longer; the animation pipeline takes the longest
        track)."""
        ends = [c.end_ms for c in self.expressions] + [c.end_ms for c in self.gaze]
        ends += [c.start_ms for c in self.moods]
        ends += [c.end_ms for c in self.camera]
        ends += [c.part.cues_end_ms for c in self.characters]
        for said in (self.speech, *self.turns):
            if said is not None and said.visemes:
                ends += [c.end_ms for c in said.visemes]
        return max(ends, default=0)
