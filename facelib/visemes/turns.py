"""One face speaking several times: the speech generator's animations of each turn as one.

A character of a dialogue may ``say`` several things, each at its own time (its turns).
Each turn is animated on its own (:func:`facelib.visemes.animate`); :func:`join_turns`
lays them on one timeline: the tracks summed by weight (turns meet only at their release
ramps), the viseme spans and phones one after the other, "speaking" wherever a turn
speaks, and their sound mixed into one from the first turn's start.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from facelib.cues import SpeechSpec
from facelib.errors import ParameterError
from facelib.mpeg4.track import FapTrack
from facelib.speech.loudness import FLOOR_DB
from facelib.speech.mix import Voice, mix_voices
from facelib.visemes.animate import SpeechAudio, VisemeAnimation
from facelib.visemes.timeline import SpeechTimeline

__all__ = ["join_turns"]


def _voices(turns: Sequence[tuple[SpeechSpec, VisemeAnimation]], first_ms: int) -> list[Voice]:
    voices = []
    for spec, anim in turns:
        offset = (spec.start_ms - first_ms) / 1000
        if spec.audio is not None:
            voices.append(Voice(offset, file=spec.audio))
        elif anim.audio is not None:
            voices.append(Voice(offset, samples=anim.audio.samples,
                                sample_rate=anim.audio.sample_rate))
    return voices


def join_turns(turns: Sequence[tuple[SpeechSpec, VisemeAnimation]]) -> VisemeAnimation:
    """The turns ``(spec, animation)`` (in start order, all at one fps) as one animation
    from time 0, its ``audio`` every turn's sound mixed from the first turn's
    ``start_ms`` on (recordings read from their files)."""
    if not turns:
        raise ParameterError("join_turns needs at least one turn")
    anims = [a for _, a in turns]
    fps = anims[0].track.fps
    n = max(a.track.n_frames for a in anims)
    tracks = [a.track.padded(n) for a in anims]
    weight = np.sum([t.weight for t in tracks], axis=0)
    summed = np.sum([t.values * t.weight for t in tracks], axis=0)
    values = np.divide(summed, weight, out=np.zeros_like(summed), where=weight > 0)
    speaking = np.zeros(n, bool)
    loudness = np.full(n, FLOOR_DB, np.float32)
    for a in anims:
        speaking[: a.speaking.size] |= a.speaking
        if a.loudness is not None:
            loudness[: a.loudness.size] = np.maximum(loudness[: a.loudness.size], a.loudness)
    speaking.flags.writeable = False
    loudness.flags.writeable = False
    first_ms = turns[0][0].start_ms
    timelines = [a.speech for a in anims]
    end_ms = max((t.visemes[-1].end_ms for t in timelines if t.visemes), default=first_ms)
    joined = SpeechTimeline(
        tuple(p for t in timelines for p in t.phones), tuple(w for t in timelines for w in t.words),
        tuple(v for t in timelines for v in t.visemes), timelines[0].source, end_ms - first_ms,
        timelines[0].alphabet)
    voices = _voices(turns, first_ms)
    audio = None
    if voices:
        samples, rate = mix_voices(voices)
        audio = SpeechAudio(samples, rate)
    return replace(anims[0], track=FapTrack(fps, values.astype(np.float32),
                                            np.minimum(weight, 1.0).astype(np.float32)),
                   timeline=joined.visemes, speaking=speaking, speech=joined, audio=audio,
                   loudness=loudness)
