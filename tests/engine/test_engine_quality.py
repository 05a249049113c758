"""Dihedral-angle roughness (seed 2, eq. 3.2-3.3, tables 4.3-4.4)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import load_face
from facelib.engine.quality import mean_roughness, triangle_roughness, vertex_roughness
from facelib.errors import ParameterError


def grid(n: int = 6) -> tuple[np.ndarray, np.ndarray]:
    xs, ys = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    verts = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], 1)
    tris = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    return verts, np.array(tris)


def bumped(height: float) -> tuple[np.ndarray, np.ndarray, int]:
    """The seed's test: one triangle in the middle of a flat mesh lifted to a bump's top."""
    verts, tris = grid()
    top = int(np.argmin(np.linalg.norm(verts[tris].mean(1)[:, :2] - [3.3, 2.7], axis=1)))
    verts = verts.copy()
    verts[tris[top], 2] = height
    return verts, tris, top


def test_flat_mesh_is_zero() -> None:
    verts, tris = grid()
    assert np.all(triangle_roughness(verts, tris) == 0)
    g, v = vertex_roughness(verts, tris)
    assert np.all(g == 0) and np.all(v == 0)
    assert mean_roughness(verts, tris) == 0


def test_roughness_grows_with_the_bump() -> None:
    small_v, tris, top = bumped(0.5)
    large_v, _, _ = bumped(2.0)
    small, large = triangle_roughness(small_v, tris), triangle_roughness(large_v, tris)
    # like tables 4.3-4.4: the bump's triangle and the mesh mean both grow with its height
    assert 0 < small[top] < large[top]
    assert 0 < mean_roughness(small_v, tris) < mean_roughness(large_v, tris)
    # far from the bump the mesh stays smooth
    verts, _ = grid()
    far = np.all(np.linalg.norm(verts[tris][:, :, :2] - [3, 3], axis=2) > 2.5, axis=1)
    assert np.all(small[far] == 0)


def test_dihedral_roughness_of_a_fold() -> None:
    # two triangles at right angles: rho_d = 1 - cos(90 deg) = 1 on their shared edge
    verts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    tris = np.array([[0, 1, 2], [0, 3, 1]])
    g, v = vertex_roughness(verts, tris)
    assert g[0] == pytest.approx(1.0) and g[1] == pytest.approx(1.0)
    assert g[2] == 0 and v[0] == 0
    np.testing.assert_allclose(triangle_roughness(verts, tris), [2 / 3, 2 / 3])


def test_default_head_is_smooth_and_jaw_opening_stays_smooth() -> None:
    face = load_face()
    skin = face.parts["skin"]
    rest = mean_roughness(face.vertices, skin.triangles)
    assert 0 < rest < 0.15  # creases at ears, nostrils, mouth corners
    values = np.zeros(84, np.float32)
    values[2] = 500
    opened = mean_roughness(face.deform_frame(values), skin.triangles)
    assert opened < 1.5 * rest
    lips = next(r for r in face.regions if r.name == "lower_lip").vertices
    assert mean_roughness(face.vertices, skin.triangles, vertex_ids=lips) > 0


def test_region_without_triangles() -> None:
    verts, tris = grid(2)
    with pytest.raises(ParameterError):
        mean_roughness(verts, tris, vertex_ids=np.array([0]))
