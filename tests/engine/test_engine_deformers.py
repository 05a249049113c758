"""Raised cosine (eq. 4.7) and multiquadric RBF (eq. 4.8-4.10) weights."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine.deformers.linear import raised_cosine_weights, rbf_weights
from facelib.errors import FaceModelError


def test_raised_cosine_profile() -> None:
    d = np.linspace(0.0, 2.0, 21)
    members = np.stack([d, np.zeros_like(d), np.zeros_like(d)], 1)
    w = raised_cosine_weights(members, np.zeros((1, 3)))[:, 0]
    expected = (1 + np.cos(np.pi * d / 2.0)) * 0.5  # eq. 4.7 with w = 0.5, d_max = 2
    np.testing.assert_allclose(w, expected, atol=1e-12)
    assert w[0] == 1.0 and w[-1] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.diff(w) <= 0)


def test_raised_cosine_falls_to_zero_at_the_region_edge() -> None:
    """A region that is not a disc: the falloff ends at its nearest edge vertex."""
    d = np.linspace(0.0, 2.0, 21)
    members = np.stack([d, np.zeros_like(d), np.zeros_like(d)], 1)
    edge = np.array([[1.0, 0.0, 0.0]])
    w = raised_cosine_weights(members, np.zeros((1, 3)), edge=edge)[:, 0]
    np.testing.assert_allclose(w[:11], (1 + np.cos(np.pi * d[:11])) * 0.5, atol=1e-12)
    assert not w[10:].any()


def test_raised_cosine_averages_several_points() -> None:
    members = np.array([[0.0, 0, 0], [1.0, 0, 0], [0.5, 0, 0]])
    controls = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    w = raised_cosine_weights(members, controls)
    assert w[0, 0] == pytest.approx(0.5)  # averaged: 1/2 of the cosine at the point
    assert w[2, 0] == pytest.approx(w[2, 1])


def test_rbf_interpolates_controls_and_pins_anchors(rng: np.random.Generator) -> None:
    controls = rng.uniform(-1, 1, (5, 3))
    angles = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    anchors = np.stack([3 * np.cos(angles), 3 * np.sin(angles), np.zeros_like(angles)], 1)
    m = rbf_weights(np.concatenate([controls, anchors]), controls, anchors)
    np.testing.assert_allclose(m[:5], np.eye(5), atol=1e-9)
    np.testing.assert_allclose(m[5:], 0, atol=1e-9)


def test_rbf_is_smooth_between_sources() -> None:
    controls = np.array([[0.0, 0, 0]])
    anchors = np.array([[-1.0, 0, 0], [1.0, 0, 0]])
    xs = np.linspace(-1, 1, 41)
    members = np.stack([xs, np.zeros_like(xs), np.zeros_like(xs)], 1)
    w = rbf_weights(members, controls, anchors)[:, 0]
    assert w[20] == pytest.approx(1.0)
    assert w[0] == pytest.approx(0.0, abs=1e-12) and w[-1] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.diff(w[:21]) > 0) and np.all(np.diff(w[20:]) < 0)
    np.testing.assert_allclose(w, w[::-1], atol=1e-12)


def test_rbf_needs_distinct_sources() -> None:
    with pytest.raises(FaceModelError):
        rbf_weights(np.zeros((2, 3)), np.zeros((1, 3)), np.zeros((1, 3)))


def test_raised_cosine_with_its_point_on_the_edge_falls_off_over_the_region():
    """Issue 14: a feature point on its region's edge used to give a 1 m radius (the region
    moved rigidly); now the falloff spans the region, the point moves fully, the far side
    not at all, and a region with no extent is an error."""
    members = np.array([[0.0, 0, 0], [0.005, 0, 0], [0.010, 0, 0], [0.015, 0, 0]])
    w = raised_cosine_weights(members, members[:1], edge=members[[0, 3]])[:, 0]
    np.testing.assert_allclose(w, [1.0, 0.75, 0.25, 0.0], atol=1e-12)
    # an edge far enough away still sets the radius
    w = raised_cosine_weights(members, members[1:2], edge=members[[3]])[:, 0]
    np.testing.assert_allclose(w[[1, 3]], [1.0, 0.0], atol=1e-12)
    with pytest.raises(FaceModelError, match="no extent"):
        raised_cosine_weights(members[:1], members[:1], edge=members[:1])
