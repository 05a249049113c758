"""``animate``: a storyboard's speech spec -> the viseme generator's FAP track."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.checks import check_fps, check_kind, check_number
from facelib.cues import MAX_FRAMES, MAX_SPEECH_TEXT_CHARS, SpeechSpec
from facelib.errors import MissingExtraError, ParameterError, SpeechError, SpeechWarning
from facelib.mpeg4.track import FapTrack
from facelib.speech import align as align_phones
from facelib.speech import timeline_from_text as phones_from_text
from facelib.speech.align import OnImplausible
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.dtw import align_dtw as align_phones_dtw
from facelib.speech.espeak import Worker
from facelib.speech.loudness import FLOOR_DB, window_loudness
from facelib.speech.recognize import recognize
from facelib.speech.synth import DEFAULT_LANGUAGE
from facelib.speech.synth import synthesize as synthesize_speech
from facelib.speech.timeline import PhoneTimeline
from facelib.visemes.articulation import span_levels
from facelib.visemes.coarticulation import (
    blend,
    driven_faps,
    envelope,
    frame_times_ms,
    speaking_mask,
)
from facelib.visemes.loudness import jaw_gain
from facelib.visemes.mapping import with_visemes
from facelib.visemes.scripts import visemes_from_cues
from facelib.visemes.tables import loudness_rules, timing_rules
from facelib.visemes.timeline import SpeechTimeline, VisemeSpan

__all__ = ["SpeechAudio", "VisemeAnimation", "align", "align_dtw", "animate", "animate_spoken",
           "speech_timeline", "spoken", "synthesize", "timeline_from_text"]


@dataclass(frozen=True, eq=False)
class SpeechAudio:
    """Speech audio to play with the animation: ``samples`` ``(n,) float32`` in [-1, 1] at
    ``sample_rate`` Hz (synthesized speech; recorded speech stays a file)."""

    samples: np.ndarray
    sample_rate: int


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
    audio: the synthesized speech (text without a recording), or None.
    loudness: ``(n_frames,) float32`` dBFS, read-only: the RMS level of the phone under each
        frame (:data:`facelib.speech.loudness.FLOOR_DB` where there is no audio).
    """

    track: FapTrack
    timeline: tuple[VisemeSpan, ...]
    speaking: np.ndarray
    speech: SpeechTimeline
    audio: SpeechAudio | None = None
    loudness: np.ndarray | None = None


def align(audio: str | Path | np.ndarray, text: str | None = None, *,
          sample_rate: int | None = None, on_implausible: OnImplausible = "warn",
          ) -> SpeechTimeline:
    """:func:`facelib.speech.align` (same arguments) with the visemes of its phones."""
    return with_visemes(align_phones(audio, text, sample_rate=sample_rate,
                                     on_implausible=on_implausible))


def align_dtw(audio: str | Path | np.ndarray, text: str, *, lang: str = DEFAULT_LANGUAGE,
              voice: str | None = None, sample_rate: int | None = None) -> SpeechTimeline:
    """:func:`facelib.speech.dtw.align_dtw` (any language) with the visemes of its phones."""
    return with_visemes(align_phones_dtw(audio, text, lang=lang, voice=voice,
                                         sample_rate=sample_rate))


def synthesize(text: str, *, lang: str = DEFAULT_LANGUAGE, voice: str | None = None,
               rate: float = 1.0, pitch: float = 50) -> tuple[SpeechTimeline, SpeechAudio]:
    """:func:`facelib.speech.synthesize` (same arguments): the timeline with visemes, and
    the audio."""
    made = synthesize_speech(text, lang=lang, voice=voice, rate=rate, pitch=pitch)
    return with_visemes(made.timeline), SpeechAudio(made.samples, made.sample_rate)


def timeline_from_text(text: str, *, rate: float = 1.0) -> SpeechTimeline:
    """:func:`facelib.speech.timeline_from_text` with the visemes of its phones."""
    return with_visemes(phones_from_text(text, rate=rate))


