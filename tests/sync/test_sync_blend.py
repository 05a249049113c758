"""The synchronizer's equations on constructed tracks (thesis 4.2.4, eq. 4.11)."""

import numpy as np
import pytest

from facelib import FapTrack, fap
from facelib.sync import HeadNoise, SyncRules, add_head_noise, blend, close_lids, combine

JAW = fap("open_jaw").index
LID = fap("close_t_l_eyelid").index
YAW = fap("head_yaw").index
EYE = fap("yaw_l_eyeball").index


def _track(n=4, **columns):
    values = np.zeros((n, 84), np.float32)
    weight = np.zeros((n, 84), np.float32)
    for name, (value, w) in columns.items():
        values[:, fap(name).index] = value
        weight[:, fap(name).index] = w
    return FapTrack(25, values, weight)


def test_mouth_conflict_is_eq_4_11():
    e = _track(open_jaw=(100, 1), raise_l_cornerlip=(150, 1))
    v = _track(open_jaw=(200, 1), lower_t_midlip=(-30, 1))
    out = blend(e, v, weight_a=1, weight_b=3)
    assert out.values[0, JAW] == pytest.approx((100 + 3 * 200) / 4)
    assert out.values[0, fap("raise_l_cornerlip").index] == 150  # only E drives: E wins
    assert out.values[0, fap("lower_t_midlip").index] == -30  # only V drives: V wins


def test_weights_from_the_table_change_the_result():
    e = _track(open_jaw=(100, 1))
    v = _track(open_jaw=(200, 1))
    assert blend(e, v, weight_a=1, weight_b=1).values[0, JAW] == pytest.approx(150)
    half = _track(open_jaw=(100, 0.5))  # an expression of importance 0.5
    assert blend(half, v, weight_a=1, weight_b=3).values[0, JAW] == pytest.approx(
        (0.5 * 100 + 3 * 200) / 3.5)


def test_gaze_expression_conflict_is_25_75():
    e = _track(close_t_l_eyelid=(800, 1), head_yaw=(1000, 1))
    g = _track(close_t_l_eyelid=(400, 1), head_yaw=(5000, 1), yaw_l_eyeball=(9000, 1))
    out = blend(e, g, weight_a=0.75, weight_b=0.25)
    assert out.values[0, LID] == pytest.approx(0.75 * 800 + 0.25 * 400)
    assert out.values[0, YAW] == pytest.approx(0.75 * 1000 + 0.25 * 5000)
    assert out.values[0, EYE] == 9000  # eyeballs: only gaze


def test_blinks_close_the_lids_whatever_the_expression_says():
    face = _track(close_t_l_eyelid=(-200, 1))  # an expression holding the eye wide open
    out = close_lids(face, np.array([0.0, 0.5, 1.0, 0.0]), closed=(1024.0, 0.0))
    assert out.values[:, LID].tolist() == pytest.approx([-200, 412, 1024, -200])
    assert out.values[2, fap("close_t_r_eyelid").index] == pytest.approx(1024)


def test_head_noise_is_seeded_bounded_and_keeps_gaze_head_motion():
    n = 500
    base = FapTrack.empty(n, fps=25)
    noise = HeadNoise(amplitude_deg=(2.0, 2.0, 2.0))
    a = add_head_noise(base, noise=noise, seed=1, head_driven=np.zeros(n))
    b = add_head_noise(base, noise=noise, seed=1, head_driven=np.zeros(n))
    c = add_head_noise(base, noise=noise, seed=2, head_driven=np.zeros(n))
    assert np.array_equal(a.values, b.values)
    assert not np.array_equal(a.values, c.values)
    degrees = np.rad2deg(a.values[:, YAW] * 1e-5)
    assert 0.3 < np.abs(degrees).max() <= 2.0
    # slow: no frame-to-frame jump bigger than 0.06 degree at 0.25 Hz (1.5 deg/s; the
    # steepest step of this seed is 0.056 since each octave draws from its own generator)
    assert np.abs(np.diff(degrees)).max() < 0.06
    held = add_head_noise(base, noise=noise, seed=1, head_driven=np.ones(n))
    assert not held.values.any()


def test_speaking_makes_the_head_livelier():
    n = 2500
    base = FapTrack.empty(n, fps=25)
    noise = HeadNoise()
    calm = add_head_noise(base, noise=noise, seed=4, head_driven=np.zeros(n))
    talk = add_head_noise(base, noise=noise, seed=4, head_driven=np.zeros(n),
                          speaking=np.ones(n, bool))
    speed = [np.abs(np.diff(t.values[:, YAW])).mean() for t in (calm, talk)]
    assert speed[1] > 1.5 * speed[0]


def test_combine_masks_driven_faps_in_every_frame():
    e = _track(open_jaw=(100, 1))
    e = FapTrack(25, e.values, e.weight * np.array([[1], [0], [0], [1]], np.float32))
    rules = SyncRules(head_noise=None, alive=None)  # masks of the blend alone
    stream = combine(expressions=e, visemes=FapTrack.empty(4, fps=25),
                     gaze=FapTrack.empty(4, fps=25), rules=rules)
    assert stream.mask[:, JAW].all()
    assert stream.values[:, JAW].tolist() == [100, 0, 0, 100]
    assert stream.active_faps() == (3,)


def test_default_rules_file_gives_the_thesis_weights():
    rules = SyncRules.load()
    assert rules.mouth == (1.0, 3.0)
    assert rules.eyes_head == (0.75, 0.25)
    assert rules.head_noise is not None
