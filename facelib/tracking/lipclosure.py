"""The mouth's *closed* state (p, b, m) and how far it is *open*, read off the inner-lip
aperture.

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
   open_jaw is left alone;
4. in the other frames ``s`` is raised to at least ``open_gain a`` by lowering the same FAPs
   alike, ``open_gain`` being the least-squares slope through 0 of the true separation on
   the aperture over the training renders' frames not in the closed state: the estimator
   and the smoothing shrink the quick openings between two closures ("a baby"), which
   MediaPipe's inner-lip points still show;
5. on a recorded track (with the smoothing), open_jaw through a closure of at most
   ``jaw_bridge_s`` seconds is drawn straight from the frame before it to the frame after
   it (:func:`bridge_jaw`): with the lips sealed, the landmarks no longer show the jaw
   (MediaPipe's chin follows it at half its motion), and a jaw that stays open for the
   next vowel while the lips press would otherwise read as closed.
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

__all__ = ["LipClosure", "bridge_jaw", "close_lips", "closed_frames", "closed_lip_columns",
           "inner_lip_aperture", "learn_open_gain", "learn_threshold", "lip_closure", "open_lips",
           "separation"]

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
    open_gain: FAP units of separation per MNS0 of aperture, used as a floor outside the
        closed state (a least-squares slope learned from the training renders).
    neighbours: ``{fap_id: share}`` raised by ``share`` times the raise of 4 (upper lip)
        or 5 (lower lip).
    jaw_bridge_s: the longest closure (seconds) open_jaw is drawn across
        (:func:`bridge_jaw`).
    """

    upper: np.ndarray
    lower: np.ndarray
    close_below: float
    open_above: float
    jaw_gain: float
    closed_gap: float
    open_gain: float
    neighbours: dict[int, float]
    jaw_bridge_s: float


@cache
def lip_closure() -> LipClosure:
    """The packaged rule."""
    raw = json_data(_DATA)
    try:
        pairs = np.asarray(raw["inner_lip_pairs"], np.int64)
        rule = LipClosure(pairs[:, 0], pairs[:, 1], float(raw["close_below"]["value"]),
                          float(raw["open_above"]["value"]), float(raw["jaw_gain"]["value"]),
                          float(raw["closed_gap"]["value"]), float(raw["open_gain"]["value"]),
                          {int(k): float(v) for k, v in raw["neighbours"]["value"].items()},
                          float(raw["jaw_bridge_s"]["value"]))
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise DataError(f"malformed lip closure rule ({exc})", path=_DATA) from exc
    if (pairs.ndim != 2 or pairs.shape[1] != 2 or not rule.close_below <= rule.open_above
            or not rule.jaw_bridge_s >= 0):
        raise DataError("lip closure rule: pairs must be (p, 2), close_below <= open_above "
                        "and jaw_bridge_s >= 0", path=_DATA)
    return rule


def inner_lip_aperture(frame: HeadFrame, rule: LipClosure) -> np.ndarray:
    """``(n,) float64`` mean vertical distance of the inner-lip pairs (upper minus lower,
    neutral head frame) over the user's MNS0; about 0 with the lips together."""
    upper = frame.landmarks[:, rule.upper, 1]
    lower = frame.landmarks[:, rule.lower, 1]
    return (upper - lower).mean(axis=1) / (frame.fapu["MNS"] * FAPU_SCALE)


def closed_frames(aperture: np.ndarray, *, close_below: float, open_above: float,
                  closed: bool = False) -> np.ndarray:
    """``(n,) bool`` frames in the closed state: entered when ``aperture`` ``(n,)`` falls
    below ``close_below``, left when it rises above ``open_above``; ``closed``: the state
    before the first frame (a live track's last)."""
    out = np.zeros(len(aperture), bool)
    state = bool(closed)
    for i, value in enumerate(np.asarray(aperture, np.float64)):
        state = value < (open_above if state else close_below)
        out[i] = state
    return out


