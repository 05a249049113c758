"""Breathing: a seeded respiratory cycle and what of it shows in the FAPs (issue 32 item 4).

The cycle runs at ``per_min`` breaths a minute (12-20 is the adult resting range), its rate
wandering by ``rate_jitter`` (smooth noise), with a raised-cosine inhalation over
``inhale_fraction`` of each cycle and a slower exhalation. Two signals come of it: the lung
volume (the chest rises and the head with it: a little head pitch up at full lungs) and
the inhaled flow (the nostrils widen while air goes in). Rules: ``breathing`` of
``facelib/data/alive/idle.json``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from facelib.checks import check_per_frame
from facelib.sync.noise import smooth_noise

__all__ = ["Breath", "Breathing", "breath_cycle"]


@dataclass(frozen=True)
class Breathing:
    """Breathing rules: rate (breaths a minute) and its relative jitter with the jitter's
    smoothing (s), the inhalation's share of a cycle, the nostril FAPs' widening at peak
    inflow (FAP name -> ENS units), the head's pitch-up from empty to full lungs (degrees,
    peak to peak) and the visible share while speaking."""

    per_min: float
    rate_jitter: float
    jitter_smooth_s: float
    inhale_fraction: float
    nostril_flare: Mapping[str, float]
    head_pitch_up_deg: float
    speaking_scale: float


@dataclass(frozen=True)
class Breath:
    """One breathing signal, frame by frame: ``volume`` ``(n,) float64`` in [0, 1] (0 empty,
    1 full lungs), ``inflow`` ``(n,) float64`` in [0, 1] (inhaled air flow, 0 while
    breathing out), ``onsets`` the frames where inhalations start."""

    volume: np.ndarray
    inflow: np.ndarray
    onsets: np.ndarray


def breath_cycle(n_frames: int, *, fps: float, seed: int, rules: Breathing,
                 rate: float | np.ndarray = 1.0) -> Breath:
    """The breathing of ``n_frames`` frames at ``fps``.

    rate: factor on ``rules.per_min``, one number or ``(n_frames,)`` (a mood's, e.g.);
    the same seed gives the same cycle.
    """
    factor = check_per_frame("rate", rate, n_frames)
    t = np.arange(n_frames) / fps
    rng = np.random.default_rng([seed, 32, 1])
    jitter = smooth_noise(t, seed=[seed, 32, 2], smooth_s=rules.jitter_smooth_s)
    per_s = np.clip(rules.per_min * factor * (1.0 + rules.rate_jitter * jitter), 0.0, None) / 60
    cycles = np.concatenate([[0.0], np.cumsum(per_s[:-1])]) / fps + float(rng.random())
    u = cycles % 1.0
    inhale = u < rules.inhale_fraction
    fin = rules.inhale_fraction
    volume = np.where(inhale, 0.5 * (1.0 - np.cos(np.pi * u / fin)),
                      0.5 * (1.0 + np.cos(np.pi * (u - fin) / (1.0 - fin))))
    inflow = np.where(inhale, np.sin(np.pi * np.minimum(u / fin, 1.0)), 0.0)
    whole = np.floor(cycles)
    onsets = np.flatnonzero(np.diff(whole) > 0) + 1
    return Breath(volume=volume, inflow=inflow, onsets=onsets)
