"""Live input as plain data: text split into sentences as it streams in, and cues from
small JSON messages or one-line FDL snippets (run in the storyboard sandbox).

A cue's times count from the moment it is placed (``at`` in a snippet or ``at_ms`` in a
message: that much later).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from facelib.cues import CameraCue, ExpressionCue, GazeCue
from facelib.errors import FdlError, ParameterError

__all__ = ["MAX_SNIPPET_CHARS", "Cues", "cues_from_fdl", "cues_from_json", "split_sentences"]

MAX_SNIPPET_CHARS = 400
"""Longest FDL snippet a cue may carry."""
_MAX_MS = 600_000
_SNIPPET_MEMORY = 8 * 1024 * 1024  # bytes a snippet's Lua state may allocate
_SNIPPET_STEPS = 200_000  # VM instructions a snippet may run (a few ms)
_END = re.compile(r"[.!?;:](?:[\"')\]]*)(?:\s+|$)")


@dataclass(frozen=True)
class Cues:
    """Cues to place together (times from the moment they are placed)."""

    expressions: tuple[ExpressionCue, ...] = ()
    gaze: tuple[GazeCue, ...] = ()
    camera: tuple[CameraCue, ...] = ()


def split_sentences(buffer: str, *, flush: bool = False) -> tuple[list[str], str]:
    """The complete sentences at the start of ``buffer`` (each ending in ``. ! ? ; :``
    followed by white space or the end) and the rest; ``flush`` makes the rest a sentence
    too. Sentences without a letter or digit (stray punctuation) are dropped."""
    sentences: list[str] = []
    start = 0
    for match in _END.finditer(buffer):
        sentences.append(buffer[start:match.end()].strip())
        start = match.end()
    rest = buffer[start:]
    if flush:
        sentences.append(rest.strip())
        rest = ""
    return [s for s in sentences if any(c.isalnum() for c in s)], rest


def _ms(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | float) or not (
            0 <= value <= _MAX_MS):
        raise ParameterError(f"{what} must be a number of ms from 0 to {_MAX_MS}, got {value!r}")
    return round(value)


def cues_from_json(message: Mapping[str, object]) -> Cues:
    """A cue message's cues: ``{"show": name, "dur_ms", "intensity"}``,
    ``{"look": behaviour, "args": [...], "dur_ms"}`` or ``{"camera": framing, "dur_ms"}``
    (``dur_ms`` of a camera move: 0 = a cut). ParameterError naming what is wrong."""
    kinds = [k for k in ("show", "look", "camera") if k in message]
    if len(kinds) != 1:
        raise ParameterError("a cue names exactly one of show, look, camera (or carries fdl)")
    kind = kinds[0]
    name = message[kind]
    if not isinstance(name, str) or not 0 < len(name) <= 64:
        raise ParameterError(f"{kind} must name something (a short string), got {name!r}")
    duration = _ms(message.get("dur_ms", 0 if kind == "camera" else 1000), "dur_ms")
    if kind == "show":
        intensity = message.get("intensity", 1.0)
        if isinstance(intensity, bool) or not isinstance(intensity, int | float) or not (
                0 <= intensity <= 1):
            raise ParameterError(f"intensity must be from 0 to 1, got {intensity!r}")
        return Cues(expressions=(ExpressionCue(name, 0, duration, float(intensity)),))
    if kind == "look":
        args = message.get("args", [])
        if not isinstance(args, list) or len(args) > 8 or not all(
                isinstance(a, str | int | float) and not isinstance(a, bool) for a in args):
            raise ParameterError("look args must be a list of up to 8 strings or numbers")
        values = tuple(a if isinstance(a, str) else float(a) for a in args)
        return Cues(gaze=(GazeCue(name, values, 0, duration),))
    return Cues(camera=(CameraCue(name, 0, duration),))


def cues_from_fdl(snippet: str) -> Cues:
    """The cues of a one-line FDL snippet (``show {...}``, ``look {...}``, ``camera {...}``),
    run in a fresh sandbox with the storyboard's limits. FdlError for anything else a
    storyboard may hold (speech, definitions, settings) or an over-long snippet."""
    from facelib.fdl import Sandbox, loads

    if not isinstance(snippet, str) or "\n" in snippet or len(snippet) > MAX_SNIPPET_CHARS:
        raise FdlError(f"a cue snippet is one line of at most {MAX_SNIPPET_CHARS} characters")
    board = loads(snippet, name="<cue>", sandbox=Sandbox(max_memory=_SNIPPET_MEMORY,
                                                         max_instructions=_SNIPPET_STEPS))
    if (board.speech is not None or board.expression_defs or board.gaze_defs
            or board.expression_mixes or board.output is not None or board.face is not None
            or board.hair is not None):
        raise FdlError("a cue snippet may only show, look and move the camera "
                       "(speech goes in a text message)", path="<cue>", line=1)
    return Cues(board.expressions, board.gaze, board.camera)
