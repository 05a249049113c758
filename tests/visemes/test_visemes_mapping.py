"""Phones -> viseme spans and the timing rules."""

from __future__ import annotations

import itertools

from facelib.visemes import SILENCE, Span, VisemeSpan, phones_to_visemes
from facelib.visemes.mapping import enforce_min_duration, merge_short_silences


def spans(*items: tuple[str, int, int]) -> list[Span]:
    return [Span(label, a, b) for label, a, b in items]


def test_diphthong_is_two_visemes_split_by_table():
    out = phones_to_visemes(spans(("AY", 0, 200)))
    assert [(s.name, s.start_ms, s.end_ms) for s in out] == [("aa", 0, 120), ("ih", 120, 200)]
    assert out[0].phones == ("AY",)


def test_same_viseme_phones_join():
    out = phones_to_visemes(spans(("M", 0, 50), ("B", 50, 120), ("AA", 120, 300)))
    assert [(s.name, s.start_ms, s.end_ms, s.phones) for s in out] == [
        ("PP", 0, 120, ("M", "B")), ("aa", 120, 300, ("AA",))]


def test_short_inner_silence_given_to_neighbours_edges_kept():
    vis = phones_to_visemes(spans((SILENCE, 0, 100), ("AA", 100, 300), (SILENCE, 300, 340),
                                  ("IY", 340, 500), (SILENCE, 500, 900)))
    out = merge_short_silences(vis, below_ms=100)
    assert [(s.name, s.start_ms, s.end_ms) for s in out] == [
        ("sil", 0, 100), ("aa", 100, 320), ("ih", 320, 500), ("sil", 500, 900)]


def test_min_duration_borrows_from_long_neighbours():
    vis = [VisemeSpan(10, "aa", 0, 200), VisemeSpan(4, "DD", 200, 220),
           VisemeSpan(12, "ih", 220, 400)]
    out = enforce_min_duration(vis, min_ms=60)
    assert all(s.duration_ms >= 60 for s in out)
    assert out[0].start_ms == 0 and out[-1].end_ms == 400
    assert [s.name for s in out] == ["aa", "DD", "ih"]
    for a, b in itertools.pairwise(out):
        assert a.end_ms == b.start_ms


def test_unseeable_span_merges_but_bilabial_survives():
    vis = [VisemeSpan(10, "aa", 0, 70), VisemeSpan(4, "DD", 70, 80), VisemeSpan(1, "PP", 80, 90),
           VisemeSpan(12, "ih", 90, 160)]
    out = enforce_min_duration(vis, min_ms=60)
    assert "PP" in [s.name for s in out]
    assert out[0].start_ms == 0 and out[-1].end_ms == 160
    for a, b in itertools.pairwise(out):
        assert a.end_ms == b.start_ms
