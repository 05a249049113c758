"""Mark Lua table constructors with their source line, and function constructors.

Lua keeps no line numbers for table values, yet every storyboard cue must name the line it
came from. :func:`mark_tables` rewrites each table constructor ``{ ... }`` into
``__fdl_at(LINE, { ... })`` (and a call argument ``f{ ... }`` into
``f(__fdl_at(LINE, { ... }))``) without adding or removing newlines, so the marked chunk
reports the same line numbers as the original. The sandbox passes ``__fdl_at`` as a local
that records ``table -> line`` in a weak table.

:func:`mark_functions` wraps every function constructor in ``__fdl_fn(...)`` (statements
``function a.b:c() end`` and ``local function f() end`` become the assignments the Lua
manual defines them as), again without changing line numbers, so the sandbox sees every
function the script makes as it is made and can number tables and functions in creation
order (``pairs`` and ``tostring`` use that number, never an address).
"""

from __future__ import annotations

import re

__all__ = ["AT_NAME", "FN_NAME", "mark_functions", "mark_tables"]

AT_NAME = "__fdl_at"
FN_NAME = "__fdl_fn"

_KEYWORDS = frozenset(
    [
        "and",
        "break",
        "do",
        "else",
        "elseif",
        "end",
        "false",
        "for",
        "function",
        "goto",
        "if",
        "in",
        "local",
        "nil",
        "not",
        "or",
        "repeat",
        "return",
        "then",
        "true",
        "until",
        "while",
    ]
)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_NUMBER = re.compile(
    r"0[xX](?:[0-9a-fA-F]*\.?[0-9a-fA-F]*)(?:[pP][+-]?[0-9]+)?"
    r"|(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
)
_LONG_OPEN = re.compile(r"\[(=*)\[")


def _skip_short_string(src: str, i: int) -> int:
    """Index just after the quoted string starting at ``src[i]`` (or the end of the line)."""
    quote = src[i]
    i += 1
    n = len(src)
    while i < n:
        c = src[i]
        if c == "\\":
            if src.startswith("z", i + 1):
                i += 2
                while i < n and src[i].isspace():
                    i += 1
                continue
            i += 2
            continue
        if c == quote:
            return i + 1
        if c == "\n":
            return i  # unfinished string: Lua reports the syntax error itself
        i += 1
    return n


def _skip_long_bracket(src: str, i: int, level: str) -> int:
    close = "]" + level + "]"
    end = src.find(close, i)
    return len(src) if end < 0 else end + len(close)


def _token(source: str, i: int) -> tuple[int, str]:
    """End index and kind of the token starting at ``source[i]``.

    Kinds: ``"space"`` (whitespace, one character), ``"comment"``, ``"string"`` (short or
    long), ``"kw"`` (a Lua keyword), ``"name"``, ``"number"``, ``"{"``, ``"}"``, ``")"``,
    ``"]"`` or ``"op"`` (any other single character).
    """
    c = source[i]
    if c.isspace():
        return i + 1, "space"
    if source.startswith("--", i):
        m = _LONG_OPEN.match(source, i + 2)
        end = _skip_long_bracket(source, m.end(), m.group(1)) if m else source.find("\n", i)
        return (len(source) if end < 0 else end), "comment"
    if c in "\"'":
        return _skip_short_string(source, i), "string"
    if c == "[" and (m := _LONG_OPEN.match(source, i)):
        return _skip_long_bracket(source, m.end(), m.group(1)), "string"
    if m := _NAME.match(source, i):
        return m.end(), "kw" if m.group() in _KEYWORDS else "name"
    if (c.isdigit() or (c == "." and source[i + 1 : i + 2].isdigit())) and (
        m := _NUMBER.match(source, i)
    ):
        return m.end(), "number"
    return i + 1, c if c in "{})]" else "op"


