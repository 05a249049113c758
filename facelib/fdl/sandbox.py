"""The sandboxed Lua 5.4 runtime that runs FDL scripts.

An ``.fdl`` file is untrusted code. :class:`Sandbox` runs it in ``lupa.lua54`` with:

- no Python builtins, no ``python.eval``, an attribute filter that refuses every Python
  attribute, and no Python object reachable from user code (host callables are upvalues
  of trusted Lua closures only);
- a fresh environment table per chunk holding a whitelist: ``string`` (without ``dump``,
  pattern functions bounded), ``table``, ``math`` (``math.random`` seeded from the
  storyboard seed, no ``randomseed``), ``utf8``, ``pairs``, ``ipairs``, ``select``,
  ``type``, ``tostring``, ``tonumber``, ``error``, ``pcall``, ``assert`` and a ``print``
  (kept in :attr:`Sandbox.printed`; the loader passes it to the ``facelib.fdl`` logger),
  plus the storyboard functions the caller names;
- chunks compiled from text only (mode ``"t"``) under their file name;
- a memory cap (``max_memory``), an instruction budget enforced by a count hook that the
  host installs before user code runs, with the C work of the string and table libraries
  charged to it (one instruction per byte or element), and a wall-clock limit
  (``max_seconds``) checked by the same hook; user ``pcall`` cannot catch any limit;
- ``pairs`` that visits keys in a stable order (numbers, strings, booleans sorted, then
  tables and functions in the order the script made them) and a ``tostring`` (also used
  by ``print`` and ``string.format``, which refuses ``%p``) that shows tables and
  functions by that creation number, never an address, so a script gives the same
  storyboard whatever Lua's per-state string hash seed and the process's addresses are;
- the string metatable's ``__index`` pointing to the sandbox's own ``string`` copy.

Every failure is raised as :class:`~facelib.errors.FdlError` with the file and line; the
sandbox stays usable afterwards.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass
from typing import Any

from facelib import data
from facelib.checks import check_count, check_number, did_you_mean
from facelib.errors import FdlError
from facelib.fdl.marking import mark_functions, mark_tables

__all__ = [
    "DEFAULT_MAX_INSTRUCTIONS",
    "DEFAULT_MAX_MEMORY",
    "DEFAULT_MAX_SECONDS",
    "WHITELIST",
    "ChunkResult",
    "Sandbox",
    "one_line",
]

DEFAULT_MAX_MEMORY = 64 * 1024 * 1024
"""Bytes the whole Lua state may hold (64 MiB)."""
DEFAULT_MAX_INSTRUCTIONS = 100_000_000
"""Lua VM instructions one chunk may execute (well under a second of pure Lua on a laptop core)."""
DEFAULT_MAX_SECONDS = 5.0
"""Wall-clock seconds one chunk may run."""
MAX_SOURCE_BYTES = 1024 * 1024
"""Largest script text accepted (1 MiB)."""
_MAX_PRINT_CHARS = 2000
_MAX_PRINT_LINES = 1000
_MAX_MESSAGE_CHARS = 300

WHITELIST = (
    "string", "table", "math", "utf8", "pairs", "ipairs", "select", "type", "tostring",
    "tonumber", "error", "pcall", "assert", "print",
)  # fmt: skip
"""Globals every chunk gets, besides the storyboard functions the caller names."""


def _refuse_attribute(obj: object, name: object, is_setting: bool) -> str:
    raise AttributeError(f"access to Python attribute {name!r} is not allowed in FDL")


@dataclass(frozen=True, slots=True)
class ChunkResult:
    """What one chunk left behind.

    ``env`` is the chunk's global table, ``lines`` a weak map from each table the chunk
    constructed to the 1-based line of its ``{``, and ``calls`` the storyboard-function
    calls in order as Lua tables ``{name, first_argument, line, n_arguments}``.
    ``instructions`` counts the VM instructions used (in steps of 1000).
    """

    path: str
    env: Any
    lines: Any
    calls: Any
    instructions: int


class Sandbox:
    """A reusable sandboxed Lua 5.4 state.

    Parameters
    ----------
    max_memory: bytes the Lua state may allocate in all.
    max_instructions: VM instructions one chunk may execute (C work of the string and table
        libraries counts one per byte or element).
    max_seconds: wall-clock seconds one chunk may run.

    ``printed`` keeps the first 1000 lines a script prints (each cut to 2000 characters).
    """

    def __init__(
        self,
        *,
        max_memory: int = DEFAULT_MAX_MEMORY,
        max_instructions: int = DEFAULT_MAX_INSTRUCTIONS,
        max_seconds: float = DEFAULT_MAX_SECONDS,
    ) -> None:
        self.max_memory = check_count("max_memory", max_memory, low=1024 * 1024)
        self.max_instructions = check_count("max_instructions", max_instructions, low=1000)
        self.max_seconds = check_number("max_seconds", max_seconds, low=0.0, high=3600.0,
                                        low_open=True)
        self.printed: list[str] = []
        self._start()

    def _start(self) -> None:
        from lupa import lua54

        self._lupa = lua54
        self._lua = lua54.LuaRuntime(
            register_eval=False,
            register_builtins=False,
            unpack_returned_tuples=True,
            attribute_filter=_refuse_attribute,
            max_memory=self.max_memory,
        )
        boot = data.text("fdl/sandbox.lua")
        # The bootstrap needs the standard library, so it runs without the memory cap.
        self._run, self._collect = self._lua.execute(
            boot, self._print, time.monotonic, name="=fdl-sandbox", mode="t"
        )

    def _print(self, text: object) -> None:
        if len(self.printed) > _MAX_PRINT_LINES:
            return
        if len(self.printed) == _MAX_PRINT_LINES:
            self.printed.append(f"... (printing stopped after {_MAX_PRINT_LINES} lines)")
            return
        message = str(text)
        if len(message) > _MAX_PRINT_CHARS:
            message = message[:_MAX_PRINT_CHARS] + "..."
        self.printed.append(message)

    def run(
        self,
        source: str,
        *,
        path: str,
        seed: int = 0,
        functions: tuple[str, ...] = (),
    ) -> ChunkResult:
        """Run ``source`` (the text of file ``path``) and return what it left behind.

        ``functions`` names the storyboard functions (recorders) to expose as globals.
        Raises FdlError with ``path`` and the line for syntax errors, runtime errors,
        exceeded memory and exceeded instruction budget.
        """
        if "\0" in source:
            raise FdlError("script contains a NUL character", path=path)
        if len(source.encode("utf-8", "surrogatepass")) > MAX_SOURCE_BYTES:
            raise FdlError(f"script is larger than {MAX_SOURCE_BYTES} bytes", path=path)
        short = _chunk_short_name(path)
        marked = f"local __fdl_at, __fdl_fn = ...; {mark_functions(mark_tables(source))}"
        api = self._lua.table_from(list(functions))
        lua_seed = int(seed) % (1 << 63)
        try:
            result = self._run(source, marked, "@" + short, self.max_instructions, lua_seed, api,
                               self.max_seconds)
        except self._lupa.LuaMemoryError:
            self._restart()
            raise FdlError(
                f"script exceeded the sandbox memory limit ({self.max_memory} bytes)", path=path
            ) from None
        except self._lupa.LuaError as exc:  # trusted code failed: start afresh
            self._restart()
            raise FdlError(f"script failed in the sandbox: {exc}", path=path) from None
        if result[0]:
            _, env, lines, calls, used = result
            return ChunkResult(path=path, env=env, lines=lines, calls=calls, instructions=used)
        _, kind, message, line, _used = result
        raise _error(kind, str(message), line, path=path, short=short, limits=self,
                     functions=functions)

    def _restart(self) -> None:
        self._start()

    def collect(self) -> None:
        """Free what finished chunks left (called by the loader between chunks)."""
        self._collect()


def one_line(text: str, *, limit: int = _MAX_MESSAGE_CHARS) -> str:
    """``text`` made safe to print as part of one message line: control characters (line
    breaks included) shown as escapes, and cut to ``limit`` characters."""
    safe = "".join(c if c.isprintable() else repr(c)[1:-1] for c in text[: limit + 1])
    return safe if len(safe) <= limit else safe[:limit] + "..."


def _chunk_short_name(path: str) -> str:
    name = path.replace("\\", "/").rsplit("/", 1)[-1] or "script"
    return name[-50:]


_WHERE = re.compile(r"^(?P<src>[^\n]*?):(?P<line>\d+): (?P<msg>.*)$", re.DOTALL)
_GLOBAL = re.compile(r"\((?:global|field) '([A-Za-z_][A-Za-z0-9_]*)'\)")


def _error(
    kind: str, message: str, line: int, *, path: str, short: str, limits: Sandbox,
    functions: tuple[str, ...],
) -> FdlError:
    """The FdlError for a failed chunk; a call of an unknown global suggests the closest
    whitelisted name or storyboard function (``functions``, those the chunk was given)."""
    where = None if line is None or line < 1 else int(line)
    if kind == "instructions":
        return FdlError(
            f"script ran past the instruction budget ({limits.max_instructions} Lua "
            "instructions); is there an endless loop?",
            path=path,
            line=where,
        )
    if kind == "time":
        return FdlError(
            f"script ran longer than the sandbox time limit ({limits.max_seconds:g} s)",
            path=path,
            line=where,
        )
    if kind == "memory":
        return FdlError(
            f"script exceeded the sandbox memory limit ({limits.max_memory} bytes)",
            path=path,
            line=where,
        )
    m = _WHERE.match(message)
    if (m and m.group("src") in (short, f"...{short[-40:]}")) or (
        m and m.group("src").endswith(short[-20:])
    ):
        where = int(m.group("line"))
        message = m.group("msg")
    message = one_line(message)
    if kind == "syntax" and "too many registers" in message:
        return FdlError("tables or expressions nested too deeply for the sandbox (it marks "
                        "every table with its line; about 80 levels fit)", path=path,
                        line=where)
    if kind == "syntax":
        return FdlError(f"syntax error: {message}", path=path, line=where)
    g = _GLOBAL.search(message)
    if g and ("call" in message or "index" in message):
        message += did_you_mean(g.group(1), (*WHITELIST, *functions))
    return FdlError(message, path=path, line=where)

