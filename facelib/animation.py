"""From a storyboard to one FAP stream: the generators, then the synchronizer."""

from __future__ import annotations

import math
import os
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType

import numpy as np

from facelib import data, expressions, gaze, visemes
from facelib.checks import check_seed
from facelib.cues import MAX_FRAMES, Storyboard
from facelib.errors import FacelibError, ParameterError
from facelib.fdl import load
from facelib.gaze.animate import GazeAnimation
from facelib.gaze.events import GazeEvent
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.track import FapTrack
from facelib.progress import ProgressCallback, progress_callback
from facelib.speech.mix import Voice, mix_voices
from facelib.sync import Liveliness, SyncRules, combine
from facelib.visemes.animate import SpeechAudio, VisemeAnimation
from facelib.visemes.timeline import VisemeSpan
from facelib.visemes.turns import join_turns

__all__ = ["Animation", "Scene", "animate", "animate_scene", "compose", "definition_line",
           "run_fdl", "run_scene", "speech_track"]


@dataclass(frozen=True)
class Animation:
    """A storyboard turned into FAPs.

    faps: the synchronized stream (what is rendered or written to ``.fap``).
    audio: the speech audio file to play with it, or None.
    speech_audio: synthesized speech (``.samples``, ``.sample_rate``) to play with it when
        the storyboard's speech is text without a recording, or None.
    loudness: ``(n_frames,) float32`` dBFS of the speech under each frame, or None.
    audio_offset: seconds into the animation at which the audio starts.
    storyboard: the storyboard it came from.
    tracks: each generator's own track (``"expressions"``, ``"visemes"``, ``"gaze"``),
        before conflict resolution, for plots and inspection.
    visemes: the viseme timeline (None without speech).
    gaze_events: saccades, blinks and head moves of the eye-behaviour model.
    """

    faps: FapStream
    audio: Path | None
    storyboard: Storyboard
    audio_offset: float = 0.0
    tracks: Mapping[str, FapTrack] = field(default_factory=dict)
    visemes: tuple[VisemeSpan, ...] | None = None
    gaze_events: tuple[GazeEvent, ...] = ()
    speech_audio: SpeechAudio | None = None
    loudness: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "tracks", MappingProxyType(dict(self.tracks)))

    def __repr__(self) -> str:
        """One line: where it came from, its length and parts, never the arrays."""
        source = self.storyboard.path.name if self.storyboard.path else "<storyboard>"
        audio = f", audio={self.audio.name!r}" if self.audio is not None else ""
        return (f"Animation({source!r}, frames={self.faps.n_frames}, fps={self.faps.fps:g}, "
                f"duration={self.faps.duration:.3f}s, "
                f"expressions={len(self.storyboard.expressions)}, "
                f"gaze={len(self.storyboard.gaze)}, gaze_events={len(self.gaze_events)}"
                f"{audio})")


@dataclass(frozen=True)
class Scene:
    """A storyboard with characters turned into FAPs: one :class:`Animation` per character.

    storyboard: the storyboard (its ``characters`` and ``camera`` cuts).
    parts: character name -> its Animation, left to right as the two-shot shows them;
        every stream has the same number of frames at the storyboard's fps.
    speech_audio: every character's speech mixed into one soundtrack from time 0
        (``.samples``, ``.sample_rate``), or None when nobody speaks.
    """

    storyboard: Storyboard
    parts: Mapping[str, Animation]
    speech_audio: SpeechAudio | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "parts", MappingProxyType(dict(self.parts)))

    @property
    def n_frames(self) -> int:
        return next(iter(self.parts.values())).faps.n_frames

    @property
    def fps(self) -> float:
        return self.storyboard.fps

    def __repr__(self) -> str:
        source = self.storyboard.path.name if self.storyboard.path else "<storyboard>"
        return (f"Scene({source!r}, characters={list(self.parts)}, frames={self.n_frames}, "
                f"fps={self.fps:g}, cuts={len(self.storyboard.camera)})")


_STAGES = 4  # speech, expressions, gaze, synchronizer: the units of animate's progress


