"""Fixational eye movements: slow drift and micro-saccades while the gaze holds still.

The parameters and their sources are the ``fixation`` block of
``facelib/data/gaze/model.json``. Drift is an Ornstein-Uhlenbeck random walk per axis
(``dx = -k x dt + sqrt(2 D) dW``, sampled exactly on the frame grid); micro-saccades are a
Poisson process with a refractory time whose steps aim back at the fixation point, each a
short linear ramp. The offset is clamped to a disk of ``max_deg`` and scaled by a hold
envelope that is 0 during a saccade and fades in once the eyes have held still a moment, so
only long gaze holds show it. Every draw comes from the caller's generator (split into one
per process: drift, onsets, steps): the same seed gives the same offsets bit for bit, and a
longer clip the same offsets over its start.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from facelib.gaze.events import Saccade
from facelib.gaze.model import gaze_model

__all__ = ["Fixational", "fixational_motion", "hold_envelope"]


@dataclass(frozen=True, eq=False)
class Fixational:
    """What :func:`fixational_motion` made.

    offsets: (n, 2) float64 degrees (left, up) to add to the eyes' rotation.
    microsaccades: (k,) float64 onsets in seconds of the micro-saccades that show (those
        where the hold envelope is above zero).
    """

    offsets: np.ndarray
    microsaccades: np.ndarray


def hold_envelope(times: np.ndarray, saccades: Sequence[Saccade]) -> np.ndarray:
    """(n,) float64 in [0, 1] at ``times`` (n,) seconds: 0 inside a saccade, rising linearly
    from 0 to 1 over ``ramp_s`` once ``onset_s`` has passed since the last saccade ended (or
    since the start)."""
    p = gaze_model()["fixation"]
    times = np.asarray(times, dtype=float)
    starts = np.array([s.start for s in saccades], dtype=float)
    order = np.argsort(starts, kind="stable")
    starts = starts[order]
    ends = np.array([s.start + s.duration for s in saccades], dtype=float)[order]
    last = np.searchsorted(starts, times, side="right")  # 1 + the last saccade begun
    held_from = np.r_[0.0, ends][last]  # its end, or the start of the clip (0 s)
    since = times - held_from
    ramp = np.clip((since - float(p["onset_s"])) / float(p["ramp_s"]), 0.0, 1.0)
    return np.where(since < 0.0, 0.0, ramp)


def _drift(rng: np.random.Generator, n: int, dt: float) -> np.ndarray:
    """(n, 2) Ornstein-Uhlenbeck drift in degrees sampled every ``dt`` seconds, starting
    from its stationary spread."""
    p = gaze_model()["fixation"]
    k, diffusion = float(p["drift_return_per_s"]), float(p["drift_diffusion_deg2_s"])
    a = np.exp(-k * dt)
    spread = np.sqrt(diffusion / k)  # stationary sd per axis
    start = rng.standard_normal(2) * spread
    noise = rng.standard_normal((n, 2)) * spread * np.sqrt(1.0 - a * a)
    noise[0] = start
    return _recursive(noise, float(a))


def _recursive(noise: np.ndarray, a: float) -> np.ndarray:
    """``(n, 2) float64``: ``y[i] = noise[i] + a * y[i - 1]`` down each column (``y[-1] = 0``).

    The first-order recursive filter written out in Python floats: the same arithmetic, in
    the same order, as ``scipy.signal.lfilter([1], [1, -a], noise, axis=0)`` (bit for bit),
    without importing ``scipy.signal`` (over a second of CPU) with ``facelib``.
    """
    out = np.empty(noise.shape, np.float64)
    for column in range(noise.shape[1]):
        previous = 0.0
        values = noise[:, column].tolist()
        for i, x in enumerate(values):
            previous = x + a * previous
            values[i] = previous
        out[:, column] = values
    return out


def _onsets(rng: np.random.Generator, seconds: float) -> np.ndarray:
    """Micro-saccade onsets in ``[0, seconds)``: a Poisson process of the model's rate
    whose intervals are at least the refractory time."""
    p = gaze_model()["fixation"]
    rate, refractory = float(p["microsaccades_per_s"]), float(p["refractory_s"])
    mean_gap = max(1.0 / rate - refractory, 1e-3)
    out, t = [], float(rng.exponential(1.0 / rate))
    while t < seconds:
        out.append(t)
        t += refractory + float(rng.exponential(mean_gap))
    return np.array(out, dtype=float)


def fixational_motion(rng: np.random.Generator, times: np.ndarray, *,
                      still: np.ndarray) -> Fixational:
    """Drift and micro-saccades at ``times`` ((n,) seconds, evenly spaced from 0), scaled by
    the hold envelope ``still`` ((n,) in [0, 1], see :func:`hold_envelope`)."""
    p = gaze_model()["fixation"]
    times = np.asarray(times, dtype=float)
    n = times.size
    if n == 0:
        return Fixational(np.zeros((0, 2)), np.zeros(0))
    dt = float(times[1] - times[0]) if n > 1 else 1.0
    # each process draws from its own generator, so a longer clip keeps its start
    drift_rng, onset_rng, rng = rng.spawn(3)
    drift = _drift(drift_rng, n, dt)
    onsets = _onsets(onset_rng, float(times[-1]) + dt)
    low, high = (float(v) for v in p["amplitude_deg"])
    duration, spread = float(p["duration_s"]), np.radians(float(p["aim_sd_deg"]))
    jumps, partial, done = np.zeros((n + 1, 2)), np.zeros((n, 2)), np.zeros(2)
    for t in onsets:  # the refractory time lets each step end before the next begins
        here = drift[min(int(np.searchsorted(times, t)), n - 1)] + done
        aim = np.arctan2(-here[1], -here[0]) + spread * float(rng.standard_normal())
        step = float(rng.uniform(low, high)) * np.array([np.cos(aim), np.sin(aim)])
        first = int(np.searchsorted(times, t, side="right"))
        full = int(np.searchsorted(times, t + duration, side="left"))
        jumps[full] += step
        partial[first:full] += ((times[first:full] - t) / duration)[:, None] * step
        done += step
    steps = np.cumsum(jumps[:n], axis=0) + partial
    offsets = drift + steps
    radius = np.hypot(offsets[:, 0], offsets[:, 1])
    limit = float(p["max_deg"])
    offsets *= np.minimum(1.0, limit / np.maximum(radius, 1e-12))[:, None]
    still = np.asarray(still, dtype=float)
    shown = onsets[still[np.minimum(np.searchsorted(times, onsets), n - 1)] > 0]
    return Fixational(offsets * still[:, None], shown)
