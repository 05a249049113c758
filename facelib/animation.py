"""From a storyboard to one FAP stream: the generators, then the synchronizer."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType

import numpy as np

from facelib import expressions, gaze, visemes
from facelib.checks import check_seed
from facelib.cues import MAX_FRAMES, Storyboard
from facelib.errors import ParameterError
from facelib.fdl import load
from facelib.gaze.events import GazeEvent
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.track import FapTrack
from facelib.sync import SyncRules, combine
from facelib.visemes.animate import VisemeAnimation
from facelib.visemes.timeline import VisemeSpan

__all__ = ["Animation", "animate", "run_fdl"]


@dataclass(frozen=True)
class Animation:
    """A storyboard turned into FAPs.

    faps: the synchronized stream (what is rendered or written to ``.fap``).
    audio: the speech audio to play with it, or None.
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

    def __post_init__(self) -> None:
        object.__setattr__(self, "tracks", MappingProxyType(dict(self.tracks)))


def animate(
    storyboard: Storyboard, *, seed: int | None = None, rules: SyncRules | None = None,
    max_frames: int = MAX_FRAMES,
) -> Animation:
    """Run the generators of a storyboard and resolve their conflicts.

    seed: overrides ``storyboard.seed``; the same storyboard and seed give the same stream
    bit for bit. rules: the synchronizer's weights (default ``facelib/data/sync.json``).
    The stream lasts as long as the longest track: the speech, or the last cue including a
    frame at its very end. ``max_frames`` bounds its length (default
    :data:`facelib.cues.MAX_FRAMES`); a longer storyboard raises ParameterError before
    anything is computed.
    """
    if seed is not None:
        storyboard = replace(storyboard, seed=check_seed(seed))
    rules = rules or SyncRules.load()
    fps = storyboard.fps
    # one frame past the last cue's end, so the face is shown settling back to neutral
    n_frames = math.floor(storyboard.cues_end_ms * fps / 1000 + 1e-9) + 1
    if n_frames > max_frames:
        raise ParameterError(
            f"storyboard {storyboard.path or '(in memory)'} lasts {storyboard.cues_end_ms} ms "
            f"= {n_frames} frames at {fps:g} fps, more than max_frames={max_frames}"
        )
    speech = (visemes.animate(storyboard.speech, fps=fps, max_frames=max_frames)
              if storyboard.speech else None)
    if speech is not None:
        n_frames = max(n_frames, speech.track.n_frames)
    speaking = np.zeros(n_frames, bool)
    viseme_track = FapTrack.empty(n_frames, fps=fps)
    if speech is not None:
        viseme_track = _with_importance(speech, rules).padded(n_frames)
        speaking[: speech.speaking.size] = speech.speaking[:n_frames]
    expression_track = expressions.animate(
        storyboard.expressions, fps=fps, n_frames=n_frames,
        library=expressions.default_library().with_defs(
            storyboard.expression_defs, mixes=storyboard.expression_mixes
        ),
        importance=rules.expression_importance,
    )
    eyes = gaze.animate(storyboard.gaze, fps=fps, n_frames=n_frames, seed=storyboard.seed,
                        behaviours=storyboard.gaze_defs, speaking=speaking)
    stream = combine(expressions=expression_track, visemes=viseme_track, gaze=eyes.open_track,
                     blinks=eyes.lid_closure, blink_lids=eyes.blink_lids, speaking=speaking,
                     rules=rules, seed=storyboard.seed)
    return Animation(
        faps=stream,
        audio=storyboard.speech.audio if storyboard.speech else None,
        storyboard=storyboard,
        audio_offset=storyboard.speech.start_ms / 1000 if storyboard.speech else 0.0,
        tracks={"expressions": expression_track, "visemes": viseme_track, "gaze": eyes.track},
        visemes=None if speech is None else speech.timeline,
        gaze_events=eyes.events,
    )


def _with_importance(speech: VisemeAnimation, rules: SyncRules) -> FapTrack:
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


def run_fdl(path: str | os.PathLike[str], *, seed: int | None = None) -> Animation:
    """Load the storyboard at ``path`` and animate it (see :func:`animate`)."""
    return animate(load(Path(path), seed=seed), seed=seed)