def separation(values: np.ndarray, rule: LipClosure) -> np.ndarray:
    """``(n,)`` inner-lip separation ``jaw_gain f3 - f4 - f5`` (FAP units) of ``(n, 84)``
    FAP values."""
    values = np.asarray(values, np.float64)
    return rule.jaw_gain * values[:, _JAW] - values[:, _UPPER] - values[:, _LOWER]


def _close_by(values: np.ndarray, amount: np.ndarray, rule: LipClosure) -> np.ndarray:
    """``(n, 84)`` values with the separation lowered by ``amount`` ``(n,)`` (negative:
    raised): FAPs 4 and 5 raised by half of it each, their neighbours in the rule's
    proportion."""
    values = np.array(values, np.float64)
    half = np.asarray(amount, np.float64) / 2
    values[:, _UPPER] += half
    values[:, _LOWER] += half
    for fap_id, share in rule.neighbours.items():
        values[:, fap_id - 1] += share * half
    return values


def close_lips(values: np.ndarray, closed: np.ndarray, rule: LipClosure) -> np.ndarray:
    """``(n, 84)`` FAP values with the inner-lip separation of the ``closed`` ``(n,)``
    frames lowered to at most ``rule.closed_gap`` (FAPs 4, 5 and neighbours raised)."""
    excess = np.maximum(separation(values, rule) - rule.closed_gap, 0.0)
    return _close_by(values, np.where(closed, excess, 0.0), rule)


def open_lips(values: np.ndarray, aperture: np.ndarray, closed: np.ndarray,
              rule: LipClosure) -> np.ndarray:
    """``(n, 84)`` FAP values with the inner-lip separation of the frames not ``closed``
    ``(n,)`` raised to at least ``rule.open_gain`` times their ``aperture`` ``(n,)`` (MNS0)
    (FAPs 4, 5 and neighbours lowered); never lowered."""
    short = np.maximum(rule.open_gain * np.asarray(aperture, np.float64)
                       - separation(values, rule), 0.0)
    return _close_by(values, -np.where(closed, 0.0, short), rule)


def bridge_jaw(jaw: np.ndarray, closed: np.ndarray, *, longest: int) -> np.ndarray:
    """``(n,) float64`` open_jaw values ``jaw`` ``(n,)`` drawn straight across each run of
    ``closed`` ``(n,) bool`` frames of at most ``longest`` frames that has an open frame on
    either side (from the value of the one before to that of the one after); the other
    frames as they were."""
    out = np.array(jaw, np.float64)
    edges = np.diff(np.concatenate([[0], np.asarray(closed, np.int8), [0]]))
    for start, stop in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
        if start > 0 and stop < len(out) and stop - start <= longest:
            share = np.arange(1, stop - start + 1) / (stop - start + 1)
            out[start:stop] = out[start - 1] + share * (out[stop] - out[start - 1])
    return out


def closed_lip_columns(rule: LipClosure) -> list[int]:
    """The FAP columns :func:`close_lips` and :func:`open_lips` may change: FAPs 4, 5 and
    the rule's neighbours."""
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


def learn_open_gain(aperture: np.ndarray, true_separation: np.ndarray,
                    is_open: np.ndarray) -> float:
    """The least-squares slope through 0 of the ``true_separation`` ``(n,)`` of the inner
    lips (FAP units, :func:`separation` of the true FAPs) on the ``aperture`` ``(n,)``
    (MNS0) over the ``is_open`` ``(n,) bool`` frames. ParameterError for mismatched shapes
    or no open frame with an aperture."""
    a, s, mask = (np.asarray(x) for x in (aperture, true_separation, is_open))
    if a.ndim != 1 or s.shape != a.shape or mask.shape != a.shape:
        raise ParameterError(f"aperture {a.shape}, true_separation {s.shape} and is_open "
                             f"{mask.shape} must be (n,) arrays of the same frames")
    a, s = a[mask.astype(bool)].astype(np.float64), s[mask.astype(bool)].astype(np.float64)
    if not (np.isfinite(a).all() and np.isfinite(s).all()):
        raise ParameterError("aperture and true_separation must be finite in the open frames")
    if not (a * a).sum():
        raise ParameterError("no open frame with a nonzero aperture to learn from")
    return float((a * s).sum() / (a * a).sum())