def speech_timeline(speech: SpeechSpec, *, rate: float = 1.0,
                    language: str | None = None) -> SpeechTimeline:
    """The timeline of ``speech`` in its own time (ms from ``speech.start_ms``): a stored
    viseme script as it is; audio and text by forced alignment (English: pocketsphinx,
    falling back to DTW; other languages: DTW against espeak-ng); audio alone by
    recognition (English words, then the phone loop; other languages the acoustic viseme
    model; see
    :func:`facelib.speech.recognize.recognize`); text alone synthesized by espeak-ng. ``rate``
    multiplies ``speech.rate``; ``language`` is the storyboard's (``speech.lang`` wins)."""
    return _spoken(speech, rate=rate, language=language)[0]


def _spoken(speech: SpeechSpec, *, rate: float, language: str | None,
            worker: Worker | None = None) -> tuple[SpeechTimeline, SpeechAudio | None]:
    lang = speech.lang or language or DEFAULT_LANGUAGE
    if speech.visemes:
        spans = visemes_from_cues(speech.visemes)
        shifted = tuple(s.shifted(-speech.start_ms) for s in spans)
        end = max(s.end_ms for s in shifted)
        return SpeechTimeline((), (), shifted, "script", end), None
    if speech.audio is not None:
        try:
            return with_visemes(_recorded(speech.audio, speech.text, lang, speech.voice)), None
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
        try:
            made = synthesize_speech(speech.text, lang=lang, voice=speech.voice,
                                     rate=min(max(speech.rate * rate, 0.5), 2.5),
                                     pitch=speech.pitch, worker=worker)
        except MissingExtraError:
            if not lang.lower().startswith("en"):
                raise
            warnings.warn("no speech synthesis (install facelib[speech]): the English duration "
                          "model times the text and the video is silent", SpeechWarning,
                          stacklevel=3)
            return timeline_from_text(speech.text, rate=speech.rate * rate), None
        return with_visemes(made.timeline), SpeechAudio(made.samples, made.sample_rate)
    path, line = speech.origin if speech.origin else (None, None)
    raise SpeechError("speech has neither audio, text nor a viseme script", path=path, line=line)


def _recorded(audio: Path, text: str | None, lang: str, voice: str | None) -> PhoneTimeline:
    """Phones of recorded ``audio``: with a transcript, pocketsphinx for English (DTW if it
    fails) and DTW against the synthesized transcript for any other language; without one,
    recognition (:func:`facelib.speech.recognize.recognize`, the best measured path for the
    language: English words, then the phone loop; any other language the acoustic viseme
    model)."""
    if text is None:
        return recognize(audio, language=lang)
    if lang.lower().startswith("en"):
        try:
            return align_phones(audio, text)
        except SpeechError:
            return align_phones_dtw(audio, text, lang=lang, voice=voice)
    return align_phones_dtw(audio, text, lang=lang, voice=voice)


def animate(speech: SpeechSpec, *, fps: float, rate: float = 1.0,
            language: str | None = None, max_frames: int = MAX_FRAMES) -> VisemeAnimation:
    """Mouth, jaw and tongue FAP curves for ``speech``.

    Frame i of the track is at ``i / fps`` s of the storyboard; the track ends at the last
    frame of the envelope's release ramp after the speech. Values come from the
    coarticulation blend of the viseme targets, faded to neutral with the speech envelope,
    which is also the weight on the driven FAPs (0 elsewhere): weights and values fade
    together, so a lone viseme track eases out instead of dropping to 0 in one frame.
    Louder speech opens the jaw further (:mod:`facelib.visemes.loudness`); the speech's
    ``style`` sets the jaw and lip levels (:mod:`facelib.visemes.articulation`).
    ``rate`` multiplies the speech's own speaking rate; ``language`` is the storyboard's.
    Speech longer than ``max_frames`` raises SpeechError before the curves are computed.
    """
    speech = check_kind("speech", speech, SpeechSpec)
    fps = check_fps(fps)
    rate = check_number("rate", rate, low=0.25, high=4.0)
    own, audio = _spoken(speech, rate=rate, language=language)
    return animate_spoken(speech, own, audio, fps=fps, max_frames=max_frames)


