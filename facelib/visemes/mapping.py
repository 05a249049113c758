"""Phones -> visemes: the annex B map, then the timing rules that keep mouth shapes visible.

Each step is a pure function from a tuple of spans to a new tuple of spans.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from facelib.errors import ParameterError
from facelib.visemes.ipa import ipa_viseme
from facelib.visemes.tables import phone_viseme, timing_rules, viseme_name
from facelib.visemes.timeline import Alphabet, PhoneTimeline, Span, SpeechTimeline, VisemeSpan

__all__ = ["enforce_min_duration", "merge_short_silences", "phones_to_visemes", "visemes_for",
           "with_visemes"]

_BILABIAL = 1


def phones_to_visemes(
    phones: Sequence[Span], *, alphabet: Alphabet = "arpabet"
) -> tuple[VisemeSpan, ...]:
    """One viseme span per phone (two for a diphthong, split as the table says; an IPA
    phone of n symbols with distinct visemes: n equal parts); adjacent spans of the same
    viseme are joined and keep all their phones. ``alphabet`` says how the phone labels
    are written: ARPAbet (``phone_to_viseme.csv``) or IPA (``ipa_to_viseme.csv``)."""
    if alphabet not in ("arpabet", "ipa"):
        raise ParameterError(f"alphabet must be 'arpabet' or 'ipa', not {alphabet!r}")
    rule_of = ipa_viseme if alphabet == "ipa" else phone_viseme
    spans: list[VisemeSpan] = []
    for phone in phones:
        rule = rule_of(phone.label)
        label = rule.phone
        n = len(rule.visemes)
        if n == 2:
            mid = phone.start_ms + round(rule.split * phone.duration_ms)
            cuts = [phone.start_ms, mid, phone.end_ms]
        else:
            cuts = [phone.start_ms + round(k * phone.duration_ms / n) for k in range(n + 1)]
        for vid, start, end in zip(rule.visemes, cuts[:-1], cuts[1:], strict=True):
            if end <= start:
                continue
            if spans and spans[-1].viseme == vid and spans[-1].end_ms == start:
                last = spans[-1]
                spans[-1] = replace(last, end_ms=end, phones=(*last.phones, label))
            else:
                spans.append(VisemeSpan(vid, viseme_name(vid), start, end, (label,)))
    return tuple(spans)


def merge_short_silences(
    visemes: Sequence[VisemeSpan], *, below_ms: int | None = None
) -> tuple[VisemeSpan, ...]:
    """Silences inside speech shorter than ``below_ms`` (default: the data file's
    ``merge_silence_below_ms``) are given half to each neighbour, so the mouth does not
    snap shut between words. Leading and trailing silences stay."""
    below = timing_rules()["merge_silence_below_ms"] if below_ms is None else below_ms
    out = list(visemes)
    i = 1
    while i < len(out) - 1:
        span = out[i]
        if span.is_silence and span.duration_ms < below:
            mid = span.start_ms + span.duration_ms // 2
            out[i - 1] = replace(out[i - 1], end_ms=mid)
            out[i + 1] = replace(out[i + 1], start_ms=mid)
            del out[i]
        else:
            i += 1
    return tuple(out)


def enforce_min_duration(
    visemes: Sequence[VisemeSpan], *, min_ms: int | None = None
) -> tuple[VisemeSpan, ...]:
    """Lengthen spans shorter than ``min_ms`` (default: the data file's ``min_visible_ms``)
    by taking time from neighbours that can spare it (they stay at least ``min_ms`` long).
    A span that still cannot be seen is merged into its longer neighbour, except a
    bilabial (p b m), whose closure must show: its neighbour gives way instead."""
    min_len = timing_rules()["min_visible_ms"] if min_ms is None else min_ms
    out = list(visemes)
    # Fix the first span that is too short, then look again from just before it: a fix
    # only touches that span and its neighbours, and never makes an earlier span too short
    # (neighbours lend only what they can spare), so spans further back stay fixed. Linear
    # in the number of spans, where restarting from the first span was quadratic.
    i = 0
    while i < len(out):
        need = min_len - out[i].duration_ms
        if need <= 0 or len(out) == 1:
            i += 1
            continue
        need = _borrow(out, i, need, min_len)
        if need > 0:
            _merge(out, i)
        i = max(i - 2, 0)
    return tuple(out)


def _borrow(out: list[VisemeSpan], i: int, need: int, min_len: int) -> int:
    """Take up to ``need`` ms from the neighbours of ``out[i]``; return what is still needed."""
    for j in sorted((j for j in (i - 1, i + 1) if 0 <= j < len(out)),
                    key=lambda j: -out[j].duration_ms):
        spare = out[j].duration_ms - min_len
        if spare <= 0 or need <= 0:
            continue
        take = min(spare, need)
        if j < i:
            out[j] = replace(out[j], end_ms=out[j].end_ms - take)
            out[i] = replace(out[i], start_ms=out[i].start_ms - take)
        else:
            out[j] = replace(out[j], start_ms=out[j].start_ms + take)
            out[i] = replace(out[i], end_ms=out[i].end_ms + take)
        need -= take
    return need


def _merge(out: list[VisemeSpan], i: int) -> None:
    """Merge the too-short ``out[i]`` with its longer neighbour (a bilabial absorbs it)."""
    neighbours = [j for j in (i - 1, i + 1) if 0 <= j < len(out)]
    j = max(neighbours, key=lambda j: out[j].duration_ms)
    keep, drop = (i, j) if out[i].viseme == _BILABIAL and out[j].viseme != _BILABIAL else (j, i)
    start = min(out[keep].start_ms, out[drop].start_ms)
    end = max(out[keep].end_ms, out[drop].end_ms)
    phones = (*out[min(keep, drop)].phones, *out[max(keep, drop)].phones)
    out[keep] = replace(out[keep], start_ms=start, end_ms=end, phones=phones)
    del out[drop]


def visemes_for(
    phones: Sequence[Span], *, alphabet: Alphabet = "arpabet"
) -> tuple[VisemeSpan, ...]:
    """The whole chain: map, merge short silences, enforce minimum durations."""
    return enforce_min_duration(
        merge_short_silences(phones_to_visemes(phones, alphabet=alphabet))
    )


def with_visemes(timeline: PhoneTimeline) -> SpeechTimeline:
    """``timeline`` (phones and words of :mod:`facelib.speech`) with its viseme spans."""
    return SpeechTimeline(timeline.phones, timeline.words,
                          visemes_for(timeline.phones, alphabet=timeline.alphabet),
                          timeline.source, timeline.duration_ms, alphabet=timeline.alphabet)
