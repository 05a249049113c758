"""Speech in: audio loading, forced alignment (pocketsphinx, the ``speech`` extra),
synthesis in any language (espeak-ng), alignment in any language (DTW against the
synthesized transcript), text normalisation, pronunciation, loudness and the text-only
duration model.

Everything here returns phone and word timelines (:class:`PhoneTimeline`);
:mod:`facelib.visemes` turns them into visemes. pocketsphinx loads only when audio is aligned.
"""

from facelib.speech.align import align
from facelib.speech.audio import load_speech
from facelib.speech.dtw import align_dtw
from facelib.speech.durations import timeline_from_text
from facelib.speech.loudness import phone_loudness
from facelib.speech.pronounce import pronounce, tokenize
from facelib.speech.synth import Synthesis, list_voices, synthesize
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span

__all__ = ["SILENCE", "PhoneTimeline", "Span", "Synthesis", "align", "align_dtw",
           "list_voices", "load_speech", "phone_loudness", "pronounce", "synthesize",
           "timeline_from_text", "tokenize"]
