"""The one vertex_normals (engine.surface), used by set-up, the renderer and the glTF export."""

from __future__ import annotations

import numpy as np

from facelib.engine.surface import vertex_normals


def test_normals_are_area_weighted_and_unit() -> None:
    # a big triangle in z = 0 and a small one standing in x = 0, sharing vertices 0 and 1
    v = np.array([[0, 0, 0], [0, 1, 0], [-2, 0, 0], [0, 0, 0.1], [5, 5, 5]], float)
    t = np.array([[0, 1, 2], [0, 1, 3]])
    n = vertex_normals(v, t)
    big, small = np.array([0, 0, 2.0]), np.array([0.1, 0, 0])  # cross products (2 x area)
    expected = (big + small) / np.linalg.norm(big + small)
    np.testing.assert_allclose(n[0], expected)
    np.testing.assert_allclose(n[1], expected)
    np.testing.assert_allclose(n[2], [0, 0, 1])
    np.testing.assert_allclose(n[3], [1, 0, 0])
    assert n.dtype == np.float64
    np.testing.assert_array_equal(n[4], [0, 0, 0])  # on no triangle
    np.testing.assert_array_equal(vertex_normals(v, t, unused=(0, 0, 1))[4], [0, 0, 1])


def test_normals_equal_a_corner_by_corner_sum(rng: np.random.Generator) -> None:
    v = rng.normal(size=(40, 3))
    t = rng.integers(0, 30, size=(60, 3))
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    summed = np.zeros_like(v)
    for corner in range(3):
        np.add.at(summed, t[:, corner], n)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    reference = np.divide(summed, length, out=np.zeros_like(summed), where=length > 0)
    np.testing.assert_array_equal(vertex_normals(v, t), reference)  # bit for bit
