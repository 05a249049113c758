"""sRGB to linear and the ambient occlusion factor shared by the renderer and glTF export."""

from __future__ import annotations

import numpy as np

from facelib.engine.colours import occlusion_factor, srgb_to_linear


def test_srgb_to_linear_known_values() -> None:
    out = srgb_to_linear(np.array([[-0.2, 0.04, 0.5], [1.0, 1.5, 0.2140]]))
    assert out.dtype == np.float32 and out.shape == (2, 3)
    np.testing.assert_allclose(out, [[0.0, 0.04 / 12.92, 0.214041], [1.0, 1.0, 0.0376357]],
                               rtol=1e-5, atol=1e-7)


def test_occlusion_factor() -> None:
    ao = np.array([1.0, 0.0, 0.25, 2.0])
    np.testing.assert_allclose(occlusion_factor(ao, strength=0.8), [1.0, 0.2, 0.4, 1.0],
                               rtol=1e-6)
    # a power above 1 darkens the half-occluded more; one per vertex
    out = occlusion_factor(ao, strength=1.0, power=np.array([1.0, 1.0, 0.5, 1.0]))
    assert out.dtype == np.float32
    np.testing.assert_allclose(out, [1.0, 0.0, 0.5, 1.0], rtol=1e-6)
