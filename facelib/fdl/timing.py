"""Time values of FDL scripts, converted to integer milliseconds.

Modern syntax: a number is seconds (``1.5``); a string names its unit: ``"1.5s"``,
``"200ms"``, ``"12f"`` / ``"12 frames"`` (frames of the storyboard's fps).
Thesis format: every duration is a number of frames at the storyboard's fps.
"""

from __future__ import annotations

import math
import re

from facelib.errors import FdlError

__all__ = ["frames_to_ms", "parse_time"]

_TIME = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*(ms|s|f|frames?)\s*$")
MAX_MS = 24 * 3600 * 1000
"""Longest time a storyboard may name (a day)."""


def frames_to_ms(frames: float, fps: float) -> int:
    """Start of frame ``frames`` (counted from 0) at ``fps``, in whole milliseconds."""
    return round(frames * 1000.0 / fps)


def parse_time(value: object, *, fps: float, what: str, path: str, line: int | None) -> int:
    """Milliseconds named by a modern-syntax time ``value`` (seconds or a unit string).

    Raises FdlError naming ``what`` for negative, non-finite, malformed or over-long times.
    """
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise FdlError(
            f'{what} must be seconds (a number) or a string like "1.5s", "200ms", "12f";'
            f" got {value!r}",
            path=path,
            line=line,
        )
    if isinstance(value, str):
        m = _TIME.match(value)
        if not m:
            raise FdlError(
                f'{what} {value!r} is not a time; write "1.5s", "200ms" or "12f"',
                path=path,
                line=line,
            )
        number, unit = float(m.group(1)), m.group(2)
        ms = number if unit == "ms" else number * 1000.0 if unit == "s" else number * 1000.0 / fps
    else:
        if not math.isfinite(value) or value < 0:
            raise FdlError(
                f"{what} must be a finite time >= 0; got {value!r}", path=path, line=line
            )
        ms = float(value) * 1000.0
    if ms > MAX_MS:
        raise FdlError(f"{what} {value!r} is longer than a day", path=path, line=line)
    return round(ms)
