"""Measured norms of blinking and head-eye coordination (issue 32 item 5), as data.

The numbers and their sources live in ``facelib/data/alive/blinks.json`` and
``facelib/data/alive/head_eye.json``; this module reads them once into frozen dataclasses
and holds the two rules built on them: the head's share of a gaze shift and the
probability that a shift carries a blink.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib import data
from facelib.errors import DataError

__all__ = ["BLINK_STATES", "BlinkNorms", "HeadEyeRule", "blink_norms", "head_eye_rule"]

BLINK_STATES = ("rest", "listening", "talking", "reading")
"""The states with a measured spontaneous blink rate."""


@dataclass(frozen=True)
class BlinkNorms:
    """Spontaneous blinks by state and gaze-evoked blinks.

    per_min: state -> blinks a minute. mode_state: gaze mode -> state.
    min_interval_s: least time between two blink onsets. interval_cv: coefficient of
    variation of the intervals. evoked_threshold_deg, evoked_p_at_threshold,
    evoked_certain_deg: a shift of the threshold carries a blink with that probability,
    rising linearly to 1 at ``evoked_certain_deg``.
    """

    per_min: Mapping[str, float]
    mode_state: Mapping[str, str]
    min_interval_s: float
    interval_cv: float
    evoked_threshold_deg: float
    evoked_p_at_threshold: float
    evoked_certain_deg: float

    def rate(self, state: str) -> float:
        """Blinks a minute in ``state`` (one of :data:`BLINK_STATES`)."""
        return self.per_min[state]

    def evoked_probability(self, shift_deg: float) -> float:
        """Probability in [0, 1] that a gaze shift of ``shift_deg`` carries a blink (0 below
        the threshold)."""
        if shift_deg < self.evoked_threshold_deg:
            return 0.0
        span = max(self.evoked_certain_deg - self.evoked_threshold_deg, 1e-9)
        rise = (shift_deg - self.evoked_threshold_deg) / span
        return float(min(1.0, self.evoked_p_at_threshold + (1 - self.evoked_p_at_threshold) * rise))


@dataclass(frozen=True)
class HeadEyeRule:
    """How much of a gaze shift the head takes: nothing up to ``onset_deg``, then ``slope``
    of the part beyond it, and at least enough that the eyes end at most
    ``eye_rest_max_deg`` from the head's straight-ahead."""

    onset_deg: float
    slope: float
    eye_rest_max_deg: float

    def head_for(self, shift: np.ndarray, *, onset_deg: float | None = None,
                 slope: float | None = None) -> np.ndarray:
        """The head rotation ``(2,)`` degrees (left, up) that a gaze shift ``shift`` ``(2,)``
        degrees (from the head's rest) recruits, along the shift's direction. ``onset_deg``
        and ``slope`` override the rule's (a behaviour's head_threshold_deg and
        head_coupling)."""
        shift = np.asarray(shift, dtype=float)
        size = float(np.hypot(*shift))
        if size == 0.0:
            return np.zeros(2)
        onset = self.onset_deg if onset_deg is None else onset_deg
        share = self.slope if slope is None else slope
        amount = max(share * (size - onset), size - self.eye_rest_max_deg, 0.0)
        return shift * (min(amount, size) / size)


def _positive(where: str, name: str, value: object) -> float:
    number = float(value)  # type: ignore[arg-type]
    if not np.isfinite(number) or number < 0:
        raise DataError(f"{name} must be a finite number >= 0, got {value!r}", path=where)
    return number


@cache
def blink_norms() -> BlinkNorms:
    """The blink norms of ``alive/blinks.json``; DataError naming the file if malformed."""
    where = str(data.path("alive/blinks.json"))
    doc = data.json_data("alive/blinks.json")
    try:
        states = {name: _positive(where, name, doc["states"][name]["per_min"])
                  for name in BLINK_STATES}
        modes = {k: str(v) for k, v in doc["mode_state"].items() if not k.startswith("_")}
        evoked = doc["evoked"]
        norms = BlinkNorms(
            per_min=MappingProxyType(states), mode_state=MappingProxyType(modes),
            min_interval_s=_positive(where, "min_interval_s", doc["min_interval_s"]),
            interval_cv=_positive(where, "interval_cv", doc["interval_cv"]),
            evoked_threshold_deg=_positive(where, "threshold_deg", evoked["threshold_deg"]),
            evoked_p_at_threshold=_positive(where, "p_at_threshold", evoked["p_at_threshold"]),
            evoked_certain_deg=_positive(where, "certain_deg", evoked["certain_deg"]),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad blink norms: {exc!r}", path=where) from exc
    unknown = set(norms.mode_state.values()) - set(BLINK_STATES)
    if unknown:
        raise DataError(f"mode_state names unknown blink states {sorted(unknown)}", path=where)
    return norms


@cache
def head_eye_rule() -> HeadEyeRule:
    """The head-eye rule of ``alive/head_eye.json``; DataError naming the file if malformed."""
    where = str(data.path("alive/head_eye.json"))
    doc = data.json_data("alive/head_eye.json")
    try:
        return HeadEyeRule(**{key: _positive(where, key, doc[key])
                              for key in ("onset_deg", "slope", "eye_rest_max_deg")})
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad head-eye rule: {exc!r}", path=where) from exc
