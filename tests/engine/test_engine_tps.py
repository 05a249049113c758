"""The TPS warp (third seed eq. 4.1-4.5) and exact closest points (eq. 4.7): tests T-1..T-6
and D-1, D-2 of the transfer reference (section C.4)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.engine.setup.tps import fit_tps
from facelib.engine.surface import (
    barycentric,
    closest_on_triangles,
    closest_points,
    surface,
    vertex_normals,
)
from facelib.errors import FaceModelError


@pytest.fixture(scope="module")
def face():  # type: ignore[no-untyped-def]
    return default_face()


@pytest.fixture(scope="module")
def landmarks(face) -> np.ndarray:  # type: ignore[no-untyped-def]
    return face.vertices[list(face.feature_points.values())].astype(np.float64)


def _moved(points: np.ndarray, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return points * 1.1 + rng.normal(scale=0.004, size=points.shape) + [0.01, -0.02, 0.03]


def _system(source: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """K (n, n) with U = r and P (n, 4) of eq. 4.2-4.3, written out for the check."""
    k = np.linalg.norm(source[:, None] - source[None], axis=2)
    return k, np.c_[np.ones(len(source)), source]


def test_t1_landmarks_are_interpolated(face, landmarks) -> None:  # type: ignore[no-untyped-def]
    target = _moved(landmarks)
    warp = fit_tps(landmarks, target)
    diag = float(np.linalg.norm(np.ptp(target, axis=0)))
    assert np.abs(warp(landmarks) - target).max() <= 1e-9 * diag


def test_t2_side_condition(landmarks) -> None:  # type: ignore[no-untyped-def]
    warp = fit_tps(landmarks, _moved(landmarks))
    _, p = _system(landmarks)
    assert np.abs(p.T @ warp.weights).max() <= 1e-10
    assert np.abs(warp.weights).max() > 1e-3  # a real non-affine part was fitted


def test_t3_affine_targets_are_reproduced(face, landmarks) -> None:  # type: ignore[no-untyped-def]
    a = np.array([[1.2, 0.1, -0.05], [0.02, 0.9, 0.1], [-0.1, 0.05, 1.05]])
    t = np.array([0.3, -0.1, 0.2])
    warp = fit_tps(landmarks, landmarks @ a.T + t)
    assert np.abs(warp.weights).max() <= 1e-10
    everything = face.vertices.astype(np.float64)
    assert np.abs(warp(everything) - (everything @ a.T + t)).max() <= 1e-12
    np.testing.assert_allclose(warp.affine[1:].T, a, atol=1e-12)
    assert warp.bending_energy() == pytest.approx(0.0, abs=1e-20)


def test_t4_coefficients_and_bending_matrix(landmarks) -> None:  # type: ignore[no-untyped-def]
    target = _moved(landmarks)
    n = len(landmarks)
    k, p = _system(landmarks)
    system = np.block([[k, p], [p.T, np.zeros((4, 4))]])
    inverse = np.linalg.inv(system)
    solved = inverse @ np.vstack([target, np.zeros((4, 3))])
    warp = fit_tps(landmarks, target)
    scale = np.abs(solved).max()
    np.testing.assert_allclose(warp.weights, solved[:n], atol=1e-8 * scale)
    np.testing.assert_allclose(warp.affine, solved[n:], atol=1e-8 * scale)
    ln = inverse[:n, :n]
    assert np.abs(ln @ k @ ln - ln).max() <= 1e-10 * np.abs(ln).max()
    eig = np.linalg.eigvalsh((ln + ln.T) / 2)
    tol = 1e-8 * np.abs(eig).max()
    assert int(np.sum(np.abs(eig) <= tol)) == 4
    assert np.all(eig <= tol)
    assert warp.bending_energy() == pytest.approx(-np.einsum("ic,ij,jc->", solved[:n], k,
                                                             solved[:n]), rel=1e-8)
    assert warp.bending_energy() > 0


@pytest.mark.parametrize("kernel", ["linear", "thin_plate_spline"])
def test_t5_jacobian_matches_central_differences(landmarks, kernel: str) -> None:  # type: ignore[no-untyped-def]
    warp = fit_tps(landmarks, _moved(landmarks), kernel=kernel)
    rng = np.random.default_rng(3)
    points = landmarks[rng.choice(len(landmarks), 20)] + rng.normal(scale=0.01, size=(20, 3))
    h = 1e-6
    numeric = np.stack([(warp(points + h * e) - warp(points - h * e)) / (2 * h)
                        for e in np.eye(3)], axis=2)
    assert np.abs(warp.jacobian(points) - numeric).max() <= 1e-7


def test_t6_singular_landmark_sets_are_refused(landmarks) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(FaceModelError, match="at least 4"):
        fit_tps(landmarks[:3], landmarks[:3])
    twice = landmarks.copy()
    twice[5] = twice[9]
    with pytest.raises(FaceModelError, match="same position"):
        fit_tps(twice, twice)
    flat = landmarks.copy()
    flat[:, 2] = 0.1
    with pytest.raises(FaceModelError, match="one plane"):
        fit_tps(flat, flat)


def _skin(face):  # type: ignore[no-untyped-def]
    skin = face.parts["skin"]
    local = np.full(face.n_vertices, -1)
    local[skin.vertex_ids] = np.arange(skin.vertex_ids.size)
    return face.vertices[skin.vertex_ids].astype(np.float64), local[skin.triangles]


def test_d1_surface_points_map_to_themselves(face) -> None:  # type: ignore[no-untyped-def]
    verts, tris = _skin(face)
    surf = surface(verts, tris)
    rng = np.random.default_rng(4)
    which = rng.choice(len(tris), 500)
    weights = rng.dirichlet(np.ones(3), size=500)
    points = np.einsum("mk,mkc->mc", weights, verts[tris[which]])
    found = closest_points(surf, np.vstack([verts, points]))
    assert found.distance.max() <= 1e-15
    inside = barycentric(verts[tris[found.triangle]], np.vstack([verts, points]))
    assert inside.min() >= -1e-9
    np.testing.assert_allclose(found.interpolate(surf, verts), np.vstack([verts, points]),
                               atol=1e-15)


@pytest.mark.slow  # brute force
def test_d2_equals_brute_force(face) -> None:  # type: ignore[no-untyped-def]
    verts, tris = _skin(face)
    surf = surface(verts, tris)
    rng = np.random.default_rng(5)
    points = verts[rng.choice(len(verts), 1000)] + rng.normal(scale=0.004, size=(1000, 3))
    found = closest_points(surf, points)
    corners = verts[tris]
    brute = np.empty(len(points))
    for i in range(0, len(points), 50):
        chunk = points[i : i + 50]
        near = closest_on_triangles(corners[None], chunk[:, None].repeat(len(tris), axis=1))
        brute[i : i + 50] = np.linalg.norm(near - chunk[:, None], axis=2).min(axis=1)
    assert np.abs(found.distance - brute).max() <= 1e-12


def test_d2_normal_check_skips_facing_away(face) -> None:  # type: ignore[no-untyped-def]
    verts, tris = _skin(face)
    surf = surface(verts, tris)
    normals = vertex_normals(verts, tris)
    rng = np.random.default_rng(6)
    ids = rng.choice(len(verts), 300)
    found = closest_points(surf, verts[ids], normals=-normals[ids])  # every face points away
    facing = np.einsum("mc,mc->m", surf.normals[found.triangle], -normals[ids])
    assert np.all((facing >= 0.5) | np.isclose(found.distance, 0))
    assert (found.distance > 0).mean() > 0.9  # it did look past the vertex's own triangles


def test_tps_agrees_with_the_shared_rbf_warp(landmarks) -> None:  # type: ignore[no-untyped-def]
    from facelib.engine.deformers.rbf import warp

    target = _moved(landmarks)
    rng = np.random.default_rng(9)
    points = landmarks.mean(axis=0) + rng.normal(scale=0.08, size=(200, 3))
    for kernel in ("linear", "thin_plate_spline"):
        mine = fit_tps(landmarks, target, kernel=kernel)(points)
        shared = warp(landmarks, target, points, kernel=kernel, degree=1)
        assert np.abs(mine - shared).max() <= 1e-10, kernel
