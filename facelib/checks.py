"""Argument checks shared by every public function: one message per kind of mistake.

Each check returns the value converted to a plain Python number, or raises
:class:`~facelib.errors.ParameterError` naming the argument and the value.
:func:`did_you_mean` is the one "did you mean ..." hint used by every error message
that names an unknown word (FAP names, expressions, FDL keywords, eye behaviours, ...).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable
from typing import TypeVar

import numpy as np

from facelib.errors import ParameterError

__all__ = [
    "check_count",
    "check_fps",
    "check_items",
    "check_kind",
    "check_number",
    "check_per_frame",
    "check_sample_rate",
    "check_seed",
    "did_you_mean",
    "is_bare_name",
]

T = TypeVar("T")


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


def check_per_frame(name: str, value: object, n_frames: int, *, high: float = 100.0
                    ) -> np.ndarray:
    """A factor given as one number or one per frame, as a read-only ``(n_frames,) float64``
    array of finite values in ``[0, high]``; ParameterError otherwise."""
    if isinstance(value, np.ndarray | list | tuple):
        array = np.asarray(value, dtype=np.float64)
        if array.shape != (n_frames,):
            raise ParameterError(f"{name} must be one number or ({n_frames},) per frame, got "
                                 f"shape {array.shape}")
        if not (np.isfinite(array).all() and (array >= 0).all() and (array <= high).all()):
            raise ParameterError(f"{name} must lie in [0, {high:g}] in every frame")
    else:
        array = np.full(n_frames, check_number(name, value, low=0.0, high=high))
    array.flags.writeable = False
    return array


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


SAMPLE_RATES = (4000, 384_000)
"""Audio sample rates facelib accepts (Hz): from narrow-band telephone speech to the highest
rate of studio formats. A rate outside sizes a resampling filter or buffer by itself (a WAV
header saying 1 Hz asked for 11.9 GiB when resampled to 16 kHz)."""


def check_sample_rate(rate: object, *, source: str) -> int:
    """``rate`` as an int within :data:`SAMPLE_RATES`; ``ParameterError`` naming ``source``
    (the file, or ``"sample_rate"`` for an array) and the rate otherwise."""
    low, high = SAMPLE_RATES
    if (isinstance(rate, bool) or not isinstance(rate, (int, np.integer))
            or not low <= rate <= high):
        raise ParameterError(f"{source} has a sample rate of {rate!r} Hz, outside "
                             f"{low}-{high} Hz")
    return int(rate)


def check_seed(seed: object) -> int:
    """``seed`` as an int in ``[0, 2**63)`` (what numpy's SeedSequence and the FDL accept);
    ``ParameterError`` for bools, floats, negatives and anything else."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not (
        0 <= seed < 2**63
    ):
        raise ParameterError(f"seed must be an integer from 0 to 2^63-1, got {seed!r}")
    return int(seed)


def check_kind(name: str, value: object, kind: type[T]) -> T:
    """``value`` if it is a ``kind``; ``ParameterError`` naming what it is otherwise."""
    if not isinstance(value, kind):
        raise ParameterError(f"{name} must be a {kind.__name__}, got {type(value).__name__} "
                             f"{value!r:.60}")
    return value


def check_items(name: str, values: object, kind: type[T]) -> list[T]:
    """``values`` (any iterable but a string) as a list of ``kind``; ``ParameterError``
    naming the first item of another type."""
    if isinstance(values, str | bytes) or not isinstance(values, Iterable):
        raise ParameterError(f"{name} must be a sequence of {kind.__name__}, got "
                             f"{type(values).__name__}")
    out = list(values)
    for i, item in enumerate(out):
        if not isinstance(item, kind):
            raise ParameterError(f"{name}[{i}] must be a {kind.__name__}, got "
                                 f"{type(item).__name__} {item!r:.60}")
    return out


def did_you_mean(word: str, choices: Iterable[str], *, cutoff: float = 0.7) -> str:
    """``"; did you mean 'x'?"`` for the closest of ``choices`` to ``word``, or ``""``.

    Case is ignored when comparing (``speaksound`` suggests ``speakSound``); ``word`` itself
    is never suggested. ``cutoff`` is :func:`difflib.get_close_matches`' similarity ratio in
    ``[0, 1]``: 0.7 keeps one-letter slips (``joyy`` -> ``joy``) and drops unrelated words
    (``nope`` does not suggest ``inlove``).
    """
    options = {c.lower(): c for c in choices if c != word}
    close = difflib.get_close_matches(word.lower(), list(options), n=1, cutoff=cutoff)
    return f"; did you mean '{options[close[0]]}'?" if close else ""


def is_bare_name(text: str) -> bool:
    """Whether ``text`` reads as a name (a bundled character's, ``"ben"``) rather than a
    file path: non-blank, without ``.``, ``/``, ``\\`` or a NUL."""
    return bool(text.strip()) and not any(c in text for c in "./\\\0")
