"""The second seed's deformers: tests L-1...L-4 and T-8 of the reference (part C.4)."""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from facelib.engine import load_face
from facelib.engine.deformers import RegionSetup, deformer
from facelib.engine.deformers.frames import frame_map, linearise
from facelib.engine.deformers.interpolation import (
    barycentric_weights,
    feature_point_weights,
    inverse_distance_weights,
    kshirsagar_weight,
)
from facelib.engine.deformers.rbf import interpolation_weights, warp
from facelib.errors import FaceModelError
from facelib.mpeg4.tables import fap_table


def _patch(n: int = 13) -> tuple[np.ndarray, np.ndarray]:
    """A gently curved square patch of side 2: (n*n, 3) vertices and its triangles."""
    xs = np.linspace(-1.0, 1.0, n)
    x, y = np.meshgrid(xs, xs)
    z = 0.15 * (x**2 + y**2)
    verts = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    tris = np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3),
                           np.stack([a, d, c], -1).reshape(-1, 3)])
    return verts, tris


def _setup(kind: str, *, anchors: bool = True, **params: object) -> RegionSetup:
    verts, tris = _patch()
    n = 13
    idx = np.arange(n * n).reshape(n, n)
    border = np.concatenate([idx[0], idx[-1], idx[1:-1, 0], idx[1:-1, -1]])
    controls = idx[[3, 3, 6, 9, 9, 6, 5], [3, 9, 6, 3, 9, 2, 8]]
    if not anchors:
        controls = np.concatenate([controls, idx[[0, 0, 12, 12], [0, 12, 0, 12]]])
        border = np.zeros(0, np.int64)
    members = np.setdiff1d(np.arange(n * n), border)
    algo = deformer(kind)
    return RegionSetup(kind, members.astype(np.int64), controls.astype(np.int64),
                       border.astype(np.int64), verts, tris.astype(np.int64), np.zeros(0),
                       MappingProxyType(algo.resolve(params, region=kind)))


def _full(kind: str, setup: RegionSetup) -> np.ndarray:
    """(Vr, S) weights over all sources (controls, then anchors)."""
    pos = setup.vertices
    sources = pos[np.concatenate([setup.controls, setup.anchors])]
    if kind == "barycentric":
        return barycentric_weights(setup)
    if kind == "feature_point":
        return feature_point_weights(setup)
    if kind == "inverse_distance":
        return inverse_distance_weights(pos[setup.members], sources)
    return interpolation_weights(sources, pos[setup.members], kernel="thin_plate_spline",
                                 degree=1)


KINDS = ("barycentric", "feature_point", "inverse_distance", "rbf")


@pytest.mark.parametrize("kind", KINDS)
def test_l1_partition_of_unity(kind: str) -> None:
    setup = _setup(kind)
    w = _full(kind, setup)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("kind", KINDS)
def test_l2_interpolation_at_controls(kind: str) -> None:
    setup = _setup(kind)
    w = _full(kind, setup)
    rows = np.searchsorted(setup.members, setup.controls)
    own = w[rows, np.arange(setup.controls.size)]
    if kind == "inverse_distance":
        assert np.all((own > 0) & (own < 1)), own  # Point Distance does not interpolate
    else:
        np.testing.assert_allclose(own, 1.0, atol=1e-9)
        np.testing.assert_allclose(np.abs(w[rows]).sum(axis=1), 1.0, atol=1e-9)
    assert deformer(kind).interpolating == (kind != "inverse_distance")


def test_feature_point_seed_variant_uses_three_sources() -> None:
    setup = _setup("feature_point", influences="nearest")
    w = feature_point_weights(setup)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    assert (np.count_nonzero(w, axis=1) <= 3).all()
    assert (np.count_nonzero(feature_point_weights(_setup("feature_point")), axis=1) > 3).any()
    with pytest.raises(FaceModelError, match="influences must be"):
        feature_point_weights(_setup("feature_point", influences="all"))


def test_l3_kshirsagar_weight() -> None:
    reach = np.array([2.0, 2.0, 2.0, 2.0])
    w = kshirsagar_weight(np.array([0.0, 1.0, 2.0, 3.0]), reach)
    np.testing.assert_allclose(w, [1.0, np.sin(np.pi / 4), 0.0, 0.0], atol=1e-15)


def test_barycentric_outside_variants_stay_normalised() -> None:
    for outside in ("exponential", "absolute", "extrapolate"):
        setup = _setup("barycentric", anchors=False, outside=outside)
        # interior controls only: the patch's border lies outside the control mesh
        setup = replace(setup, controls=setup.controls[:7])
        w = barycentric_weights(setup)
        np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
        rows = np.searchsorted(setup.members, setup.controls)
        np.testing.assert_allclose(w[rows], np.eye(7), atol=1e-12)
        if outside != "extrapolate":
            assert w.min() >= 0
    with pytest.raises(FaceModelError, match="outside must be"):
        barycentric_weights(_setup("barycentric", outside="inside"))


