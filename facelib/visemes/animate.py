"""``animate``: a storyboard's speech spec -> the viseme generator's FAP track."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.checks import check_fps, check_kind, check_number
from facelib.cues import MAX_FRAMES, MAX_SPEECH_TEXT_CHARS, SpeechSpec
from facelib.errors import SpeechError
from facelib.mpeg4.track import FapTrack
from facelib.speech import align as align_phones
from facelib.speech import timeline_from_text as phones_from_text
from facelib.speech.align import OnImplausible
from facelib.visemes.coarticulation import (
    blend,
    driven_faps,
    envelope,
    frame_times_ms,
    speaking_mask,
)
from facelib.visemes.mapping import with_visemes
from facelib.visemes.scripts import visemes_from_cues
from facelib.visemes.timeline import SpeechTimeline, VisemeSpan

__all__ = ["VisemeAnimation", "align", "animate", "speech_timeline", "timeline_from_text"]


@dataclass(frozen=True, eq=False)
class VisemeAnimation:
    """What the speech generator contributes.

    Attributes
    ----------
    track: FapTrack at the storyboard's fps from time 0 to the end of the speech; weights
        are > 0 only on the mouth, jaw and tongue FAPs, and only around speech.
    timeline: the viseme spans in storyboard time (ms), with their viseme id, name and
        the phones they show.
    speaking: ``(n_frames,) bool``, read-only: True where a sound other than silence is
        shown (the gaze model's "talking" state).
    speech: the full timeline (phones, words, visemes) in storyboard time.
    """

    track: FapTrack
    timeline: tuple[VisemeSpan, ...]
    speaking: np.ndarray
    speech: SpeechTimeline


def align(audio: str | Path | np.ndarray, text: str | None = None, *,
          sample_rate: int | None = None, on_implausible: OnImplausible = "warn",
          ) -> SpeechTimeline:
    """:func:`facelib.speech.align` (same arguments) with the visemes of its phones."""
    return with_visemes(align_phones(audio, text, sample_rate=sample_rate,
                                     on_implausible=on_implausible))


def timeline_from_text(text: str, *, rate: float = 1.0) -> SpeechTimeline:
    """:func:`facelib.speech.timeline_from_text` with the visemes of its phones."""
    return with_visemes(phones_from_text(text, rate=rate))


def speech_timeline(speech: SpeechSpec, *, rate: float = 1.0) -> SpeechTimeline:
    """The timeline of ``speech`` in its own time (ms from ``speech.start_ms``): a stored
    viseme script as it is; audio and text by forced alignment; audio alone by phone-loop
    recognition; text alone by the duration model at speaking ``rate``."""
    if speech.visemes:
        spans = visemes_from_cues(speech.visemes)
        shifted = tuple(s.shifted(-speech.start_ms) for s in spans)
        end = max(s.end_ms for s in shifted)
        return SpeechTimeline((), (), shifted, "script", end)
    if speech.audio is not None:
        try:
            return align(speech.audio, speech.text)
        except SpeechError as exc:
            if speech.origin is None or (exc.path is not None and exc.line is not None):
                raise
            raise SpeechError(f"{exc.message} (speech of {speech.origin[0]}:"
                              f"{speech.origin[1]})", path=exc.path) from exc
    if speech.text:
        if len(speech.text) > MAX_SPEECH_TEXT_CHARS:
            path, line = speech.origin if speech.origin else (None, None)
            raise SpeechError(f"speech text has {len(speech.text)} characters, more than "
                              f"{MAX_SPEECH_TEXT_CHARS}", path=path, line=line)
        return timeline_from_text(speech.text, rate=rate)
    path, line = speech.origin if speech.origin else (None, None)
    raise SpeechError("speech has neither audio, text nor a viseme script", path=path, line=line)


def animate(speech: SpeechSpec, *, fps: float, rate: float = 1.0,
            max_frames: int = MAX_FRAMES) -> VisemeAnimation:
    """Mouth, jaw and tongue FAP curves for ``speech``.

    Frame i of the track is at ``i / fps`` s of the storyboard; the track ends at the last
    frame inside the speech. Values come from the coarticulation blend of the viseme
    targets; weights are the speech envelope on the driven FAPs (0 elsewhere).
    ``rate`` is the speaking rate of the text-only duration model. Speech longer than
    ``max_frames`` raises SpeechError before the curves are computed.
    """
    speech = check_kind("speech", speech, SpeechSpec)
    fps = check_fps(fps)
    rate = check_number("rate", rate, low=0.25, high=4.0)
    timeline = speech_timeline(speech, rate=rate).shifted(speech.start_ms)
    end_ms = speech.start_ms + timeline.duration_ms
    n_frames = math.floor(end_ms * fps / 1000) + 1
    if n_frames > max_frames:
        path, line = speech.origin if speech.origin else (None, None)
        raise SpeechError(f"speech lasts {end_ms} ms = {n_frames} frames at {fps:g} fps, more "
                          f"than max_frames={max_frames}", path=path, line=line)
    times = frame_times_ms(n_frames, fps)
    values = blend(timeline.visemes, times)
    weight = np.zeros_like(values)
    weight[:, driven_faps()] = envelope(timeline.visemes, times)[:, None]
    speaking = speaking_mask(timeline.visemes, times)
    speaking.flags.writeable = False
    return VisemeAnimation(FapTrack(fps, values, weight), timeline.visemes, speaking, timeline)
