"""The ``mood`` storyboard function: a baseline mood from a time on.

``mood { "happy", at = 2, intensity = 0.6, ease = 1 }`` puts the character in the named
mood (a row of ``facelib/data/moods/moods.csv``, read through :mod:`facelib.data`, so the
storyboard layer need not load the expression library) from ``at`` until the next mood
call. A call without ``at`` starts at 0 for the first mood, else 2 s after the previous
mood's start. ``ease`` (seconds) is how long the face takes to settle into it.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import TYPE_CHECKING

from facelib import data
from facelib.checks import did_you_mean
from facelib.cues import MoodCue
from facelib.errors import FdlError
from facelib.fdl.context import Context
from facelib.fdl.modern import DraftCue, ModernParts, table_of, who_of
from facelib.fdl.timing import parse_time

if TYPE_CHECKING:
    from facelib.fdl.functions import StoryboardFunction

__all__ = ["mood_cues", "mood_names", "read_mood"]

_FOLLOW_MS = 2000  # a mood without ``at`` starts this long after the previous one


def mood_names() -> tuple[str, ...]:
    """The moods a storyboard may name."""
    return tuple(row["mood"] for _, row in data.csv_rows("moods/moods.csv"))


def _mood_name(items: Sequence[object], ctx: Context, line: int | None) -> str:
    names = mood_names()
    if len(items) != 1:
        raise FdlError(f'mood takes one mood name first, like mood {{ "happy", at = 2 }}; '
                       f"moods: {', '.join(names)}", path=ctx.path, line=line)
    value = items[0]
    if not isinstance(value, str) or value.lower() not in names:
        hint = did_you_mean(value, names) if isinstance(value, str) else ""
        raise FdlError(f"mood: {value!r} is not one of {', '.join(names)}{hint}",
                       path=ctx.path, line=line)
    return value.lower()


def read_mood(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``mood { "name", at, intensity, ease }``: a mood from ``at`` on."""
    t = table_of(arg, "mood", ctx, line, allowed=fn.fields)
    name = _mood_name(t.items, ctx, line)
    intensity = t.fields.get("intensity", 1.0)
    if (isinstance(intensity, bool) or not isinstance(intensity, int | float)
            or not 0.0 <= intensity <= 1.0):
        raise FdlError(f"mood: intensity must be a number from 0 to 1; got {intensity!r}",
                       path=ctx.path, line=line)
    at, ease = t.fields.get("at"), t.fields.get("ease")
    parts.moods.append(DraftCue(
        name=name, args=(),
        at_ms=None if at is None else parse_time(at, fps=ctx.fps, what="mood: at",
                                                 path=ctx.path, line=line),
        duration_ms=0, line=line, intensity=float(intensity),
        ramp_in_ms=None if ease is None else parse_time(ease, fps=ctx.fps,
                                                        what="mood: ease", path=ctx.path,
                                                        line=line),
        who=who_of(t, "mood", ctx, line)))


def mood_cues(drafts: Sequence[DraftCue], ctx: Context) -> tuple[MoodCue, ...]:
    """``mood`` drafts as cues in time order; FdlError where two start at the same time."""
    cues: list[MoodCue] = []
    cursor: int | None = None
    for d in drafts:
        start = d.at_ms if d.at_ms is not None else (
            0 if cursor is None else cursor + _FOLLOW_MS)
        cues.append(MoodCue(d.name, start, intensity=d.intensity, ease_ms=d.ramp_in_ms,
                            origin=ctx.origin(d.line)))
        cursor = start
    ordered = sorted(cues, key=lambda c: c.start_ms)
    for before, after in itertools.pairwise(ordered):
        if after.start_ms == before.start_ms:
            raise FdlError(f"mood: {before.name!r} and {after.name!r} both start at "
                           f"{after.start_ms} ms", path=ctx.path,
                           line=after.origin[1] if after.origin else None)
    return tuple(ordered)
