"""Argument checks shared by every public function: one message per kind of mistake.

Each returns the value converted to a plain Python number, or raises
:class:`~facelib.errors.ParameterError` naming the argument and the value.
"""

from __future__ import annotations

import math

import numpy as np

from facelib.errors import ParameterError

__all__ = ["check_count", "check_fps", "check_number"]


def check_number(name: str, value: object, *, low: float | None = None,
                 high: float | None = None, low_open: bool = False) -> float:
    """``value`` as a finite float within ``[low, high]`` (``(low, high]`` with ``low_open``).

    Accepts Python and numpy numbers; refuses bools, strings, NaN and infinities.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    number = float(value)
    too_low = low is not None and (number <= low if low_open else number < low)
    if not math.isfinite(number) or too_low or (high is not None and number > high):
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        bracket = "(" if low_open else "["
        raise ParameterError(f"{name} must be a finite number in {bracket}{lo}, {hi}], "
                             f"got {value!r}")
    return number


def check_fps(fps: object) -> float:
    """``fps`` as a float; ``ParameterError`` unless it is a finite number > 0."""
    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.number)):
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    value = float(fps)
    if not math.isfinite(value) or value <= 0:
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    return value


def check_count(name: str, value: object, *, low: int = 0) -> int:
    """``value`` as an int ``>= low``; refuses bools and non-integral numbers."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ParameterError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)
