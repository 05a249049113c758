"""Smooth pursuit: the eyes follow a moving target with latency, a smooth velocity and
catch-up saccades when the target runs away (thesis 5.2, "Follower Eyes").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from facelib.gaze.model import gaze_model, saccade_duration, saccade_profile

__all__ = ["PursuitPath", "pursue_path"]


@dataclass(frozen=True, slots=True)
class PursuitPath:
    """Result of :func:`pursue_path`.

    t: (m,) float64 seconds from the pursuit start, step ``pursuit.step_s``.
    gaze: (m, 2) float64 degrees (left, up) of the gaze line.
    catch_ups: (start_s, duration_s, (2,) shift in degrees) of each catch-up saccade.
    """

    t: np.ndarray
    gaze: np.ndarray
    catch_ups: tuple[tuple[float, float, tuple[float, float]], ...]


def _sampled(
    target_t: np.ndarray, target: np.ndarray, *, dt: float, latency: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The target on the simulation grid: times (n,) s every ``dt`` from 0, x and y (n,)
    degrees, and velocity (n, 2) deg/s (zero before ``latency``: nothing seen yet)."""
    target_t = np.asarray(target_t, dtype=float)
    target = np.asarray(target, dtype=float)
    t = np.arange(0.0, float(target_t[-1]) + 0.5 * dt, dt)
    tx = np.interp(t, target_t, target[:, 0])
    ty = np.interp(t, target_t, target[:, 1])
    vel = np.gradient(np.column_stack([tx, ty]), dt, axis=0) if t.size > 1 else np.zeros((1, 2))
    vel[t < latency] = 0.0
    return t, tx, ty, vel


def pursue_path(
    target_t: np.ndarray, target: np.ndarray, *, start_gaze: tuple[float, float]
) -> PursuitPath:
    """Follow ``target`` ((k, 2) degrees at times ``target_t`` (k,) seconds, ascending, from
    0) starting from ``start_gaze``.

    Model (numbers in ``model.json`` ``pursuit``): the eyes see the target ``latency_s``
    late; their smooth velocity tends to ``gain`` times the seen target velocity (capped at
    ``max_velocity_deg_s``) through a first-order lag ``velocity_tau_s``. When the predicted
    position error exceeds ``catch_up_threshold_deg``, a catch-up saccade of that error
    (plus the target motion during the saccade) is made, at most one per ``min_fixation_s``.
    """
    p = gaze_model()["pursuit"]
    min_fix = float(gaze_model()["saccade"]["min_fixation_s"])
    dt = float(p["step_s"])
    latency, gain, tau = float(p["latency_s"]), float(p["gain"]), float(p["velocity_tau_s"])
    vmax, threshold = float(p["max_velocity_deg_s"]), float(p["catch_up_threshold_deg"])
    t, tx, ty, vel = _sampled(target_t, target, dt=dt, latency=latency)
    seen_idx = np.clip(np.round((t - latency) / dt).astype(int), 0, t.size - 1)

    gaze = np.empty((t.size, 2))
    smooth = np.asarray(start_gaze, dtype=float).copy()
    v = np.zeros(2)
    saccade_offset = np.zeros(2)
    catch_ups: list[tuple[float, float, tuple[float, float]]] = []
    active: tuple[float, float, np.ndarray] | None = None  # start, duration, shift
    last_saccade = -math.inf
    for i, ti in enumerate(t):
        seen_v = gain * vel[seen_idx[i]]
        speed = float(np.hypot(*seen_v))
        if speed > vmax:
            seen_v *= vmax / speed
        v += (seen_v - v) * (dt / tau)
        smooth += v * dt
        if active is not None:
            s0, dur, shift = active
            frac = float(saccade_profile(np.array((ti - s0) / dur), float(np.hypot(*shift))))
            offset = saccade_offset + frac * shift
            if ti - s0 >= dur:
                saccade_offset = saccade_offset + shift
                offset = saccade_offset
                active = None
        else:
            offset = saccade_offset
            j = seen_idx[i]
            predicted = np.array([tx[j], ty[j]]) + vel[j] * latency
            error = predicted - (smooth + offset)
            size = float(np.hypot(*error))
            if ti >= latency and size > threshold and ti - last_saccade >= min_fix:
                dur = saccade_duration(size)
                shift = error + vel[j] * dur * (1.0 - gain)
                active = (float(ti), dur, shift)
                last_saccade = float(ti)
                catch_ups.append((float(ti), dur, (float(shift[0]), float(shift[1]))))
        gaze[i] = smooth + offset
    return PursuitPath(t=t, gaze=gaze, catch_ups=tuple(catch_ups))