def animate(
    storyboard: Storyboard, *, seed: int | None = None, rules: SyncRules | None = None,
    max_frames: int = MAX_FRAMES,
    progress: bool | ProgressCallback | None = None,
    liveliness: Liveliness | None = None,
) -> Animation:
    """Run the generators of a storyboard and resolve their conflicts.

    seed: overrides ``storyboard.seed``; the same storyboard and seed give the same stream
    bit for bit. rules: the synchronizer's weights (default ``facelib/data/sync.json``).
    The stream lasts as long as the longest track: the speech, or the last cue including a
    frame at its very end. ``max_frames`` bounds its length (default
    :data:`facelib.cues.MAX_FRAMES`); a longer storyboard raises ParameterError before
    anything is computed. ``progress`` (see :mod:`facelib.progress`) is called after each
    of the four stages (speech, expressions, gaze, synchronizer) as ``progress(done, 4)``.
    ``liveliness`` scales breathing, listening motion, micro-movements and the blink rate
    (:class:`facelib.sync.Liveliness`; default: the data's numbers).
    An error of a generator that names no file is raised again naming the storyboard (and
    the line of the definition it concerns, where one can be found).
    """
    try:
        return _animate(storyboard, seed=seed, rules=rules, max_frames=max_frames,
                        report=progress_callback(progress, "animating", unit="stages"),
                        liveliness=liveliness)
    except FacelibError as exc:
        if exc.path is not None or storyboard.path is None:
            raise
        raise type(exc)(exc.message, path=storyboard.path,
                        line=definition_line(storyboard.path, exc.message)) from exc


def _animate(
    storyboard: Storyboard, *, seed: int | None, rules: SyncRules | None, max_frames: int,
    report: ProgressCallback | None, liveliness: Liveliness | None,
) -> Animation:
    def step(done: int) -> None:
        if report is not None:
            report(done, _STAGES)

    if storyboard.characters:
        names = ", ".join(c.name for c in storyboard.characters)
        raise ParameterError(f"storyboard {storyboard.path or '(in memory)'} names characters "
                             f"({names}): animate it with facelib.animate_scene")
    if seed is not None:
        storyboard = replace(storyboard, seed=check_seed(seed))
    rules = rules or SyncRules.load()
    speech, n_frames = _speech(storyboard, max_frames=max_frames)
    step(1)
    return _animation(storyboard, speech, n_frames=n_frames, rules=rules,
                      report=lambda done: step(1 + done), liveliness=liveliness)


def _speech(storyboard: Storyboard, *, max_frames: int) -> tuple[VisemeAnimation | None, int]:
    """The speech generator's animation of ``storyboard`` (None without speech) and the
    number of frames it needs: one past the last cue's end, or the speech's length."""
    fps = storyboard.fps
    # one frame past the last cue's end, so the face is shown settling back to neutral
    n_frames = math.floor(storyboard.cues_end_ms * fps / 1000 + 1e-9) + 1
    if n_frames > max_frames:
        raise ParameterError(
            f"storyboard {storyboard.path or '(in memory)'} lasts {storyboard.cues_end_ms} ms "
            f"= {n_frames} frames at {fps:g} fps, more than max_frames={max_frames}"
        )
    said = [s for s in (storyboard.speech, *storyboard.turns) if s is not None]
    turns = [(s, visemes.animate(s, fps=fps, max_frames=max_frames,
                                 language=storyboard.language)) for s in said]
    speech = None if not turns else turns[0][1] if len(turns) == 1 else join_turns(turns)
    if speech is not None:
        n_frames = max(n_frames, speech.track.n_frames)
    return speech, n_frames


def _animation(
    storyboard: Storyboard, speech: VisemeAnimation | None, *, n_frames: int,
    rules: SyncRules, report: Callable[[int], None] | None, liveliness: Liveliness | None,
) -> Animation:
    """The Animation of ``storyboard`` over ``n_frames`` frames with its ``speech``."""
    viseme_track = None if speech is None else speech_track(speech, rules)
    stream, tracks, eyes = compose(
        storyboard, visemes=viseme_track,
        speaking=None if speech is None else speech.speaking, n_frames=n_frames, rules=rules,
        report=report, liveliness=liveliness)
    return Animation(
        faps=stream,  # several turns: their sound is mixed into speech_audio
        audio=storyboard.speech.audio if storyboard.speech and not storyboard.turns else None,
        storyboard=storyboard,
        audio_offset=storyboard.speech.start_ms / 1000 if storyboard.speech else 0.0,
        tracks=tracks,
        visemes=None if speech is None else speech.timeline,
        gaze_events=eyes.events,
        speech_audio=None if speech is None else speech.audio,
        loudness=None if speech is None else speech.loudness,
    )


