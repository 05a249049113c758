"""The statistical model against Eyes Alive's numbers, over long fixed-seed simulations."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import stats

from facelib.gaze import simulate
from facelib.gaze.model import (
    direction_bin,
    gaze_model,
    mode_stats,
    saccade_duration,
    saccade_profile,
)


@pytest.fixture(scope="module")
def talking():
    return simulate("default", "talking", 1.0, seconds=3600, seed=11)


@pytest.fixture(scope="module")
def listening():
    return simulate("default", "listening", 1.0, seconds=3600, seed=12)


def _truncated_exponential_cdf(x, lo, hi, scale):
    return (1 - np.exp(-(x - lo) / scale)) / (1 - math.exp(-(hi - lo) / scale))


@pytest.mark.slow  # a long simulation
def test_direction_bins_within_two_points_of_table():
    # Short intervals and no mutual gaze give many drawn saccades in one run (a look away
    # that would leave the allowed disk is shortened along its drawn direction).
    restless = {"restless": {"base": "default", "p_mutual": 0.0, "interval_scale": 0.15}}
    anim = simulate("restless", "talking", seconds=2400, seed=3, behaviours=restless)
    away = np.array([s.direction for s in anim.saccades if s.kind == "away"])
    assert away.size > 8000
    share = np.bincount(direction_bin(away), minlength=8) / away.size * 100
    table = np.array(gaze_model()["saccade"]["direction_percent"])
    assert np.abs(share - table).max() < 2.0


@pytest.mark.parametrize("fixture", ["talking", "listening"])
def test_magnitude_law(fixture, request):
    anim = request.getfixturevalue(fixture)
    mode = fixture
    sac = anim.saccades
    # Looks away that start from mutual gaze are single draws of the magnitude law.
    mags = np.array(
        [b.magnitude for a, b in itertools.pairwise(sac) if b.kind == "away" and a.kind == "mutual"]
    )
    assert mags.size > 100
    cfg = gaze_model()["saccade"]
    lo, hi = cfg["magnitude_min_deg"], mode_stats(mode).magnitude_max_deg
    # The mutual-gaze point is jittered by <= mutual_spread_deg, which moves magnitudes a bit.
    assert mags.max() <= hi + 1e-9
    result = stats.kstest(mags, lambda x: _truncated_exponential_cdf(x, lo, hi, 6.9))
    assert result.pvalue > 0.01
    # P(A) = 15.7 exp(-A / 6.9): the share in [0, 5) vs [5, 10) falls by exp(-5/6.9).
    if mode == "talking":
        low, mid = np.sum(mags < 5), np.sum((mags >= 5) & (mags < 10))
        assert mid / low == pytest.approx(math.exp(-5 / 6.9), rel=0.2)


@pytest.mark.parametrize("fixture", ["talking", "listening"])
def test_interval_means_per_mode(fixture, request):
    anim = request.getfixturevalue(fixture)
    st = mode_stats(fixture)
    starts = np.array([s.start for s in anim.saccades])
    kinds = np.array([s.kind for s in anim.saccades])
    gaps = np.diff(starts)
    for kind, (mean, _) in (("mutual", st.mutual_s), ("away", st.away_s)):
        observed = gaps[kinds[:-1] == kind]
        assert observed.size > 100
        assert observed.mean() == pytest.approx(mean, rel=0.10)
    share_mutual = np.mean(kinds == "mutual")
    assert share_mutual == pytest.approx(st.p_mutual, abs=0.04)


def test_thinking_mode_intervals():
    anim = simulate("default", "thinking", seconds=2400, seed=5)
    st = mode_stats("thinking")
    starts = np.array([s.start for s in anim.saccades])
    kinds = np.array([s.kind for s in anim.saccades])
    gaps = np.diff(starts)
    assert gaps[kinds[:-1] == "away"].mean() == pytest.approx(st.away_s[0], rel=0.10)
    assert gaps[kinds[:-1] == "mutual"].mean() == pytest.approx(st.mutual_s[0], rel=0.10)


def test_saccade_durations_follow_main_sequence(talking):
    for s in talking.saccades[:200]:
        assert s.duration == pytest.approx((25 + 2.4 * s.magnitude) / 1000)
    assert saccade_duration(10.0) == pytest.approx(0.049)


def test_velocity_profile_is_a_skewed_bell():
    u = np.linspace(0, 1, 2001)
    for amp in (2.0, 20.0):
        pos = saccade_profile(u, amp)
        assert pos[0] == 0 and pos[-1] == pytest.approx(1.0)
        vel = np.gradient(pos, u)
        assert (np.diff(pos) >= -1e-12).all()
        assert vel[0] < 0.01 * vel.max() and vel[-1] < 0.01 * vel.max()
        peak = u[np.argmax(vel)]
        assert 0.25 < peak < 0.5  # accelerates faster than it decelerates
    peak_small = u[np.argmax(np.gradient(saccade_profile(u, 2.0), u))]
    peak_large = u[np.argmax(np.gradient(saccade_profile(u, 20.0), u))]
    assert peak_large < peak_small


@pytest.mark.parametrize(("fixture", "rate"), [("talking", 26.0), ("listening", 17.0)])
def test_blink_rates(fixture, rate, request):
    anim = request.getfixturevalue(fixture)
    per_min = len(anim.blinks) / 60.0
    assert per_min == pytest.approx(rate, rel=0.15)
    spontaneous = sum(not b.evoked for b in anim.blinks) / 60.0
    assert spontaneous <= per_min


def test_anatomical_limits_never_exceeded(talking):
    lim = gaze_model()["eye_limits_deg"]
    eyes = talking.eyes
    assert eyes[:, 0].min() >= -lim["yaw"] and eyes[:, 0].max() <= lim["yaw"]
    assert eyes[:, 1].min() >= -lim["down"] and eyes[:, 1].max() <= lim["up"]
    v = talking.track.values
    deg = 1745.329
    assert np.abs(v[:, 22:24]).max() <= lim["yaw"] * deg
    upper = v[:, 18]
    assert upper.max() <= 1024.0 + 1e-3
    head = talking.head
    hl = gaze_model()["head"]["limits_deg"]
    assert np.abs(head[:, 0]).max() <= hl["yaw"]


def test_identical_seed_identical_output():
    a = simulate("default", "talking", 0.9, seconds=60, seed=7)
    b = simulate("default", "talking", 0.9, seconds=60, seed=7)
    c = simulate("default", "talking", 0.9, seconds=60, seed=8)
    assert np.array_equal(a.track.values, b.track.values)
    assert a.saccades == b.saccades and a.blinks == b.blinks
    assert not np.array_equal(a.track.values, c.track.values)
