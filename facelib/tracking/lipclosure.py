"""The mouth's *closed* state (p, b, m) read off the inner-lip aperture.

The learned observation model (:mod:`~facelib.tracking.observation`) recovers how far the
mouth opens, but not the press of the lips past contact: MediaPipe's inner-lip landmarks
stop where the lips meet, so the model's lips often stay a little apart in a p, b or m.
The seed's Virtual Mirror detects the mouth state (open, closed) as a high-level action;
here it is detected from MediaPipe's inner-lip landmarks and sets the lip FAPs to the
closed state in those frames:

1. the aperture ``a``: the mean vertical distance of the inner-lip landmark pairs
   (``facelib/data/tracking/lip_closure.json``: the upper and lower inner-lip points on
   the midline and on either side) in the neutral head's frame, over the user's ``MNS0``;
2. the closed frames: ``a`` below ``close_below``, staying closed until ``a`` rises above
   ``open_above`` (a hysteresis; the packaged rule has none, both thresholds are equal);
   the threshold is learned from the training renders
   (``tools/build_tracking_observation.py``): the aperture under which 15 % of the frames
   whose true inner-lip gap is at least 0.1 MNS0 fall;
3. in those frames the inner-lip separation the FAPs give,
   ``s = k_jaw f3 - f4 - f5`` (FAP units, MNS/1024), is lowered to at most the closed
   value ``closed_gap`` (the press of facelib's p/b/m viseme), by raising the inner lip
   FAPs 4 and 5 by equal amounts and their neighbours 8-11 in the viseme's proportion.
   open_jaw is left alone.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from facelib.checks import check_number
from facelib.data import json_data
from facelib.errors import DataError, ParameterError
from facelib.mpeg4 import FAPU_SCALE, fap
from facelib.tracking.headframe import HeadFrame

__all__ = ["LipClosure", "close_lips", "closed_frames", "closed_lip_columns", "inner_lip_aperture",
           "learn_threshold", "lip_closure"]

_DATA = "tracking/lip_closure.json"
_JAW, _UPPER, _LOWER = (fap(name).index for name in ("open_jaw", "lower_t_midlip",
                                                      "raise_b_midlip"))
"""Columns of FAPs 3, 4 and 5: the jaw and the inner lip midpoints the rule moves."""


@dataclass(frozen=True)
class LipClosure:
    """The closed-state rule (``facelib/data/tracking/lip_closure.json``).

    Attributes
    ----------
    upper, lower: ``(p,) int64`` MediaPipe landmark indices of the inner-lip pairs.
    close_below, open_above: aperture thresholds (MNS0 units) entering and leaving the
        closed state.
    jaw_gain: inner-lip separation per unit of open_jaw (FAP 3) in units of FAPs 4/5.
    closed_gap: the separation ``jaw_gain f3 - f4 - f5`` of the closed state (FAP units).
    neighbours: ``{fap_id: share}`` raised by ``share`` times the raise of 4 (upper lip)
        or 5 (lower lip).
    """

    upper: np.ndarray
    lower: np.ndarray
    close_below: float
    open_above: float
    jaw_gain: float
    closed_gap: float
    neighbours: dict[int, float]


@cache
def lip_closure() -> LipClosure:
    """The packaged rule."""
    raw = json_data(_DATA)
    try:
        pairs = np.asarray(raw["inner_lip_pairs"], np.int64)
        rule = LipClosure(pairs[:, 0], pairs[:, 1], float(raw["close_below"]["value"]),
                          float(raw["open_above"]["value"]), float(raw["jaw_gain"]["value"]),
                          float(raw["closed_gap"]["value"]),
                          {int(k): float(v) for k, v in raw["neighbours"]["value"].items()})
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise DataError(f"malformed lip closure rule ({exc})", path=_DATA) from exc
    if pairs.ndim != 2 or pairs.shape[1] != 2 or not rule.close_below <= rule.open_above:
        raise DataError("lip closure rule: pairs must be (p, 2) and close_below <= open_above",
                        path=_DATA)
    return rule


def inner_lip_aperture(frame: HeadFrame, rule: LipClosure) -> np.ndarray:
    """``(n,) float64`` mean vertical distance of the inner-lip pairs (upper minus lower,
    neutral head frame) over the user's MNS0; about 0 with the lips together."""
    upper = frame.landmarks[:, rule.upper, 1]
    lower = frame.landmarks[:, rule.lower, 1]
    return (upper - lower).mean(axis=1) / (frame.fapu["MNS"] * FAPU_SCALE)


def closed_frames(aperture: np.ndarray, *, close_below: float,
                  open_above: float) -> np.ndarray:
    """``(n,) bool`` frames in the closed state: entered when ``aperture`` ``(n,)`` falls
    below ``close_below``, left when it rises above ``open_above``."""
    closed = np.zeros(len(aperture), bool)
    state = False
    for i, value in enumerate(np.asarray(aperture, np.float64)):
        state = value < (open_above if state else close_below)
        closed[i] = state
    return closed


def close_lips(values: np.ndarray, closed: np.ndarray, rule: LipClosure) -> np.ndarray:
    """``(n, 84)`` FAP values with the inner-lip separation of the ``closed`` ``(n,)``
    frames lowered to at most ``rule.closed_gap`` (FAPs 4, 5 and neighbours raised)."""
    values = np.array(values, np.float64)
    separation = rule.jaw_gain * values[:, _JAW] - values[:, _UPPER] - values[:, _LOWER]
    raise_by = np.where(closed, np.maximum(separation - rule.closed_gap, 0.0) / 2, 0.0)
    values[:, _UPPER] += raise_by
    values[:, _LOWER] += raise_by
    for fap_id, share in rule.neighbours.items():
        values[:, fap_id - 1] += share * raise_by
    return values


def closed_lip_columns(rule: LipClosure) -> list[int]:
    """The FAP columns :func:`close_lips` may change: FAPs 4, 5 and the rule's neighbours."""
    return [_UPPER, _LOWER, *(f - 1 for f in rule.neighbours)]


def learn_threshold(aperture: np.ndarray, is_open: np.ndarray, *,
                    false_closed: float = 0.15) -> float:
    """The aperture threshold under which only a ``false_closed`` share of the open frames
    (``is_open`` ``(n,) bool``: lips apart in truth) fall: the ``false_closed`` quantile of
    their apertures ``(n,)``. ParameterError for mismatched shapes, no open frames or a
    ``false_closed`` outside [0, 1]."""
    share = check_number("false_closed", false_closed, low=0.0, high=1.0)
    apertures = np.asarray(aperture, np.float64)
    open_mask = np.asarray(is_open, bool)
    if apertures.ndim != 1 or open_mask.shape != apertures.shape:
        raise ParameterError(f"aperture {apertures.shape} and is_open {open_mask.shape} must "
                             "be (n,) arrays of the same frames")
    if not open_mask.any():
        raise ParameterError(f"no open frames among the {len(apertures)} to learn from")
    return float(np.quantile(apertures[open_mask], share))