def animate_scene(
    storyboard: Storyboard, *, seed: int | None = None, rules: SyncRules | None = None,
    max_frames: int = MAX_FRAMES, progress: bool | ProgressCallback | None = None,
    liveliness: Liveliness | None = None,
) -> Scene:
    """Animate each character of a storyboard with ``characters { ... }`` as :func:`animate`
    does a storyboard of one face, all over the same frames (the longest part's), each one's
    mutual gaze turned toward the others (``facelib/data/alive/dialogue.json``) unless the
    storyboard defines its own ``default`` eye behaviour, and mix their speech into one
    soundtrack. ``seed`` overrides the storyboard's (character ``i`` takes ``seed + i``);
    ``progress`` is called as ``progress(done, 4 * n_characters)``; the other options as for
    :func:`animate`."""
    try:
        return _animate_scene(storyboard, seed=seed, rules=rules or SyncRules.load(),
                              max_frames=max_frames, liveliness=liveliness,
                              report=progress_callback(progress, "animating", unit="stages"))
    except FacelibError as exc:
        if exc.path is not None or storyboard.path is None:
            raise
        raise type(exc)(exc.message, path=storyboard.path,
                        line=definition_line(storyboard.path, exc.message)) from exc


def _animate_scene(
    storyboard: Storyboard, *, seed: int | None, rules: SyncRules, max_frames: int,
    liveliness: Liveliness | None, report: ProgressCallback | None,
) -> Scene:
    cast = storyboard.characters
    if not cast:
        raise ParameterError(f"storyboard {storyboard.path or '(in memory)'} names no "
                             "characters: animate it with facelib.animate")
    total = _STAGES * len(cast)
    parts = [_facing(c.part, index, len(cast), seed=seed) for index, c in enumerate(cast)]
    speeches = []
    for index, part in enumerate(parts):
        speeches.append(_speech(part, max_frames=max_frames))
        if report is not None:
            report(index + 1, total)
    n_frames = max(n for _, n in speeches)
    animations = {}
    for index, (character, part, (speech, _)) in enumerate(zip(cast, parts, speeches,
                                                                strict=True)):
        done = len(cast) + 3 * index

        def step(k: int, done: int = done) -> None:
            if report is not None:
                report(done + k, total)

        animations[character.name] = _animation(part, speech, n_frames=n_frames, rules=rules,
                                                report=step, liveliness=liveliness)
    return Scene(storyboard, animations, speech_audio=_soundtrack(animations.values()))


def _facing(part: Storyboard, index: int, count: int, *, seed: int | None) -> Storyboard:
    """Character ``index`` of ``count`` (left to right) with its mutual gaze turned toward
    the others and the seed ``seed + index`` when ``seed`` is given."""
    if seed is not None:
        part = replace(part, seed=(check_seed(seed) + index) % 2**63)
    if "default" in part.gaze_defs:
        return part
    rule = data.json_data("alive/dialogue.json")
    side = float(np.sign((count - 1) / 2 - index))  # left of centre: +1 (looks to its left)
    toward = {"gaze_offset_deg": (side * rule["partner_gaze_deg"], 0.0),
              "head_offset_deg": (side * rule["partner_head_deg"], 0.0)}
    return replace(part, gaze_defs={**part.gaze_defs, "default": toward})


def _soundtrack(animations: Iterable[Animation]) -> SpeechAudio | None:
    """Every animation's speech (recording or synthesized) mixed from time 0."""
    voices = []
    for anim in animations:
        if anim.audio is not None:
            voices.append(Voice(anim.audio_offset, file=anim.audio))
        elif anim.speech_audio is not None:
            voices.append(Voice(anim.audio_offset, samples=anim.speech_audio.samples,
                                sample_rate=anim.speech_audio.sample_rate))
    if not voices:
        return None
    samples, rate = mix_voices(voices)
    return SpeechAudio(samples, rate)


def _expression_track(storyboard: Storyboard, n_frames: int,
                      rules: SyncRules) -> tuple[FapTrack, expressions.MoodCurves | None]:
    """The expression track with the storyboard's moods blended under it, and the moods."""
    fps = storyboard.fps
    library = expressions.default_library().with_defs(
        storyboard.expression_defs, mixes=storyboard.expression_mixes)
    moods = (expressions.mood_curves(storyboard.moods, fps=fps, n_frames=n_frames,
                                     library=library) if storyboard.moods else None)
    track = expressions.animate(storyboard.expressions, fps=fps, n_frames=n_frames,
                                library=library, importance=rules.expression_importance,
                                moods=moods)
    return track, moods


def _with_mood(lively: Liveliness, moods: expressions.MoodCurves | None) -> Liveliness:
    """``lively`` with the moods' idle amplitude on the micro-movements and their head
    motion on the listening head motion, frame by frame (unchanged without moods)."""
    if moods is None:
        return lively
    return replace(
        lively,
        micro_amplitude=lively.micro_amplitude * moods.scales["idle_amplitude"],
        listening_amplitude=lively.listening_amplitude * moods.scales["head_motion_scale"])


