"""Viseme timelines in and out: the thesis's ``Sentence`` script, JSON and TSV.

JSON (also what ``facelib align`` writes)::

    {"source": "forced", "duration": 3.54,
     "phones": [{"phone": "HH", "start": 0.255, "end": 0.39}, ...],
     "words": [{"word": "hello", "start": 0.255, "end": 0.6}, ...],
     (a word recognised in audio without a transcript adds "confidence": 0-1)
     "visemes": [{"viseme": 10, "name": "aa", "start": 0.3, "end": 0.41,
                  "phones": ["AH"]}, ...]}

Times in seconds, phones in ARPAbet without stress, silence as ``SIL``. TSV has one row per
span: ``tier  label  start  end  viseme  confidence`` (confidence: recognised words only).
The ``Sentence`` script is Lua, one ``{"name", frames}`` entry per viseme, durations in
frames of the storyboard's fps.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from facelib.atomic import write_text_atomic
from facelib.checks import check_fps
from facelib.cues import VisemeCue
from facelib.errors import FdlError, ParameterError
from facelib.visemes.tables import script_name, viseme_id, viseme_name
from facelib.visemes.timeline import Span, SpeechTimeline, VisemeSpan

__all__ = [
    "timeline_from_json",
    "timeline_to_json",
    "timeline_to_sentence",
    "timeline_to_tsv",
    "visemes_from_cues",
    "write_timeline",
]


def _s(ms: int) -> float:
    return round(ms / 1000.0, 3)


def timeline_to_json(timeline: SpeechTimeline) -> dict[str, Any]:
    """The timeline as a JSON-ready dict (times in seconds)."""
    return {
        "source": timeline.source,
        "alphabet": timeline.alphabet,
        "duration": _s(timeline.duration_ms),
        "phones": [{"phone": p.label, "start": _s(p.start_ms), "end": _s(p.end_ms)}
                   for p in timeline.phones],
        "words": [_word_json(w) for w in timeline.words],
        "visemes": [{"viseme": v.viseme, "name": v.name, "start": _s(v.start_ms),
                     "end": _s(v.end_ms), "phones": list(v.phones)} for v in timeline.visemes],
    }


def _word_json(word: Span) -> dict[str, Any]:
    out: dict[str, Any] = {"word": word.label, "start": _s(word.start_ms),
                           "end": _s(word.end_ms)}
    if word.confidence is not None:
        out["confidence"] = round(word.confidence, 3)
    return out


def timeline_from_json(data: Mapping[str, Any]) -> SpeechTimeline:
    """Inverse of :func:`timeline_to_json` (times rounded to whole ms)."""
    try:
        def ms(x: float | str) -> int:
            return round(float(x) * 1000)

        phones = tuple(Span(p["phone"], ms(p["start"]), ms(p["end"])) for p in data["phones"])
        words = tuple(Span(w["word"], ms(w["start"]), ms(w["end"]),
                           None if w.get("confidence") is None else float(w["confidence"]))
                      for w in data["words"])
        visemes = tuple(
            VisemeSpan(int(v["viseme"]), viseme_name(int(v["viseme"])), ms(v["start"]),
                       ms(v["end"]), tuple(v.get("phones", ())))
            for v in data["visemes"]
        )
        source = data.get("source", "script")
        alphabet = data.get("alphabet", "arpabet")
        if alphabet not in ("arpabet", "ipa"):
            raise ValueError(f"alphabet {alphabet!r}")
        duration = ms(data["duration"]) if "duration" in data else max(
            (v.end_ms for v in visemes), default=0)
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"not a speech timeline: {exc!r}") from exc
    return SpeechTimeline(phones, words, visemes, source, duration, alphabet)


def timeline_to_tsv(timeline: SpeechTimeline) -> str:
    """Tab-separated ``tier label start end viseme confidence`` rows (times in s; viseme id
    on the viseme tier only; confidence on recognised words only), with a header line."""
    rows = ["tier\tlabel\tstart\tend\tviseme\tconfidence"]
    rows += [f"phone\t{p.label}\t{_s(p.start_ms)}\t{_s(p.end_ms)}\t\t" for p in timeline.phones]
    rows += [f"word\t{w.label}\t{_s(w.start_ms)}\t{_s(w.end_ms)}\t\t"
             f"{'' if w.confidence is None else round(w.confidence, 3)}" for w in timeline.words]
    rows += [f"viseme\t{v.name}\t{_s(v.start_ms)}\t{_s(v.end_ms)}\t{v.viseme}\t"
             for v in timeline.visemes]
    return "\n".join(rows) + "\n"


def timeline_to_sentence(timeline: SpeechTimeline, *, fps: float) -> str:
    """The visemes as the thesis's stored script (Lua)::

        Sentence = {
        {"silence", 11},
        {"A", 6},
        ...
        }

    Durations are whole frames at ``fps``; boundaries are rounded once each (no drift), and
    a viseme that rounds to no frame is left out.
    """
    fps = check_fps(fps)
    header = f"-- viseme script: {len(timeline.visemes)} visemes, frames at {fps:g} fps"
    lines = [header, "Sentence = {"]
    for v in timeline.visemes:
        frames = round(v.end_ms * fps / 1000) - round(v.start_ms * fps / 1000)
        if frames > 0:
            lines.append(f'{{"{script_name(v.viseme)}", {frames}}},')
    lines.append("}")
    return "\n".join(lines) + "\n"


def visemes_from_cues(cues: Sequence[VisemeCue]) -> tuple[VisemeSpan, ...]:
    """Viseme spans of a stored viseme script (``SpeechSpec.visemes``), names mapped by
    ``mpeg4_visemes.csv``. An unknown name raises :class:`FdlError` at the cue's file and line."""
    spans = []
    for cue in cues:
        try:
            vid = viseme_id(cue.viseme)
            spans.append(VisemeSpan(vid, viseme_name(vid), int(cue.start_ms), int(cue.end_ms)))
        except ParameterError as exc:
            path, line = cue.origin if cue.origin else (None, None)
            raise FdlError(exc.message, path=path, line=line) from exc
    return tuple(sorted(spans, key=lambda s: s.start_ms))


def write_timeline(timeline: SpeechTimeline, path: str | Path, *, fps: float = 25.0) -> Path:
    """Write ``timeline`` by the file's extension: ``.json``, ``.tsv`` or ``.sb``/``.lua``/
    ``.fdl`` (a ``Sentence`` script at ``fps``). Atomic (temp file + rename)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".json":
        text = json.dumps(timeline_to_json(timeline), indent=1) + "\n"
    elif suffix == ".tsv":
        text = timeline_to_tsv(timeline)
    elif suffix in (".sb", ".lua", ".fdl"):
        text = timeline_to_sentence(timeline, fps=fps)
    else:
        raise ParameterError(f"unknown timeline format {path.suffix!r} of {path}; "
                             "use .json, .tsv or .sb")
    write_text_atomic(path, text)
    return path