def mark_tables(source: str) -> str:
    """Return ``source`` with every table constructor wrapped in ``__fdl_at(line, ...)``.

    Strings, long strings and comments are left untouched; the result has exactly the
    same number of lines, and each marker carries the 1-based line of its ``{``.
    """
    out: list[str] = []
    closers: list[str] = []  # what each open brace becomes when it closes
    line = 1
    i = 0
    prev = ""  # kind of the previous significant token (see _token)
    while i < len(source):
        end, kind = _token(source, i)
        text = source[i:end]
        if kind == "{":
            call_argument = prev in ("name", "string", ")", "]", "}")
            out.append(f"({AT_NAME}({line},{{" if call_argument else f"{AT_NAME}({line},{{")
            closers.append("}))" if call_argument else "})")
        elif kind == "}":
            out.append(closers.pop() if closers else "}")
        else:
            out.append(text)
        line += text.count("\n")
        if kind not in ("space", "comment"):
            prev = kind
        i = end
    return "".join(out)


def _tokens(source: str) -> list[tuple[str, str]]:
    """``(text, kind)`` of every token of ``source`` (kinds as :func:`_token`)."""
    out = []
    i = 0
    while i < len(source):
        end, kind = _token(source, i)
        out.append((source[i:end], kind))
        i = end
    return out


def _next_significant(tokens: list[tuple[str, str]], i: int) -> int:
    """Index of the first token at or after ``i`` that is not space or a comment."""
    while i < len(tokens) and tokens[i][1] in ("space", "comment"):
        i += 1
    return i


def _function_header(tokens: list[tuple[str, str]], i: int, local: bool) -> tuple[str, int]:
    """The text replacing ``function NAME(`` (``tokens[i]`` is ``function``) and the index
    of the token after its ``(``. Skipped line breaks are kept before the ``(``."""
    j = _next_significant(tokens, i + 1)
    if j < len(tokens) and tokens[j][0] == "(":  # an anonymous function
        return f"{FN_NAME}(function(", j + 1
    name, method, breaks = "", False, ""
    while j < len(tokens) and tokens[j][0] != "(":
        text, kind = tokens[j]
        if kind in ("space", "comment"):
            breaks += "\n" * text.count("\n")
        elif text == ":":
            name, method = name + ".", True
        else:
            name += text
        j += 1
    after = j + 1
    opening = "("
    if method:
        k = _next_significant(tokens, after)
        opening += "self" if k < len(tokens) and tokens[k][0] == ")" else "self, "
    target = f" {name}; {name}" if local else name
    return f"{target} = {FN_NAME}(function{breaks}{opening}", after


def mark_functions(source: str) -> str:
    """Return ``source`` with every function constructor wrapped in ``__fdl_fn(...)``.

    ``function (...) body end`` becomes ``__fdl_fn(function (...) body end)``,
    ``function a.b:c(x) body end`` becomes ``a.b.c = __fdl_fn(function(self, x) body end)``
    and ``local function f() body end`` becomes ``local f; f = __fdl_fn(function() body
    end)``. Blocks are matched by their keywords (``function``, ``if`` and ``do`` open one,
    ``end`` closes it); strings and comments are left untouched and line numbers kept.
    Only run on text that Lua has compiled (the sandbox compiles the original first).
    """
    tokens = _tokens(source)
    out: list[str] = []
    closers: list[str] = []  # what each open block's ``end`` becomes
    i = 0
    while i < len(tokens):
        text, kind = tokens[i]
        if kind == "kw" and text == "function":
            local = bool(out) and _last_keyword(out) == "local"
            header, i = _function_header(tokens, i, local)
            out.append(header)
            closers.append("end)")
            continue
        if kind == "kw" and text in ("if", "do"):
            closers.append("end")
        elif kind == "kw" and text == "end":
            text = closers.pop() if closers else "end"
        out.append(text)
        i += 1
    return "".join(out)


def _last_keyword(out: list[str]) -> str:
    """The last significant piece already written (``local`` before a local function)."""
    for piece in reversed(out):
        if piece.strip() and not piece.lstrip().startswith("--"):
            return piece.strip()
    return ""
