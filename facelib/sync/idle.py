"""Idle micro-movements of brows, lids and mouth corners (issue 32 item 4).

Each group of FAPs moves by smooth noise of a given standard deviation (in the FAPs' own
units), a share ``symmetric`` of its variance common to every FAP of the group (both brows
rise together) and the rest each FAP's own. Rules: ``micro`` of
``facelib/data/alive/idle.json``; the same seed gives the same motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.checks import check_per_frame
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.sync.noise import smooth_noise

__all__ = ["MicroGroup", "micro_movements"]


@dataclass(frozen=True)
class MicroGroup:
    """One group: its FAP names, sd (FAP units), smoothing (s) and symmetric share."""

    name: str
    faps: tuple[str, ...]
    sd: float
    smooth_s: float
    symmetric: float


def micro_movements(n_frames: int, *, fps: float, seed: int,
                    groups: tuple[MicroGroup, ...], amplitude: float | np.ndarray = 1.0,
                    rate: float | np.ndarray = 1.0) -> np.ndarray:
    """Offsets ``(n_frames, 84) float64`` in FAP units (0 on FAPs no group names).

    amplitude: factor on every offset; rate: factor on their pace; each one number or
    ``(n_frames,)``.
    """
    gain = check_per_frame("amplitude", amplitude, n_frames)
    pace = check_per_frame("rate", rate, n_frames)
    clock = np.concatenate([[0.0], np.cumsum(pace[:-1])]) / fps
    out = np.zeros((n_frames, N_FAPS))
    for g, group in enumerate(groups):
        shared = smooth_noise(clock, seed=[seed, 32, 5, g], smooth_s=group.smooth_s)
        common, own = np.sqrt(group.symmetric), np.sqrt(1.0 - group.symmetric)
        for k, name in enumerate(group.faps):
            alone = smooth_noise(clock, seed=[seed, 32, 6, g, k], smooth_s=group.smooth_s)
            out[:, fap(name).index] += group.sd * (common * shared + own * alone)
    return out * gain[:, None]
