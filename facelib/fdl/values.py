"""Lua values left by a script, copied into plain Python with the line of each table.

:func:`to_python` turns a Lua table into a :class:`LuaTable` (its array part, its named
fields and the 1-based source line of its ``{``), recursively. Strings, numbers, booleans
and nil come through as ``str``, ``int``/``float``, ``bool`` and ``None``; functions and
other Lua values become :class:`Opaque` so validation can name them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from facelib.errors import FdlError

__all__ = ["LuaTable", "LuaValue", "Opaque", "to_python"]

_MAX_DEPTH = 32
_MAX_NODES = 1_000_000
MAX_STRING_CHARS = 16 * 1024 * 1024
"""Characters of strings a script may hand to the host in all (each reference counts)."""


@dataclass(frozen=True, slots=True)
class Opaque:
    """A Lua value with no data meaning here (a function, ...): ``kind`` is its Lua type."""

    kind: str


@dataclass(frozen=True, slots=True)
class LuaTable:
    """A Lua table: ``items`` holds keys 1..n in order, ``fields`` the string keys,
    ``line`` the line of its constructor (None when no constructor made it)."""

    items: tuple[LuaValue, ...] = ()
    fields: dict[str, LuaValue] = field(default_factory=dict)
    line: int | None = None


LuaValue = str | int | float | bool | LuaTable | Opaque | None
"""A Lua value copied into Python by :func:`to_python`."""


def lua_kind(value: Any) -> str:
    """The Lua type name of a converted value (for error messages)."""
    if value is None:
        return "nil"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int | float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, LuaTable):
        return "table"
    if isinstance(value, Opaque):
        return value.kind
    return type(value).__name__


def to_python(value: Any, lines: Any, *, path: str, line: int | None = None) -> LuaValue:
    """Copy ``value`` (a lupa value) into plain Python.

    ``lines`` is the sandbox's table -> line map. Tables nested deeper than 32 levels
    (or cyclic), more than a million values or more than :data:`MAX_STRING_CHARS` characters
    of strings in all (a string referenced twice counts twice) raise FdlError.
    """
    try:
        return _Copier(lines, path).value(value, 0, line)
    except UnicodeDecodeError:
        raise FdlError("a string is not valid UTF-8", path=path, line=line) from None


class _Copier:
    """One copy out of Lua, with its budgets of values and string characters."""

    def __init__(self, lines: Any, path: str) -> None:
        from lupa import lua54

        self.lua_type = lua54.lua_type
        self.lines = lines
        self.path = path
        self.values = 0
        self.chars = 0

    def fail(self, message: str, line: int | None) -> FdlError:
        return FdlError(message, path=self.path, line=line)

    def value(self, v: Any, depth: int, where: int | None) -> LuaValue:
        self.values += 1
        if self.values > _MAX_NODES:
            raise self.fail(f"script left more than {_MAX_NODES} values", where)
        if isinstance(v, str):
            self.chars += len(v)
            if self.chars > MAX_STRING_CHARS:
                raise self.fail(f"script left more than {MAX_STRING_CHARS} characters of "
                                "strings", where)
            return v
        if v is None or isinstance(v, bool | int | float):
            return v
        if isinstance(v, bytes):
            raise self.fail("a string is not valid UTF-8", where)
        kind = self.lua_type(v)
        if kind != "table":
            return Opaque(kind or type(v).__name__)
        return self.table(v, depth, where)

    def table(self, v: Any, depth: int, where: int | None) -> LuaTable:
        own = self.lines[v]
        here = int(own) if isinstance(own, int) else where
        if depth >= _MAX_DEPTH:
            raise self.fail(f"tables nested deeper than {_MAX_DEPTH} levels (a cycle?)", here)
        numbered: dict[int, LuaValue] = {}
        named: dict[str, LuaValue] = {}
        for key, item in v.items():
            if isinstance(key, bool) or not isinstance(key, int | str):
                raise self.fail(f"table key {key!r} is neither a name nor a position", here)
            if isinstance(key, int):
                numbered[key] = self.value(item, depth + 1, here)
            else:
                named[key] = self.value(item, depth + 1, here)
        n = len(numbered)
        if numbered and (min(numbered) != 1 or max(numbered) != n):
            gaps = [i for i in range(1, n + 4) if i not in numbered][:3]
            raise self.fail(f"table has holes in its list part (missing positions {gaps})", here)
        items = tuple(numbered[i] for i in range(1, n + 1))
        # named fields in name order: Lua's hash order changes from state to state
        return LuaTable(items=items, fields=dict(sorted(named.items())),
                        line=here if own is not None else None)
