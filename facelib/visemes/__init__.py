"""Speech to visemes: forced alignment (pocketsphinx, the ``speech`` extra), phone-to-viseme
mapping (thesis annex B), coarticulation and viseme FAP curves, viseme scripts.

``animate(speech, fps=...)`` is the generator the animation pipeline calls; ``align`` is the
forced aligner on its own. pocketsphinx is imported only when audio is aligned.
"""

from facelib.visemes.align import SpeechWarning, align
from facelib.visemes.animate import VisemeAnimation, animate, speech_timeline
from facelib.visemes.coarticulation import blend, driven_faps, envelope
from facelib.visemes.durations import timeline_from_text
from facelib.visemes.mapping import phones_to_visemes, visemes_for
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
    "SpeechTimeline",
    "SpeechWarning",
    "VisemeAnimation",
    "VisemeSpan",
    "align",
    "animate",
    "blend",
    "driven_faps",
    "envelope",
    "phone_viseme",
    "phones_to_visemes",
    "script_name",
    "speech_timeline",
    "timeline_from_json",
    "timeline_from_text",
    "timeline_to_json",
    "timeline_to_sentence",
    "timeline_to_tsv",
    "viseme_id",
    "viseme_name",
    "viseme_targets",
    "visemes_for",
    "visemes_from_cues",
    "write_timeline",
]
