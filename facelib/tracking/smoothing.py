"""The One Euro filter (Casiez, Roussel and Vogel, CHI 2012) over many signals at once.

A low-pass filter whose cutoff rises with the signal's speed: ``fc = min_cutoff + beta *
|dx/dt|``. A still face keeps a low cutoff (no jitter); a blink or a lip closure moves fast,
raises the cutoff and keeps its depth and timing.

Run causally the filter lags behind fast motion by a frame or two (at 25 fps, speech's
jaw lost 0.03-0.05 of its correlation with the truth on the closed loop, with the model of
the time). A recorded track has its future too, so :func:`measure_faps
<facelib.tracking.faps.measure_faps>` filters it both ways (``causal=False``): the mean of
the forward pass and of the pass over the reversed track, whose lags are equal and
opposite.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.checks import check_fps, check_number

__all__ = ["EuroState", "one_euro", "one_euro_step"]


@dataclass(frozen=True)
class EuroState:
    """Where a causal One Euro filter stands after a frame: its ``(C,)`` output ``value``
    and its ``(C,)`` filtered ``speed`` (signal units per second)."""

    value: np.ndarray
    speed: np.ndarray


def _alpha(cutoff: np.ndarray | float, dt: float) -> np.ndarray:
    tau = 1.0 / (2.0 * np.pi * np.asarray(cutoff, np.float64))
    return 1.0 / (1.0 + tau / dt)


def one_euro(signal: np.ndarray, *, fps: float, min_cutoff: float = 4.0, beta: float = 1.0,
             d_cutoff: float = 1.0, causal: bool = True) -> np.ndarray:
    """Filter ``(n_frames, C)`` signals sampled at ``fps``; returns ``(n_frames, C) float64``.

    Parameters
    ----------
    min_cutoff: Hz, the cutoff of a still signal (> 0).
    beta: s per signal unit, how fast the cutoff rises with speed (>= 0).
    d_cutoff: Hz, the cutoff of the speed estimate (> 0).
    causal: filter forward only (usable live; the first frame passes unchanged); False
        averages the forward pass and the backward one (no lag, for recorded tracks).
    """
    dt = 1.0 / check_fps(fps)
    min_cutoff = check_number("min_cutoff", min_cutoff, low=0, low_open=True)
    beta = check_number("beta", beta, low=0)
    d_cutoff = check_number("d_cutoff", d_cutoff, low=0, low_open=True)
    x = np.asarray(signal, np.float64)
    if not causal:
        forward = one_euro(x, fps=fps, min_cutoff=min_cutoff, beta=beta, d_cutoff=d_cutoff)
        backward = one_euro(x[::-1], fps=fps, min_cutoff=min_cutoff, beta=beta,
                            d_cutoff=d_cutoff)[::-1]
        return 0.5 * (forward + backward)
    out = np.empty_like(x)
    state = None
    for i, row in enumerate(x):
        state = one_euro_step(row, state, dt=dt, min_cutoff=min_cutoff, beta=beta,
                              d_cutoff=d_cutoff)
        out[i] = state.value
    return out


def one_euro_step(signal: np.ndarray, state: EuroState | None, *, dt: float,
                  min_cutoff: float, beta: float, d_cutoff: float) -> EuroState:
    """One frame of the causal filter: ``(C,)`` ``signal`` after ``state`` (None at the first
    frame, which passes unchanged), ``dt`` seconds after it; the parameters are those of
    :func:`one_euro` (not checked here: the live loop calls this every frame)."""
    x = np.asarray(signal, np.float64)
    if state is None:
        return EuroState(x.copy(), np.zeros_like(x))
    speed = state.speed + _alpha(d_cutoff, dt) * ((x - state.value) / dt - state.speed)
    a = _alpha(min_cutoff + beta * np.abs(speed), dt)
    return EuroState(state.value + a * (x - state.value), speed)
