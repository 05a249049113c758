"""One Euro filter, rigid pose fit and the rig fit on exact (model-made) landmark motion."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.engine.rigid import rotation_matrices
from facelib.mpeg4 import FapStream
from facelib.tracking.embedding import default_head_embedding
from facelib.tracking.faps import default_rig
from facelib.tracking.pose import HeadPose, euler_angles, fit_pose, refine_pose_2d, unpose_2d
from facelib.tracking.rigfit import fit_faps
from facelib.tracking.smoothing import one_euro


def test_one_euro_removes_jitter_and_keeps_a_blink():
    rng = np.random.default_rng(7)
    n = 200
    blink = np.zeros(n)
    blink[100:106] = [0.3, 0.8, 1.0, 1.0, 0.7, 0.2]  # a 6-frame blink at 25 fps
    noisy = blink + rng.normal(0, 0.02, n)
    out = one_euro(noisy[:, None], fps=25)[:, 0]
    assert out[:90].std() < 0.7 * noisy[:90].std()     # jitter on a still face shrinks
    assert out[100:108].max() > 0.8                    # the blink keeps its depth
    const = one_euro(np.full((10, 3), 4.0), fps=25)
    np.testing.assert_array_equal(const, 4.0)


def test_two_way_one_euro_does_not_lag():
    """A 5 Hz syllable rhythm at 25 fps: the causal filter's output lags (its correlation
    with the input drops), the two-way one (forward and reversed passes averaged) does not;
    a blink keeps its depth and its centre in time."""
    wave = np.sin(2 * np.pi * 5 * np.arange(100) / 25)[:, None]
    causal, both = (one_euro(wave, fps=25, causal=c)[10:90, 0] for c in (True, False))
    assert np.corrcoef(causal, wave[10:90, 0])[0, 1] < 0.95
    assert np.corrcoef(both, wave[10:90, 0])[0, 1] > 0.99
    blink = np.zeros((60, 1))
    blink[30:36, 0] = [0.3, 0.8, 1.0, 1.0, 0.7, 0.2]
    frames = np.arange(60)
    centre = frames @ blink[:, 0] / blink.sum()
    causal, both = (one_euro(blink, fps=25, causal=c)[:, 0] for c in (True, False))
    assert both.max() > 0.85
    assert abs(frames @ both / both.sum() - centre) < 0.05
    assert frames @ causal / causal.sum() - centre > 0.3


def test_pose_fit_recovers_a_similarity():
    rng = np.random.default_rng(1)
    x = rng.normal(size=(12, 3)) * [40, 40, 20]
    rot = rotation_matrices(np.array([0.1, -0.2]), np.array([0.35, 0.0]), np.array([0.05, 0.3]))
    y = 1.3 * np.einsum("nij,sj->nsi", rot, x) + np.array([[4, -2, 7], [0, 9, 1]])[:, None]
    pose = fit_pose(x, y)
    np.testing.assert_allclose(pose.scale, 1.3)
    np.testing.assert_allclose(pose.rotation, rot, atol=1e-9)
    pitch, yaw, roll = euler_angles(pose.rotation)
    np.testing.assert_allclose([pitch, yaw, roll], [[0.1, -0.2], [0.35, 0.0], [0.05, 0.3]],
                               atol=1e-12)  # yaw 0.0 comes back as a rounding error
    # the image-plane refinement ignores a garbage depth
    y_bad = y.copy()
    y_bad[..., 2] = rng.normal(size=y.shape[:2]) * 30
    start = HeadPose(np.ones(2), np.repeat(np.eye(3)[None], 2, 0), np.zeros((2, 3)))
    refined = refine_pose_2d(x, y_bad, start, iterations=10)
    np.testing.assert_allclose(refined.rotation, rot, atol=1e-6)
    back = unpose_2d(y_bad, x, refined)
    np.testing.assert_allclose(back, np.broadcast_to(x, back.shape), atol=1e-6)


def test_rig_fit_inverts_the_default_head():
    face = default_face()
    rig = default_rig()
    truth = np.zeros((3, 84), np.float32)
    truth[1, [2, 52, 58, 30, 18]] = (300, 120, 150, 80, 500)
    truth[2, [53, 59, 50, 51]] = (-90, 200, 60, 120)
    moved = face.deform(FapStream(25, truth))[:, default_head_embedding()[rig.landmarks], :2]
    # the FAPU a tracker would measure on this face with its own landmarks
    measured = {name: face.fapu[name] / rig.fapu_ratio[name] for name in face.fapu}
    found = fit_faps(rig, moved - moved[0], measured, ridge=0.0)
    column = {int(f): i for i, f in enumerate(rig.faps)}
    for frame, fap_id in ((1, 3), (1, 53), (1, 59), (1, 31), (1, 19), (2, 54), (2, 60)):
        assert found[frame, column[fap_id]] == pytest.approx(truth[frame, fap_id - 1], rel=0.1,
                                                             abs=10), fap_id
