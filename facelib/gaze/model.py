"""The statistical saccade model (Lee, Badler & Badler 2002, "Eyes Alive") as data plus
samplers.

The numbers live in ``facelib/data/gaze/model.json`` with their sources; this module reads
them once and draws from them with a caller's :class:`numpy.random.Generator`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from facelib import data
from facelib.gaze.norms import blink_norms

__all__ = [
    "GAZE_MODES",
    "ModeStats",
    "direction_bin",
    "gaze_model",
    "mode_stats",
    "saccade_duration",
    "saccade_profile",
    "sample_direction",
    "sample_interval",
    "sample_magnitude",
]

GAZE_MODES = ("talking", "listening", "thinking")


@cache
def gaze_model() -> dict[str, Any]:
    """The parsed ``facelib/data/gaze/model.json`` (treat as read-only)."""
    model: dict[str, Any] = data.json_data("gaze/model.json")
    return model


@dataclass(frozen=True, slots=True)
class ModeStats:
    """Gaze statistics of one conversational mode.

    p_mutual: probability that the next gaze state is mutual gaze.
    mutual_s, away_s: (mean, sd) of the state durations in seconds.
    magnitude_max_deg: largest saccade drawn.
    blinks_per_min: spontaneous blink rate of the mode's blink state
        (``alive/blinks.json``).
    direction_percent: (8,) percentages of the direction bins 0, 45, ..., 315 degrees.
    """

    p_mutual: float
    mutual_s: tuple[float, float]
    away_s: tuple[float, float]
    magnitude_max_deg: float
    blinks_per_min: float
    direction_percent: tuple[float, ...]


@cache
def mode_stats(mode: str) -> ModeStats:
    """Statistics of ``mode`` (one of :data:`GAZE_MODES`)."""
    model = gaze_model()
    modes = model["modes"]
    row = modes[mode]
    norms = blink_norms()
    fps = float(modes["frames_per_second"])
    percent = row.get("direction_percent", model["saccade"]["direction_percent"])
    return ModeStats(
        p_mutual=float(row["p_mutual"]),
        mutual_s=(row["mutual_frames"][0] / fps, row["mutual_frames"][1] / fps),
        away_s=(row["away_frames"][0] / fps, row["away_frames"][1] / fps),
        magnitude_max_deg=float(row["magnitude_max_deg"]),
        blinks_per_min=norms.rate(norms.mode_state[mode]),
        direction_percent=tuple(float(p) for p in percent),
    )


def sample_magnitude(rng: np.random.Generator, *, max_deg: float) -> float:
    """A saccade magnitude in degrees from P(A) = 15.7 exp(-A / 6.9), i.e. an exponential of
    scale 6.9 deg truncated to [magnitude_min_deg, max_deg] (inverse-CDF sampling)."""
    sac = gaze_model()["saccade"]
    scale = float(sac["magnitude_decay_deg"])
    lo = float(sac["magnitude_min_deg"])
    hi = max(float(max_deg), lo)
    span = 1.0 - math.exp(-(hi - lo) / scale)
    return lo - scale * math.log1p(-rng.random() * span)


def sample_direction(rng: np.random.Generator, percent: tuple[float, ...] | np.ndarray) -> float:
    """A saccade direction in degrees [0, 360): a bin of the 8-bin table (0 = face's left,
    90 = up), then a uniform offset within +-``direction_jitter_deg`` of the bin centre."""
    sac = gaze_model()["saccade"]
    weights = np.asarray(percent, dtype=float)
    k = int(rng.choice(len(weights), p=weights / weights.sum()))
    jitter = float(sac["direction_jitter_deg"])
    return float((sac["directions_deg"][k] + rng.uniform(-jitter, jitter)) % 360.0)


def direction_bin(direction_deg: float | np.ndarray) -> np.ndarray:
    """Index 0-7 of the 45-degree bin centred on 0, 45, ..., 315 degrees."""
    return (np.round(np.asarray(direction_deg) / 45.0).astype(int)) % 8


def sample_interval(rng: np.random.Generator, mean_s: float, sd_s: float) -> float:
    """A gaze-state duration in seconds: ``min_fixation_s`` plus a gamma variable, so that
    the result has exactly mean ``mean_s`` and standard deviation ``sd_s``."""
    floor = float(gaze_model()["saccade"]["min_fixation_s"])
    excess = max(mean_s - floor, 1e-3)
    if sd_s <= 0:
        return floor + excess
    shape = (excess / sd_s) ** 2
    return floor + float(rng.gamma(shape, excess / shape))


def saccade_duration(magnitude_deg: float) -> float:
    """Saccade duration in seconds, D = D0 + d * A (25 ms + 2.4 ms/deg)."""
    sac = gaze_model()["saccade"]
    ms = float(sac["duration_d0_ms"]) + float(sac["duration_slope_ms_per_deg"]) * magnitude_deg
    return ms / 1000.0


def saccade_profile(u: np.ndarray, magnitude_deg: float) -> np.ndarray:
    """Fraction of the movement done at normalised time ``u`` in [0, 1] (any shape, float64).

    The velocity is a beta(a, b) density with b = a + skew * A: bell-shaped and, for large
    saccades, peaking early (fast acceleration, longer deceleration), as real saccades do.
    """
    from scipy.special import betainc

    sac = gaze_model()["saccade"]
    a = float(sac["profile_a"])
    b = a + float(sac["profile_skew_per_deg"]) * magnitude_deg
    return betainc(a, b, np.clip(u, 0.0, 1.0))
