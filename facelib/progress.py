"""Progress of long jobs: a callback protocol and the console reporter behind it.

Every long-running API (``render``, ``run_fdl``, batch and dataset runs) takes
``progress=``: None or False for silence, True for :class:`ConsoleProgress` on stderr, or any
callable ``progress(done, total)`` called with whole numbers as work completes
(``0 <= done <= total``; the last call has ``done == total``).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

__all__ = ["ConsoleProgress", "ProgressCallback", "progress_callback"]

ProgressCallback = Callable[[int, int], None]
"""``progress(done, total)``: units done so far and the total (frames, stages, clips)."""

_BAR_WIDTH = 30


class ConsoleProgress:
    """Report ``(done, total)`` on a text stream.

    On a terminal: one bar redrawn in place (``\\r``), at most every 0.1 s, erased at the end.
    Otherwise (a log file, a pipe, CI): one line at each new tenth, e.g.
    ``rendering: 40% (48/120 frames, 3.1 s)``, so long jobs are never silent.
    """

    def __init__(self, label: str, *, unit: str = "frames", stream: TextIO | None = None,
                 tty: bool | None = None) -> None:
        self.label = label
        self.unit = unit
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self._isatty() if tty is None else tty
        self._started = time.monotonic()
        self._last_draw = 0.0
        self._tenth = -1
        self._drawn = False

    def _isatty(self) -> bool:
        isatty = getattr(self.stream, "isatty", None)
        return bool(isatty and isatty())

    def __call__(self, done: int, total: int) -> None:
        if total <= 0:
            return
        done = max(0, min(done, total))
        elapsed = time.monotonic() - self._started
        if self.tty:
            if done < total and elapsed - self._last_draw < 0.1 and self._drawn:
                return
            self._last_draw = elapsed
            filled = round(_BAR_WIDTH * done / total)
            bar = "#" * filled + "-" * (_BAR_WIDTH - filled)
            self.stream.write(f"\r{self.label} [{bar}] {done}/{total} {self.unit}")
            self._drawn = True
            if done == total:
                self.stream.write("\r" + " " * (len(self.label) + _BAR_WIDTH + 40) + "\r")
                self._drawn = False
            self.stream.flush()
            return
        tenth = done * 10 // total
        if tenth > self._tenth:
            self._tenth = tenth
            self.stream.write(f"{self.label}: {tenth * 10}% ({done}/{total} {self.unit}, "
                              f"{elapsed:.1f} s)\n")
            self.stream.flush()


def progress_callback(progress: bool | ProgressCallback | None, label: str, *,
                      unit: str = "frames") -> ProgressCallback | None:
    """The callback for a ``progress=`` argument: None/False -> None, True -> a
    :class:`ConsoleProgress` on stderr, a callable -> itself."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return ConsoleProgress(label, unit=unit)
    if not callable(progress):
        from facelib.errors import ParameterError

        raise ParameterError(f"progress must be True, False, None or a callable "
                             f"progress(done, total), got {progress!r}")
    return progress
