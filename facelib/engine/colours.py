"""Colour arithmetic shared by everything that shows a face: sRGB to linear, and the
darkening by baked ambient occlusion (``Face.vertex_ao``) that the renderer and the glTF
export both apply, so that an exported head looks like a rendered one."""

from __future__ import annotations

import numpy as np

__all__ = ["occlusion_factor", "srgb_to_linear"]


def srgb_to_linear(rgb: np.ndarray) -> np.ndarray:
    """sRGB colours in [0, 1] (any shape; clipped to the range) -> linear, ``float32``,
    same shape (the sRGB transfer function: linear below 0.04045, a 2.4 power above)."""
    rgb = np.clip(np.asarray(rgb, np.float32), 0.0, 1.0)
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4).astype(np.float32)


def occlusion_factor(occlusion: np.ndarray, *, strength: np.ndarray | float,
                     power: np.ndarray | float = 1.0) -> np.ndarray:
    """``(V,) float32`` factor by which linear colours are darkened: ``1 - strength * (1 -
    occlusion ** power)``, ``occlusion`` ``(V,)`` in [0, 1] (1 = open sky; clipped to the
    range), ``strength`` and ``power`` numbers or ``(V,)``."""
    ao = np.clip(np.asarray(occlusion, np.float32), 0.0, 1.0)
    return np.asarray(1.0 - strength * (1.0 - ao ** power), np.float32)