def spoken(speech: SpeechSpec, *, rate: float = 1.0, language: str | None = None,
           worker: Worker | None = None) -> tuple[SpeechTimeline, SpeechAudio | None]:
    """The timeline of ``speech`` in its own time (as :func:`speech_timeline`) and its
    synthesized audio (None for a recording or a viseme script): the slow half of
    :func:`animate`, which a live session runs once per sentence before it knows when the
    sentence will start. ``worker``: an espeak-ng process started ahead for text (the same
    result, sooner; :class:`facelib.speech.espeak.Worker`)."""
    speech = check_kind("speech", speech, SpeechSpec)
    rate = check_number("rate", rate, low=0.25, high=4.0)
    return _spoken(speech, rate=rate, language=language, worker=worker)


def animate_spoken(speech: SpeechSpec, own: SpeechTimeline, audio: SpeechAudio | None, *,
                   fps: float, max_frames: int = MAX_FRAMES) -> VisemeAnimation:
    """:func:`animate` of ``speech`` whose timeline ``own`` (in its own ms, from
    :func:`spoken` or a recognizer) and ``audio`` are known: the curves start at
    ``speech.start_ms``. ``audio`` (samples at their rate) gives the loudness that drives
    the jaw; without it a recording named by ``speech.audio`` does."""
    fps = check_fps(fps)
    timeline = own.shifted(speech.start_ms)
    # through the envelope's release ramp, so the mouth is seen settling back to neutral
    end_ms = speech.start_ms + timeline.duration_ms + timing_rules()["envelope_ramp_ms"]
    n_frames = math.floor(end_ms * fps / 1000) + 1
    if n_frames > max_frames:
        path, line = speech.origin if speech.origin else (None, None)
        raise SpeechError(f"speech lasts {end_ms} ms = {n_frames} frames at {fps:g} fps, more "
                          f"than max_frames={max_frames}", path=path, line=line)
    times = frame_times_ms(n_frames, fps)
    loudness = _frame_loudness(speech, own, audio, times - speech.start_ms)
    env = envelope(timeline.visemes, times)
    gain = jaw_gain(loudness, rules=loudness_rules())
    levels = _levels(speech, timeline)
    values = blend(timeline.visemes, times, jaw_gain=gain, levels=levels) * env[:, None]
    weight = np.zeros_like(values)
    weight[:, driven_faps()] = env[:, None]
    speaking = speaking_mask(timeline.visemes, times)
    speaking.flags.writeable = False
    return VisemeAnimation(FapTrack(fps, values, weight), timeline.visemes, speaking, timeline,
                           audio, loudness)


def _levels(speech: SpeechSpec, timeline: SpeechTimeline) -> np.ndarray:
    """Each span's jaw and lip levels for the speech's style; SpeechError at the ``say``."""
    try:
        return span_levels(timeline.visemes, style=speech.style)
    except ParameterError as exc:
        path, line = speech.origin if speech.origin else (None, None)
        raise SpeechError(f"say: {exc.message}", path=path, line=line) from exc


def _frame_loudness(speech: SpeechSpec, timeline: SpeechTimeline, audio: SpeechAudio | None,
                    times_ms: np.ndarray) -> np.ndarray:
    """``(n_frames,) float32`` dBFS of the speech around each frame (times in the speech's
    own ms): the RMS level over the ``loudness_window_ms`` centred on the frame, so the jaw
    follows the speech envelope within a phone as well as from phone to phone; the floor
    outside phones and where there is no audio."""
    out = np.full(times_ms.size, FLOOR_DB, np.float32)
    phones = timeline.phones
    if phones and (audio is not None or speech.audio is not None):
        if audio is not None:
            samples, sample_rate = audio.samples, audio.sample_rate
        else:
            samples, sample_rate = load_speech(speech.audio), ALIGN_RATE  # type: ignore[arg-type]
        half = loudness_rules()["window_ms"] / 2
        centre = np.round(times_ms).astype(np.int64)
        levels = window_loudness(samples, sample_rate=sample_rate,
                                 starts_ms=np.maximum(centre - int(half), 0),
                                 ends_ms=centre + int(half))
        starts = np.array([p.start_ms for p in phones], np.float64)
        ends = np.array([p.end_ms for p in phones], np.float64)
        k = np.clip(np.searchsorted(starts, times_ms, side="right") - 1, 0, len(phones) - 1)
        inside = (times_ms >= starts[k]) & (times_ms < ends[k])
        out[inside] = levels[inside]
    out.flags.writeable = False
    return out
