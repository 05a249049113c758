"""Speech in: audio loading, forced alignment (pocketsphinx, the ``speech`` extra),
pronunciation and the text-only duration model.

Everything here returns phone and word timelines (:class:`PhoneTimeline`);
:mod:`facelib.visemes` turns them into visemes. pocketsphinx loads only when audio is aligned.
"""

from facelib.speech.align import align
from facelib.speech.audio import load_speech
from facelib.speech.durations import timeline_from_text
from facelib.speech.pronounce import pronounce, tokenize
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span

__all__ = ["SILENCE", "PhoneTimeline", "Span", "align", "load_speech", "pronounce",
           "timeline_from_text", "tokenize"]
