"""Noise for idle motion: Perlin noise for the head (thesis 4.2.4, "head control") and
Gaussian-smoothed white noise of an exact standard deviation for a face alive between cues."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["perlin1d", "smooth_noise"]


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


def smooth_noise(phase: np.ndarray, *, seed: int | Sequence[int], smooth_s: float,
                 step_s: float = 0.05) -> np.ndarray:
    """Smooth stationary Gaussian noise of standard deviation 1, sampled at ``phase``.

    phase: ``(n,)`` float seconds, non-decreasing from about 0 (a time, or a time scaled
    frame by frame by a rate). White noise on a lattice of ``step_s`` is convolved with a
    Gaussian of sd ``smooth_s`` and divided by the kernel's norm, so every sample has unit
    variance whatever the length; it is read off the lattice by linear interpolation.
    Returns ``(n,) float64``, the same for the same ``seed``.
    """
    phase = np.asarray(phase, dtype=np.float64)
    if phase.size == 0:
        return np.zeros(0)
    sigma = max(smooth_s / step_s, 1e-6)
    half = int(np.ceil(4.0 * sigma))
    kernel = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    kernel /= np.sqrt(np.sum(kernel * kernel))
    points = int(np.ceil(max(float(phase.max()), 0.0) / step_s)) + 2
    white = np.random.default_rng(seed).standard_normal(points + 2 * half)
    lattice = np.convolve(white, kernel, mode="valid")
    return np.interp(phase, np.arange(points) * step_s, lattice)
