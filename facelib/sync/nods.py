"""Speech-driven head motion: small nods and turns on the stressed syllables (issue 14).

While speaking, people beat time with the head: a short nod (pitch down and back) on
accented syllables, with a smaller turn or tilt. The accents are taken from the viseme
track's jaw opening (its peaks are the open, stressed vowels), each nod is a raised-cosine
pulse scaled by the accent's strength, and the seeded jitter varies size and side, so the
same storyboard and seed give the same motion. Rules: ``speech_nods`` of ``sync.json``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.mpeg4.tables import ANGLE_UNIT, fap
from facelib.mpeg4.track import FapTrack

__all__ = ["Nods", "accents", "add_brow_beats", "add_nods"]

_JAW = fap("open_jaw").index
_PITCH, _YAW, _ROLL = (fap(n).index for n in ("head_pitch", "head_yaw", "head_roll"))
_BROWS = [fap(f"raise_{s}_{p}_eyebrow").index for s in "lr" for p in "imo"]


@dataclass(frozen=True)
class Nods:
    """Nod rules: peak angles (degrees) of a full-strength accent, pulse length and the least
    gap between accents (ms), the jaw-peak threshold (fraction of the speech's largest jaw
    opening) and the seeded size jitter (fraction)."""

    pitch_deg: float = 3.0
    yaw_deg: float = 1.5
    roll_deg: float = 0.8
    duration_ms: float = 380.0
    min_gap_ms: float = 450.0
    threshold: float = 0.45
    jitter: float = 0.3


def accents(visemes: FapTrack, *, nods: Nods) -> np.ndarray:
    """``(n_frames,) float64`` accent strength in [0, 1] at the frames of stressed syllables
    (local maxima of the weighted jaw opening above ``threshold`` of its maximum, at least
    ``min_gap_ms`` apart, strongest first), 0 elsewhere."""
    jaw = visemes.values[:, _JAW].astype(np.float64) * visemes.weight[:, _JAW]
    out = np.zeros(jaw.size)
    if jaw.size < 3 or jaw.max() <= 0:
        return out
    peak = (jaw[1:-1] >= jaw[:-2]) & (jaw[1:-1] > jaw[2:])
    candidates = np.flatnonzero(peak) + 1
    candidates = candidates[jaw[candidates] >= nods.threshold * jaw.max()]
    gap = nods.min_gap_ms * visemes.fps / 1000.0
    taken: list[int] = []
    for i in candidates[np.argsort(-jaw[candidates], kind="stable")]:
        if all(abs(int(i) - j) >= gap for j in taken):
            taken.append(int(i))
    out[taken] = jaw[taken] / jaw.max()
    return out


def _pulse(nods: Nods, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Frame offsets and the raised-cosine pulse of one accent over them."""
    half = nods.duration_ms * fps / 2000.0
    offsets = np.arange(-int(np.ceil(half)), int(np.ceil(half)) + 1)
    return offsets, 0.5 * (1.0 + np.cos(np.pi * np.clip(offsets / half, -1.0, 1.0)))


def add_brow_beats(track: FapTrack, *, strength: np.ndarray, nods: Nods,
                   brow: np.ndarray) -> FapTrack:
    """Raise (or, negative, lower) the brows on each accent (``strength``, from
    :func:`accents`) by ``brow`` (``(n_frames,)`` ENS units at a full accent, the mood's
    ``speech_brow``), with the nods' pulse; unchanged where ``brow`` is 0."""
    brow = np.asarray(brow, np.float64)
    if not brow.any() or not strength.any():
        return track
    n = track.n_frames
    offsets, pulse = _pulse(nods, track.fps)
    wave = np.zeros(n)
    for i in np.flatnonzero(strength):
        at = i + offsets
        keep = (at >= 0) & (at < n)
        wave[at[keep]] += strength[i] * brow[i] * pulse[keep]
    values = track.values.astype(np.float64)
    weight = track.weight.copy()
    values[:, _BROWS] += wave[:, None]
    weight[:, _BROWS] = np.maximum(weight[:, _BROWS], (wave != 0)[:, None].astype(np.float32))
    return FapTrack(track.fps, values.astype(np.float32), weight)


def add_nods(track: FapTrack, *, strength: np.ndarray, nods: Nods, seed: int,
             head_driven: np.ndarray, scale: np.ndarray | None = None) -> FapTrack:
    """Add a nod per accent (``strength``, from :func:`accents`) to FAP 48-50, faded out
    where gaze moves the head (``head_driven`` in [0, 1]) and scaled by ``scale``
    (``(n_frames,)``, the mood's head motion; None: 1)."""
    n = track.n_frames
    rng = np.random.default_rng([seed, 14])
    offsets, pulse = _pulse(nods, track.fps)
    wave = np.zeros((n, 3))
    for i in np.flatnonzero(strength):
        size = strength[i] * (1.0 + nods.jitter * rng.uniform(-1.0, 1.0))
        side = rng.choice((-1.0, 1.0))
        angles = np.deg2rad([nods.pitch_deg, side * nods.yaw_deg, side * nods.roll_deg])
        at = i + offsets
        keep = (at >= 0) & (at < n)
        wave[at[keep]] += size * pulse[keep, None] * angles[None, :]
    free = 1.0 - np.clip(np.asarray(head_driven, np.float64), 0.0, 1.0)
    if scale is not None:
        free = free * np.asarray(scale, np.float64)
    values = track.values.astype(np.float64)
    weight = track.weight.copy()
    for axis, column in enumerate((_PITCH, _YAW, _ROLL)):
        values[:, column] += wave[:, axis] / ANGLE_UNIT * free
        if strength.any():
            weight[:, column] = np.maximum(weight[:, column], np.float32(1.0))
    return FapTrack(track.fps, values.astype(np.float32), weight)