def compose(
    storyboard: Storyboard, *, visemes: FapTrack | None, speaking: np.ndarray | None,
    n_frames: int, rules: SyncRules, report: Callable[[int], None] | None = None,
    liveliness: Liveliness | None = None,
) -> tuple[FapStream, dict[str, FapTrack], GazeAnimation]:
    """The expressions and the eyes of ``storyboard`` over ``n_frames`` frames, merged with
    the speech's ``visemes`` track (weights carrying importance, :func:`speech_track`;
    None: no speech) by the synchronizer: the stream, each generator's track and the eye
    animation. ``speaking``: ``(k,) bool`` from frame 0 (cut or padded with False to
    ``n_frames``). Every generator is causal in its random draws, so a longer ``n_frames``
    or a cue starting at frame ``i`` leaves the frames before ``i`` bit for bit as they
    were: a live session runs this over a growing window. ``report(k)`` after each of the
    three stages (expressions, gaze, synchronizer). ``liveliness``: the idle motion's and
    blink rate's factors (:class:`facelib.sync.Liveliness`; per-frame arrays must have
    ``n_frames`` rows)."""
    lively = liveliness or Liveliness()
    fps = storyboard.fps
    talking = np.zeros(n_frames, bool)
    viseme_track = FapTrack.empty(n_frames, fps=fps)
    if visemes is not None:
        viseme_track = visemes.padded(n_frames)
    if speaking is not None:
        talking[: speaking.size] = speaking[:n_frames]
    expression_track, moods = _expression_track(storyboard, n_frames, rules)
    lively = _with_mood(lively, moods)
    if report is not None:
        report(1)
    eyes = gaze.animate(storyboard.gaze, fps=fps, n_frames=n_frames, seed=storyboard.seed,
                        behaviours=storyboard.gaze_defs, speaking=talking,
                        blink_rate=lively.blink_rate)
    if report is not None:
        report(2)
    stream = combine(expressions=expression_track, visemes=viseme_track, gaze=eyes.open_track,
                     blinks=eyes.lid_closure, blink_lids=eyes.blink_lids, speaking=talking,
                     rules=rules, seed=storyboard.seed, liveliness=lively,
                     head_scale=None if moods is None else moods.scales["head_motion_scale"],
                     speech_brow=None if moods is None else moods.scales["speech_brow"])
    if report is not None:
        report(3)
    tracks = {"expressions": expression_track, "visemes": viseme_track, "gaze": eyes.track}
    return stream, tracks, eyes


def speech_track(speech: VisemeAnimation, rules: SyncRules) -> FapTrack:
    """The viseme track with each viseme's importance (``rules.viseme_importance``) on its
    weight, frame by frame along the timeline."""
    track = speech.track
    if not rules.viseme_importance:
        return track
    factor = np.ones(track.n_frames, np.float32)
    for span in speech.timeline:
        first = math.floor(span.start_ms * track.fps / 1000)
        last = math.ceil(span.end_ms * track.fps / 1000)
        factor[first:last] = rules.viseme_importance.get(span.name, 1.0)
    return FapTrack(track.fps, track.values, track.weight * factor[:, None])


def run_fdl(path: str | os.PathLike[str], *, seed: int | None = None,
            progress: bool | ProgressCallback | None = None) -> Animation:
    """Load the storyboard at ``path`` and animate it (see :func:`animate`; ``progress``
    is called after each of animate's four stages)."""
    return animate(load(Path(path), seed=seed), seed=seed, progress=progress)


def run_scene(path: str | os.PathLike[str], *, seed: int | None = None,
              progress: bool | ProgressCallback | None = None) -> Scene:
    """Load the storyboard with characters at ``path`` and animate it (see
    :func:`animate_scene`)."""
    return animate_scene(load(Path(path), seed=seed), seed=seed, progress=progress)


def definition_line(path: str | os.PathLike[str], message: str) -> int | None:
    """The 1-based line of ``path`` that defines the expression or eye behaviour a
    generator's error ``message`` names (``... 'name' ...``), or None.

    Generators see definitions as plain mappings without their script lines; this finds
    ``define_gaze { "name"`` / ``define_expression { "name"`` (or ``name = {`` in a
    ``behaviours``/``expressions`` table) so the error can point at it.
    """
    quoted = re.findall(r"'([^']+)'", message)
    if not quoted:
        return None
    try:
        lines = Path(path).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return None
    name = re.escape(quoted[0])
    pattern = re.compile(
        rf"define_\w+\s*\{{\s*[\"']{name}[\"']|(^|[{{,\s]){name}\s*=\s*\{{")
    for number, line in enumerate(lines, 1):
        if pattern.search(line.split("--", 1)[0]):
            return number
    return None
