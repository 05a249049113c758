"""``visemes_from_audio``: speech audio without a transcript -> the viseme generator's FAP
track, as a storyboard's ``say { audio = ... }`` without text makes it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from facelib.checks import check_fps
from facelib.cues import MAX_FRAMES, SpeechSpec
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.recognize import Method, recognize
from facelib.visemes.animate import SpeechAudio, VisemeAnimation, animate_spoken
from facelib.visemes.articulation import Style
from facelib.visemes.mapping import with_visemes

__all__ = ["visemes_from_audio"]


def visemes_from_audio(
    audio: str | Path | np.ndarray, *, sample_rate: int | None = None, language: str = "en",
    fps: float = 25.0, method: Method = "auto", style: Style = "normal",
    max_frames: int = MAX_FRAMES,
) -> VisemeAnimation:
    """Visemes and mouth, jaw and tongue FAP curves of speech ``audio`` alone.

    Parameters
    ----------
    audio:
        A sound file in any format soundfile reads, or an array ``(n,)`` or
        ``(n, channels)`` of samples (then give ``sample_rate`` in Hz).
    language:
        The speech's language, any: ``method="auto"`` takes the path that measures best
        for it (English: words decoded, then aligned, the phone loop where no word is
        heard; every other language: the acoustic viseme model).
    fps:
        Frame rate of the track.
    method:
        ``"auto"``, ``"acoustic"`` (any language), ``"words"`` or ``"phones"`` (English),
        as :func:`facelib.speech.recognize.recognize`.
    style:
        Articulation, as a ``say``'s ``style``.

    Returns
    -------
    VisemeAnimation (``track``, ``timeline`` of viseme spans, ``speaking``, ``speech``, the
    full timeline with each recognised word's ``confidence``, ``loudness``), with
    coarticulation, the p/b/m closure and the loudness rules applied as for aligned speech.
    Frame i of the track is at ``i / fps`` s of the audio.
    """
    fps = check_fps(fps)
    phones = recognize(audio, sample_rate=sample_rate, language=language, method=method)
    samples = load_speech(audio, sample_rate=sample_rate)
    spec = SpeechSpec(audio=None, text=None, style=style)
    made = animate_spoken(spec, with_visemes(phones), SpeechAudio(samples, ALIGN_RATE),
                          fps=fps, max_frames=max_frames)
    return replace(made, audio=None)  # ``audio`` is synthesized speech; this was recorded
