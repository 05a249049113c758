"""A listener's head: slow drift and small back-channel nods (issue 32 item 4).

While the character does not speak its head drifts (smooth noise of a given standard
deviation per axis) and nods now and then (a raised-cosine pitch pulse down and back,
sometimes doubled), so a listening face is never frozen. Rules: ``listening`` of
``facelib/data/alive/idle.json``; the same seed gives the same motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.checks import check_per_frame
from facelib.sync.noise import smooth_noise

__all__ = ["Listening", "listening_motion", "nod_times"]


@dataclass(frozen=True)
class Listening:
    """Listening rules: drift sd (pitch, yaw, roll degrees) and its smoothing (s); nods:
    mean time between them (s), its coefficient of variation and least value, the nod's
    depth (degrees down), size jitter (fraction) and length (s), the chance of a second
    nod right after; ``ease_s``: the fade at the edges of speech."""

    drift_sd_deg: tuple[float, float, float]
    drift_smooth_s: float
    nod_interval_s: float
    nod_interval_cv: float
    nod_min_gap_s: float
    nod_pitch_deg: float
    nod_jitter: float
    nod_duration_s: float
    double_p: float
    ease_s: float


def nod_times(span_s: float, *, rng: np.random.Generator, rules: Listening
              ) -> list[tuple[float, float]]:
    """(start, depth in degrees) of the nods over ``[0, span_s)`` seconds (of the rate-scaled
    clock): gamma intervals of mean ``nod_interval_s`` never under ``nod_min_gap_s``, a
    second, smaller nod right after with probability ``double_p``."""
    excess = max(rules.nod_interval_s - rules.nod_min_gap_s, 1e-3)
    shape = (excess / max(rules.nod_interval_cv * rules.nod_interval_s, 1e-9)) ** 2
    nods: list[tuple[float, float]] = []
    t = float(rng.uniform(0.0, rules.nod_interval_s))
    while t < span_s:
        depth = rules.nod_pitch_deg * (1.0 + rules.nod_jitter * float(rng.uniform(-1, 1)))
        nods.append((t, depth))
        if rng.random() < rules.double_p:
            nods.append((t + 0.9 * rules.nod_duration_s, 0.6 * depth))
        t += rules.nod_min_gap_s + float(rng.gamma(shape, excess / shape))
    return nods


def listening_motion(n_frames: int, *, fps: float, seed: int, rules: Listening,
                     amplitude: float | np.ndarray = 1.0, rate: float | np.ndarray = 1.0
                     ) -> np.ndarray:
    """A listener's head motion as ``(n_frames, 3) float64`` degrees of FAP 48-50's
    orientation (pitch down, yaw left, roll), all the time (the caller fades it where the
    character speaks).

    amplitude: factor on every angle; rate: factor on the pace of drift and nods; each one
    number or ``(n_frames,)``.
    """
    gain = check_per_frame("amplitude", amplitude, n_frames)
    pace = check_per_frame("rate", rate, n_frames)
    clock = np.concatenate([[0.0], np.cumsum(pace[:-1])]) / fps
    out = np.zeros((n_frames, 3))
    for axis, sd in enumerate(rules.drift_sd_deg):
        out[:, axis] = sd * smooth_noise(clock, seed=[seed, 32, 3, axis],
                                         smooth_s=rules.drift_smooth_s)
    span = float(clock[-1]) + 1.0 / fps if n_frames else 0.0
    half = 0.5 * rules.nod_duration_s
    for start, depth in nod_times(span, rng=np.random.default_rng([seed, 32, 4]), rules=rules):
        rel = (clock - start - half) / half
        inside = np.abs(rel) < 1.0
        out[inside, 0] += depth * 0.5 * (1.0 + np.cos(np.pi * rel[inside]))
    return out * gain[:, None]
