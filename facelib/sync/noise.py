"""Perlin noise for idle head motion (thesis 4.2.4, "head control")."""

from __future__ import annotations

import numpy as np

__all__ = ["perlin1d"]


def perlin1d(x: np.ndarray, *, seed: int, octaves: int = 1) -> np.ndarray:
    """Ken Perlin's gradient noise in one dimension, summed over ``octaves``.

    x: ``(n,)`` float positions (one unit = one lattice cell = one period of the base
    octave). Each octave doubles the frequency and halves the amplitude. Returns ``(n,)
    float64`` in about [-1, 1] (normalised by the octaves' total amplitude), 0 at every
    lattice point of the base octave, smooth (C2, through the quintic fade) everywhere,
    and the same for the same ``seed``; for ``x`` from 0, the values at a prefix of ``x``
    do not depend on how far ``x`` goes on.
    """
    x = np.asarray(x, dtype=np.float64)
    total = np.zeros_like(x)
    norm = 0.0
    for octave in range(octaves):
        scale = 2.0**octave
        p = x * scale
        cell = np.floor(p).astype(np.int64)
        lo = int(cell.min(initial=0))
        # one generator per octave, so the gradients of the cells from ``lo`` on are the
        # same however far ``x`` reaches: a longer stream keeps its start bit for bit
        rng = np.random.default_rng(seed if octave == 0 else [seed, octave])
        gradients = rng.uniform(-1.0, 1.0, int(cell.max(initial=0)) - lo + 2)
        f = p - cell
        g0 = gradients[cell - lo]
        g1 = gradients[cell - lo + 1]
        fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0)
        # Gradient contributions from both lattice ends; the factor 2 maps the range to ~[-1, 1].
        total += 2.0 * (g0 * f + fade * (g1 * (f - 1.0) - g0 * f)) / scale
        norm += 1.0 / scale
    return total / norm
