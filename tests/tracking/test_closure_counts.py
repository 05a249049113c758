"""How the closed loop counts lip closures (facelib.tracking.closedloop), on made-up gaps."""

from __future__ import annotations

import numpy as np

from facelib.tracking.closedloop import (
    bilabial_closures,
    closure_recall,
    curve_correlation,
    curve_gain,
    false_closures,
    lip_closures,
)
from facelib.visemes.timeline import VisemeSpan, bilabial_spans

FPS = 25.0


def true_gap() -> np.ndarray:
    """``(60,)`` inner-lip gap (MNS0): an m at frames 10-12, a near-touch of another
    consonant at 20, and a p at 30 that runs on into a 0.6 s pause (frames 30-44)."""
    gap = np.full(60, 0.3)
    gap[10:13] = -0.2
    gap[20] = 0.08
    gap[30:45] = -0.1
    return gap


def test_brief_contacts_and_bilabial_closures_differ() -> None:
    gap = true_gap()
    assert lip_closures(gap, FPS) == [(10, 13), (20, 21)]  # the pause is too long
    bilabial = [(400.0, 500.0), (1160.0, 1240.0)]  # ms: frames 10-12.5 and 29-31
    assert bilabial_closures(gap, bilabial, FPS) == [(10, 13), (30, 45)]
    assert bilabial_closures(gap, [], FPS) == []


def test_lips_must_touch_and_part_again() -> None:
    truth = true_gap()
    events = bilabial_closures(truth, [(400.0, 500.0)], FPS)
    apart = np.full(60, 0.25)
    apart[11] = 0.0                      # touches at 11, parts on both sides
    assert closure_recall(events, apart) == 1.0
    assert closure_recall(events, apart, truth_gap=truth) == 1.0
    shut = apart.copy()
    shut[:13] = 0.0                      # touches but never parts before the m
    assert closure_recall(events, shut) == 1.0
    assert closure_recall(events, shut, truth_gap=truth) == 0.0
    assert false_closures(truth, apart) == 0
    extra = apart.copy()
    extra[52:55] = 0.0                   # the avatar closes where the source does not
    assert false_closures(truth, extra) == 1


def test_bilabial_spans_come_from_viseme_1_only() -> None:
    track = [VisemeSpan(0, "sil", 0, 300), VisemeSpan(1, "PP", 300, 380, ("M",)),
             VisemeSpan(10, "aa", 380, 500, ("AY",)), VisemeSpan(1, "PP", 500, 560, ("B",))]
    assert bilabial_spans(track) == [(300, 380), (500, 560)]
    assert bilabial_spans(None) == []  # an animation without speech


def test_curve_agreement() -> None:
    t = np.sin(np.linspace(0, 6, 50))
    assert abs(curve_correlation(t, 0.5 * t + 3) - 1) < 1e-12
    assert abs(curve_gain(t, 0.5 * t + 3) - 0.5) < 1e-12
    assert np.isnan(curve_correlation(t, np.zeros(50)))
    assert np.isnan(curve_gain(np.zeros(50), t))
