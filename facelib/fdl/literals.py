"""Lua source text for plain values, by Lua 5.4's lexical rules (reference manual 3.1).

facelib writes storyboards itself (a dataset clip's ``clip.fdl``); every string it puts in
one goes through :func:`lua_string`, so no text, however hostile, can end the literal and
become code.
"""

from __future__ import annotations

from facelib.errors import ParameterError

__all__ = ["lua_string"]

# the escapes Lua reads back as exactly these characters
_SHORT_ESCAPES = {"\\": "\\\\", '"': '\\"', "\n": "\\n", "\r": "\\r", "\t": "\\t",
                  "\a": "\\a", "\b": "\\b", "\f": "\\f", "\v": "\\v"}


def _escape(char: str) -> str:
    """``char`` as it may stand inside a double-quoted Lua string."""
    if char in _SHORT_ESCAPES:
        return _SHORT_ESCAPES[char]
    code = ord(char)
    if 0x20 <= code < 0x7F:
        return char
    if code < 0x80:
        return f"\\{code:03d}"  # always three digits: a digit after it stays a digit
    if char.isprintable() and not 0xD800 <= code <= 0xDFFF:
        return char  # written as its UTF-8 bytes, which Lua keeps as they are
    return f"\\u{{{code:X}}}"


def lua_string(text: str) -> str:
    """``text`` as a double-quoted Lua string literal that Lua reads back as the UTF-8 bytes
    of ``text``: quotes, backslashes and control characters escaped, other characters kept
    (unprintable ones and lone surrogates as ``\\u{XXXX}``)."""
    if not isinstance(text, str):
        raise ParameterError(f"a Lua string needs a str, got {type(text).__name__}")
    return '"' + "".join(_escape(c) for c in text) + '"'

