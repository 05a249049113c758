"""What the storyboard readers share while turning script values into cues."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from facelib.cues import Origin

__all__ = ["Context", "line_of_name"]


@dataclass(frozen=True, slots=True)
class Context:
    """The script being read: its ``path`` (as shown in errors and origins), its text,
    the folder its file names resolve in, and the storyboard's frame rate."""

    path: str
    source: str
    base_dir: Path | None
    fps: float

    def line_of(self, name: str, *, after: int | None = None) -> int | None:
        """Line where ``name = ...`` is first written (at or after line ``after``)."""
        return line_of_name(self.source, name, after=after)

    def origin(self, line: int | None) -> Origin | None:
        """The cue origin ``(path, line)`` of line ``line`` of this script (None without)."""
        return None if line is None else (self.path, int(line))


def line_of_name(source: str, name: str, *, after: int | None = None) -> int | None:
    """1-based line of the first ``name =`` (not ``==``) in ``source`` at or after ``after``.

    Used to point errors about a global or a table field at the line that sets it.
    """
    pattern = re.compile(rf"(?<![\w.]){re.escape(name)}\s*=(?!=)")
    for number, text in enumerate(source.splitlines(), start=1):
        if after is not None and number < after:
            continue
        if pattern.search(text):
            return number
    return after
