"""Dominance blend: targets reached, bilabial closure, anticipation, envelope."""

from __future__ import annotations

import numpy as np

from facelib.mpeg4.tables import fap
from facelib.visemes import VisemeSpan, blend, envelope, viseme_id, viseme_targets
from facelib.visemes.coarticulation import speaking_mask

JAW = fap("open_jaw").index
LOWER = fap("raise_b_midlip").index
UPPER = fap("lower_t_midlip").index
PUSH = fap("push_t_lip").index


def seq(*items: tuple[str, int, int]) -> list[VisemeSpan]:
    return [VisemeSpan(viseme_id(n), n, a, b) for n, a, b in items]


def test_long_span_reaches_its_target():
    vis = seq(("sil", 0, 200), ("aa", 200, 800), ("sil", 800, 1000))
    values = blend(vis, np.array([500.0]))
    np.testing.assert_allclose(values[0], viseme_targets()[10], atol=1.0)


def test_bilabial_closes_lips_even_inside_open_vowels():
    # "abba": a short p between wide-open vowels
    vis = seq(("aa", 0, 300), ("PP", 300, 360), ("aa", 360, 660))
    times = np.arange(0, 660, 10.0)
    values = blend(vis, times)
    pp = viseme_targets()[1]
    inside = (times >= 300) & (times < 360)
    # upper lip at the closure value; lower lip rises by the jaw's extra opening
    np.testing.assert_allclose(values[inside, UPPER], pp[UPPER], atol=1e-3)
    from facelib.visemes.tables import lower_lip_per_jaw

    jaw_drop = lower_lip_per_jaw() * (values[inside, JAW] - pp[fap("open_jaw").index])
    gap = jaw_drop - (values[inside, LOWER] - pp[LOWER])
    np.testing.assert_allclose(gap, 0.0, atol=1e-3)
    # the closure is smooth: the lower lip travels to the seal over several 10 ms steps
    # (no step more than a fifth of its whole travel)
    travel = np.ptp(values[:, LOWER])
    assert np.abs(np.diff(values[:, LOWER])).max() < travel / 5


def test_bilabial_shorter_than_a_frame_still_closes():
    vis = seq(("aa", 0, 300), ("PP", 300, 310), ("aa", 310, 600))
    times = np.arange(0, 600, 40.0)  # 25 fps: no frame falls inside 300-310
    values = blend(vis, times)
    k = int(np.argmin(np.abs(times - 305)))
    assert values[k, UPPER] == viseme_targets()[1, UPPER]


def test_rounding_is_anticipated_more_than_spreading():
    # lips start to protrude before a rounded vowel, through the consonant before it
    times = np.array([350.0])
    round_vowel = blend(seq(("aa", 0, 300), ("SS", 300, 400), ("ou", 400, 700)), times)
    spread_vowel = blend(seq(("aa", 0, 300), ("SS", 300, 400), ("ih", 400, 700)), times)
    assert round_vowel[0, PUSH] > 0.4 * viseme_targets()[14, PUSH]
    assert spread_vowel[0, PUSH] < 10
    before = blend(seq(("sil", 0, 400), ("ou", 400, 700)), np.array([250.0]))
    assert before[0, PUSH] > 0.1 * viseme_targets()[14, PUSH]


def test_envelope_and_speaking_mask():
    vis = seq(("sil", 0, 1000), ("aa", 1000, 1200), ("sil", 1200, 1400), ("ih", 1400, 1600),
              ("sil", 1600, 4000))
    times = np.arange(0, 4000, 10.0)
    env = envelope(vis, times, ramp_ms=150, release_pause_ms=500)
    assert env[times < 850].max() == 0 and env[times >= 1750].max() == 0
    assert env[(times >= 1000) & (times < 1600)].min() == 1  # the 200 ms pause is held
    assert 0 < env[times == 920][0] < 1
    assert np.all(np.diff(env[times < 1000]) >= 0)
    speaking = speaking_mask(vis, times)
    assert speaking[(times >= 1000) & (times < 1200)].all()
    assert not speaking[(times >= 1200) & (times < 1400)].any()
    # a long pause releases the mouth
    env2 = envelope(vis, times, ramp_ms=150, release_pause_ms=100)
    assert env2[times == 1300][0] < 1
