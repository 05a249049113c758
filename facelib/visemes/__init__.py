"""Speech to visemes: phone-to-viseme mapping (thesis annex B), coarticulation and viseme
FAP curves, viseme scripts.

``animate(speech, fps=...)`` is the generator the animation pipeline calls; ``align`` and
``timeline_from_text`` are :mod:`facelib.speech`'s with the visemes of the phones added.
"""

from facelib.errors import SpeechWarning
from facelib.visemes.animate import (
    SpeechAudio,
    VisemeAnimation,
    align,
    align_dtw,
    animate,
    speech_timeline,
    synthesize,
    timeline_from_text,
)
from facelib.visemes.coarticulation import blend, driven_faps, envelope
from facelib.visemes.from_audio import visemes_from_audio
from facelib.visemes.mapping import phones_to_visemes, visemes_for, with_visemes
from facelib.visemes.scripts import (
    timeline_from_json,
    timeline_to_json,
    timeline_to_sentence,
    timeline_to_tsv,
    visemes_from_cues,
    write_timeline,
)
from facelib.visemes.tables import (
    N_VISEMES,
    phone_viseme,
    script_name,
    viseme_id,
    viseme_name,
    viseme_targets,
)
from facelib.visemes.timeline import SILENCE, Span, SpeechTimeline, VisemeSpan

__all__ = [
    "N_VISEMES",
    "SILENCE",
    "Span",
    "SpeechAudio",
    "SpeechTimeline",
    "SpeechWarning",
    "VisemeAnimation",
    "VisemeSpan",
    "align",
    "align_dtw",
    "animate",
    "blend",
    "driven_faps",
    "envelope",
    "phone_viseme",
    "phones_to_visemes",
    "script_name",
    "speech_timeline",
    "synthesize",
    "timeline_from_json",
    "timeline_from_text",
    "timeline_to_json",
    "timeline_to_sentence",
    "timeline_to_tsv",
    "viseme_id",
    "viseme_name",
    "viseme_targets",
    "visemes_for",
    "visemes_from_audio",
    "visemes_from_cues",
    "with_visemes",
    "write_timeline",
]
