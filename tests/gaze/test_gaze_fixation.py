"""Fixational drift and micro-saccades during gaze holds (issue 14, item 8)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.cues import GazeCue
from facelib.gaze import animate
from facelib.gaze.events import Saccade
from facelib.gaze.fixation import fixational_motion, hold_envelope
from facelib.gaze.model import gaze_model

FPS = 25.0
TARGET = np.array([10.0, 0.0])  # lookTo left 10 deg, eyes only


def _hold(seed: int, seconds: float = 4.0):  # type: ignore[no-untyped-def]
    """A lookTo that holds its target: the eyes from 1 s to the end (3 s for 4 s)."""
    cue = GazeCue("lookTo", ("left", 10.0, "no"), 0, int(seconds * 1000) + 1000)
    anim = animate([cue], fps=FPS, n_frames=int(seconds * FPS), seed=seed)
    (look,) = anim.saccades
    assert look.start + look.duration < 0.2  # one saccade at the start, then a long hold
    return anim, anim.eyes[int(FPS):] - TARGET


def _steps(offsets: np.ndarray) -> int:
    """Micro-saccade steps seen in the angles: runs of frames whose 2-frame change exceeds
    0.1 deg (a step is 0.15-0.35 deg in 25 ms; drift moves about 0.02 deg a frame)."""
    jump = np.hypot(*(offsets[2:] - offsets[:-2]).T) > 0.1
    return int((jump & ~np.r_[False, jump[:-1]]).sum())


def test_a_three_second_hold_moves_a_little_and_is_seeded():
    anim, offsets = _hold(seed=5)
    radius = np.hypot(offsets[:, 0], offsets[:, 1])
    assert radius.max() < 0.5  # degrees
    assert np.ptp(offsets, axis=0).min() > 0.05  # not frozen, in both directions
    assert len(np.unique(np.round(offsets, 6), axis=0)) > 0.9 * len(offsets)  # drifts
    assert _steps(offsets) >= 1
    again, same = _hold(seed=5)
    assert np.array_equal(same, offsets) and again.microsaccades == anim.microsaccades
    _, other = _hold(seed=6)
    assert not np.array_equal(other, offsets)
    # the gaze line itself (what the planner aimed at) holds the target exactly
    assert np.abs(anim.gaze[int(FPS):] - TARGET).max() < 1e-9


def test_micro_saccades_come_about_one_to_two_a_second():
    seen, logged, held = 0, 0, 0.0
    for seed in range(8):
        anim, offsets = _hold(seed=seed)
        seen += _steps(offsets)
        logged += sum(1 for t in anim.microsaccades if t >= 1.0)
        held += len(offsets) / FPS
        assert np.hypot(offsets[:, 0], offsets[:, 1]).max() < 0.5
    assert 1.0 <= seen / held <= 2.2
    assert abs(seen - logged) <= 0.15 * logged  # the steps in the angles are the logged ones


def test_a_saccade_resets_the_hold_and_the_offsets_stay_inside_the_disk():
    times = np.arange(100) / FPS
    saccade = Saccade(start=1.0, duration=0.05, magnitude=5.0, direction=0.0, head=0.0,
                      kind="away")
    still = hold_envelope(times, [saccade])
    p = gaze_model()["fixation"]
    assert still[int(1.02 * FPS)] == 0.0  # inside the saccade
    assert still[int((1.05 + p["onset_s"]) * FPS)] == pytest.approx(0.0, abs=0.3)
    assert still[-1] == 1.0 and still[int(0.9 * FPS)] == 1.0
    motion = fixational_motion(np.random.default_rng(0), np.arange(20000) / FPS,
                               still=np.ones(20000))
    assert np.hypot(*motion.offsets.T).max() <= p["max_deg"] + 1e-12
    assert 1.2 <= len(motion.microsaccades) / (20000 / FPS) <= 1.8


def test_drift_filter_matches_scipy_lfilter_bit_for_bit():
    # the drift's recursive filter is written out so import facelib need not load
    # scipy.signal (issue 30); it must be the same arithmetic
    from scipy.signal import lfilter

    from facelib.gaze.fixation import _recursive

    noise = np.random.default_rng(3).standard_normal((5000, 2)) * 0.3
    noise[7] = [-0.0, 0.0]
    for a in (0.0, 0.2, float(np.exp(-0.4 / 25.0)), 0.999999):
        expected = lfilter([1.0], [1.0, -a], noise, axis=0)
        assert np.array_equal(_recursive(noise, a), expected)
        assert np.array_equal(np.signbit(_recursive(noise, a)), np.signbit(expected))