@pytest.mark.parametrize("kind", ["soffd", "planar_bones"])
def test_l4_rigid_motion_is_reproduced_by_the_exact_map(kind: str) -> None:
    setup = _setup(kind, anchors=False)
    fmap = frame_map(setup, kind=kind)
    rot = Rotation.from_euler("xyz", [0.4, -0.7, 1.1]).as_matrix()
    centre = np.array([0.3, -2.0, 0.5])
    pos = setup.vertices
    controls = pos[setup.controls]
    dc = (controls - centre) @ rot.T + centre - controls
    members = pos[setup.members]
    expected = (members - centre) @ rot.T + centre - members
    got = fmap.displace(dc[None])[0]
    np.testing.assert_allclose(got, expected, atol=1e-9)
    np.testing.assert_allclose(fmap.displace(np.zeros((1, *dc.shape)))[0], 0.0, atol=1e-12)


@pytest.mark.parametrize("kind", ["soffd", "planar_bones"])
def test_l4_linearisation_is_first_order(kind: str) -> None:
    setup = _setup(kind)
    fmap = frame_map(setup, kind=kind)
    jac = linearise(fmap)
    rng = np.random.default_rng(7)
    direction = rng.normal(size=(setup.controls.size, 3))
    errors = []
    for size in (0.02, 0.01):
        dc = size * direction
        exact = fmap.displace(dc[None])[0]
        errors.append(np.abs(exact - np.einsum("vaib,ib->va", jac, dc)).max())
    assert errors[1] < errors[0] / 3.0  # second order: halving the motion quarters it


@pytest.mark.parametrize("kind", ["soffd", "planar_bones"])
def test_l4_linearised_head_agrees_with_exact_step_for_small_motion(kind: str) -> None:
    lin = load_face(deformers={"lips": kind})
    exact = load_face(deformers={"lips": {"deformer": kind, "mode": "exact"}})
    frame = np.zeros(84, np.float32)
    frame[[4, 5, 6, 11, 12, 15, 16]] = [60, 120, 120, 100, 100, 80, 80]
    # every feature point moves by at most the sum of its FAPs' motions (eq. 4.6)
    reach = sum(abs(float(frame[f.index])) * lin.fapu[f.fapu] for f in fap_table()
                if f.fapu in lin.fapu)
    scale = 1e-3 / reach  # controls move <= 1 mm
    a, b = lin.deform_frame(frame * scale), exact.deform_frame(frame * scale)
    assert np.abs(a - b).max() <= 1e-4  # 0.1 mm
    a, b = lin.deform_frame(frame), exact.deform_frame(frame)
    assert 0 < np.abs(a - b).max() < 5e-3  # measured and reported by the evaluation


def test_t8_rbf_defaults_reproduce_the_thesis_multiquadric() -> None:
    from facelib.engine.deformers.linear import rbf_weights

    rng = np.random.default_rng(11)
    controls, anchors, members = (rng.normal(size=(k, 3)) for k in (6, 20, 50))
    today = rbf_weights(members, controls, anchors)
    new = interpolation_weights(np.concatenate([controls, anchors]), members,
                                kernel="multiquadric_eck", degree=-1)[:, :6]
    assert np.array_equal(today, new)


@pytest.mark.parametrize("kernel", ["multiquadric_eck", "wendland", "thin_plate_spline", "gaussian",
                                    "cubic", "inverse_multiquadric"])
def test_t8_rbf_polynomial_reproduces_translation_and_affine_maps(kernel: str) -> None:
    rng = np.random.default_rng(5)
    sources = rng.normal(size=(30, 3))
    points = rng.normal(size=(200, 3))
    w = interpolation_weights(sources, points, kernel=kernel, degree=1)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-10)
    shift = np.array([0.3, -1.0, 2.0])
    np.testing.assert_allclose(w @ (sources + shift) - points, np.tile(shift, (200, 1)), atol=1e-9)
    affine = np.array([[1.1, 0.2, 0.0], [0.0, 0.9, -0.3], [0.1, 0.0, 1.2]])
    np.testing.assert_allclose(warp(sources, sources @ affine.T, points, kernel=kernel),
                               points @ affine.T, atol=1e-8)
    np.testing.assert_allclose(interpolation_weights(sources, sources, kernel=kernel),
                               np.eye(30), atol=1e-8)


def test_rbf_smoothing_approximates() -> None:
    rng = np.random.default_rng(2)
    sources = rng.normal(size=(20, 3))
    w = interpolation_weights(sources, sources, kernel="thin_plate_spline", smoothing=1.0)
    assert np.abs(np.diag(w)).max() < 1 - 1e-3
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-10)


def test_rbf_rejects_bad_input() -> None:
    with pytest.raises(FaceModelError, match="distinct"):
        interpolation_weights(np.zeros((3, 3)), np.zeros((1, 3)))
    with pytest.raises(FaceModelError, match="degree"):
        interpolation_weights(np.eye(3), np.zeros((1, 3)), degree=2)
