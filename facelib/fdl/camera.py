"""The ``camera`` storyboard function: re-frame the rendered video over time.

``camera { framing = "head", at = 2, dur = 0.5 }`` (or ``camera { "head", at = 2 }``) moves
the camera to the named framing, arriving ``dur`` seconds after ``at`` (no ``dur``: a cut).
In a storyboard with characters (:mod:`facelib.fdl.cast`) ``camera { who = "ben" }`` cuts
to one character and ``camera { "two_shot" }`` to all of them side by side.
The framings are the renderer's (``render_look.json``, read through :mod:`facelib.data`, so
the storyboard layer need not load the renderer). A call without ``at`` starts where the
previous camera call's move ended (the first at 0).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import TYPE_CHECKING

from facelib import data
from facelib.checks import did_you_mean
from facelib.cues import TWO_SHOT, CameraCue
from facelib.errors import FdlError
from facelib.fdl.context import Context
from facelib.fdl.modern import DraftCue, ModernParts, table_of, who_of
from facelib.fdl.timing import parse_time

if TYPE_CHECKING:
    from facelib.fdl.functions import StoryboardFunction

__all__ = ["camera_cues", "framing_names", "read_camera"]


def framing_names() -> tuple[str, ...]:
    """The named framings a camera cue may ask for (the renderer's)."""
    return tuple(data.json_data("render_look.json")["framings"])


def _framing(items: Sequence[object], fields: dict[str, object], ctx: Context,
             line: int | None) -> str | None:
    """The framing a call names; None only when it names a character (``who``), whose
    shot then takes the render's framing."""
    if len(items) > 1 or (items and "framing" in fields):
        raise FdlError('camera takes one framing: camera { framing = "head", at = ... }',
                       path=ctx.path, line=line)
    value = items[0] if items else fields.get("framing")
    if value is None:
        if "who" in fields:
            return None
        raise FdlError('camera needs a framing, like camera { framing = "head", at = 2 }',
                       path=ctx.path, line=line)
    names = framing_names()
    if not isinstance(value, str) or value not in (*names, TWO_SHOT):
        hint = did_you_mean(value, (*names, TWO_SHOT)) if isinstance(value, str) else ""
        raise FdlError(f"camera: framing {value!r} is not one of {', '.join(names)}{hint}",
                       path=ctx.path, line=line)
    return value


def read_camera(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``camera { framing = "...", at, dur }``: a camera cut or move."""
    t = table_of(arg, "camera", ctx, line, allowed=fn.fields)
    framing = _framing(t.items, dict(t.fields), ctx, line)
    at = t.fields.get("at")
    parts.camera.append(DraftCue(
        name=framing or "", args=(), who=who_of(t, "camera", ctx, line),
        at_ms=None if at is None else parse_time(at, fps=ctx.fps, what="camera: at",
                                                 path=ctx.path, line=line),
        duration_ms=parse_time(t.fields.get("dur", 0), fps=ctx.fps, what="camera: dur",
                               path=ctx.path, line=line),
        line=line))


def camera_cues(drafts: Sequence[DraftCue], ctx: Context) -> tuple[CameraCue, ...]:
    """``camera`` drafts as cues in time order; FdlError where a move starts before the
    previous one has arrived (the moves of one camera cannot overlap)."""
    cues: list[CameraCue] = []
    cursor = 0
    for d in drafts:
        start = cursor if d.at_ms is None else d.at_ms
        cues.append(CameraCue(framing=d.name or None, start_ms=start, duration_ms=d.duration_ms,
                              origin=ctx.origin(d.line), who=d.who))
        cursor = start + d.duration_ms
    ordered = sorted(cues, key=lambda c: c.start_ms)
    for before, after in itertools.pairwise(ordered):
        if after.start_ms < before.end_ms:
            line = after.origin[1] if after.origin else None
            raise FdlError(
                f"camera: the move to {after.framing!r} at {after.start_ms} ms starts before "
                f"the move to {before.framing!r} arrives ({before.end_ms} ms)",
                path=ctx.path, line=line)
    return tuple(ordered)
