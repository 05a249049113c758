"""Smooth pursuit of a moving target (Follower Eyes)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.errors import ParameterError
from facelib.gaze import pursue
from facelib.gaze.model import gaze_model


def test_slow_target_is_tracked_smoothly_after_the_latency():
    fps = 50
    t = np.arange(4 * fps) / fps
    target = np.column_stack([10 * np.sin(2 * np.pi * 0.25 * t), np.zeros_like(t)])
    anim = pursue(target, fps=fps, seed=0)
    latency = gaze_model()["pursuit"]["latency_s"]
    moving = np.flatnonzero(np.abs(anim.gaze[:, 0]) > 0.05)
    assert moving[0] / fps >= latency - 1 / fps
    error = np.abs(anim.gaze[fps:, 0] - target[fps:, 0])
    assert error.max() < 2.5
    assert len([s for s in anim.saccades if s.kind == "catch_up"]) <= 10


def test_fast_target_needs_catch_up_saccades():
    fps = 50
    t = np.arange(2 * fps) / fps
    target = np.column_stack([60 * t - 30, np.zeros_like(t)])  # 60 deg/s, past the limit
    anim = pursue(target, fps=fps, seed=0, start_deg=(-30.0, 0.0))
    catch_ups = [s for s in anim.saccades if s.kind == "catch_up"]
    assert len(catch_ups) >= 3
    assert all(abs(((s.direction + 180) % 360) - 180) < 20 for s in catch_ups)  # leftward
    assert anim.gaze[-1, 0] == pytest.approx(target[-1, 0], abs=8)


def test_near_target_makes_the_eyes_converge():
    target = np.zeros((25, 2))
    anim = pursue(target, fps=25, distance_m=0.3)
    left_yaw, right_yaw = anim.track.values[-1, 22], anim.track.values[-1, 23]
    expected = np.degrees(2 * np.arctan(0.0315 / 0.3)) / 2 * np.pi / 180 / 1e-5
    assert left_yaw == pytest.approx(-expected, rel=1e-4)  # left eye turns toward the nose
    assert right_yaw == pytest.approx(expected, rel=1e-4)


def test_pursue_rejects_bad_targets():
    with pytest.raises(ParameterError, match="target_deg"):
        pursue(np.zeros((10, 3)), fps=25)
    with pytest.raises(ParameterError, match="distance_m"):
        pursue(np.zeros((10, 2)), fps=25, distance_m=-1.0)
