"""The thesis's FDL format (Queiroz 2010, section 4.2.5).

A storyboard sets ``FDL = { speakSound = ..., speakText = ..., expressionScript = ...,
eyesScript = ..., visemeScript = ..., output = ... }`` (``"none"`` for an absent part).
Sub-scripts hold one list each: ``expressions = { {"joy", 100}, ... }``,
``eyes = { {"lookTo", "left", 17.0, "yes", 50}, ... }`` and
``Sentence = { {"silence", 11}, {"A", 6}, ... }``. The last value of every entry is a
duration in frames at the storyboard's fps; entries follow each other without gaps.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from facelib.checks import did_you_mean
from facelib.errors import FdlError
from facelib.fdl.context import Context
from facelib.fdl.timing import frames_to_ms
from facelib.fdl.values import LuaTable, lua_kind

__all__ = ["FDL_FIELDS", "SCRIPT_GLOBALS", "SequenceEntry", "check_fdl_table", "sequence"]

FDL_FIELDS = (
    "speakSound", "speakText", "expressionScript", "eyesScript", "visemeScript", "output",
)  # fmt: skip
"""Fields of the thesis's ``FDL`` table."""

SCRIPT_GLOBALS = {
    "expressionScript": "expressions",
    "eyesScript": "eyes",
    "visemeScript": "Sentence",
}
"""The list each sub-script field's file must define."""


@dataclass(frozen=True, slots=True)
class SequenceEntry:
    """One entry of a thesis list: name, the values between name and duration, times."""

    name: str
    args: tuple[str | float, ...]
    start_ms: int
    duration_ms: int
    line: int | None


def check_fdl_table(table: object, ctx: Context, line: int | None) -> dict[str, str | None]:
    """The ``FDL`` table's fields as ``{field: value or None for "none"}``.

    Raises FdlError for a non-table, positional entries, unknown fields (with a suggestion)
    and non-string values.
    """
    if not isinstance(table, LuaTable):
        raise FdlError(f"FDL must be a table; got a {lua_kind(table)}", path=ctx.path, line=line)
    where = table.line or line
    if table.items:
        raise FdlError(
            "FDL holds named fields only (speakSound = ..., ...); found a list entry "
            f"{table.items[0]!r}",
            path=ctx.path,
            line=where,
        )
    out: dict[str, str | None] = {}
    for key, value in table.fields.items():
        key_line = ctx.line_of(key, after=where)
        if key not in FDL_FIELDS:
            raise FdlError(
                f"unknown FDL field {key!r}{did_you_mean(key, FDL_FIELDS)}"
                f" (fields: {', '.join(FDL_FIELDS)})",
                path=ctx.path,
                line=key_line,
            )
        if not isinstance(value, str):
            raise FdlError(
                f'FDL.{key} must be a file name or "none"; got a {lua_kind(value)} {value!r}',
                path=ctx.path,
                line=key_line,
            )
        out[key] = None if value.strip().lower() == "none" or not value.strip() else value
    return out


def sequence(
    table: object,
    ctx: Context,
    *,
    list_name: str,
    min_len: int,
    max_len: int | None,
    line: int | None,
) -> Iterator[SequenceEntry]:
    """Entries of a thesis list ``{ {name, ..., frames}, ... }``, one after the other from 0.

    ``min_len`` / ``max_len`` bound the number of values per entry (name and duration
    included). Raises FdlError with the entry's line for malformed entries.
    """
    if not isinstance(table, LuaTable):
        raise FdlError(
            f"{list_name} must be a list of entries; got a {lua_kind(table)}",
            path=ctx.path,
            line=line,
        )
    if table.fields:
        key = next(iter(table.fields))
        raise FdlError(
            f"{list_name} is a list of {{name, ..., duration}} entries; found the field {key!r}",
            path=ctx.path,
            line=table.line or line,
        )
    frame = 0.0
    for index, entry in enumerate(table.items, start=1):
        where = entry.line if isinstance(entry, LuaTable) and entry.line else table.line or line
        name, args, frames = _entry(entry, f"{list_name}[{index}]", ctx, where,
                                    min_len=min_len, max_len=max_len)
        start = frames_to_ms(frame, ctx.fps)
        frame += frames
        end = frames_to_ms(frame, ctx.fps)
        yield SequenceEntry(name=name, args=args, start_ms=start, duration_ms=end - start,
                            line=where)


def _entry(
    entry: object, label: str, ctx: Context, where: int | None, *, min_len: int,
    max_len: int | None,
) -> tuple[str, tuple[str | float, ...], float]:
    """One entry ``{name, ..., frames}`` of a thesis list as (name, values between, frames);
    FdlError naming ``label`` (``eyes[2]``) at line ``where`` if it is malformed."""
    if not isinstance(entry, LuaTable) or entry.fields:
        raise FdlError(
            f'{label} must be a list like {{"name", ..., frames}}; got {_show(entry)}',
            path=ctx.path,
            line=where,
        )
    values = entry.items
    if len(values) < min_len or (max_len is not None and len(values) > max_len):
        expected = str(min_len) if max_len == min_len else f"at least {min_len}"
        raise FdlError(
            f"{label} has {len(values)} values; expected {expected} (name, ..., frames)",
            path=ctx.path,
            line=where,
        )
    name, *args, frames = values
    if not isinstance(name, str) or not name:
        raise FdlError(f"{label} must start with a name; got {name!r}", path=ctx.path, line=where)
    if isinstance(frames, bool) or not isinstance(frames, int | float) or not 0 <= frames < 1e7:
        raise FdlError(
            f"{label} ends with {frames!r}; expected a duration in frames (a number >= 0)",
            path=ctx.path,
            line=where,
        )
    between: list[str | float] = []
    for arg in args:
        if isinstance(arg, bool) or not isinstance(arg, str | int | float):
            raise FdlError(
                f"{label} value {arg!r} must be a string or a number", path=ctx.path, line=where
            )
        between.append(arg if isinstance(arg, str) else float(arg))
    return name, tuple(between), float(frames)


def _show(value: object) -> str:
    if isinstance(value, LuaTable):
        return "a table with named fields"
    return f"a {lua_kind(value)} {value!r}"
