"""The readers of the modern FDL syntax's storyboard functions (see ``docs/fdl.md``).

``say``, ``show``, ``look``, ``define_expression`` and ``define_gaze`` each take one table
(``say`` also a plain string); they are declared in :mod:`facelib.fdl.functions`, which
dispatches each call the sandbox recorded to its reader here. A reader validates the call
into draft cues; :mod:`facelib.fdl.modern_cues` times the drafts into cues. Times are
seconds or unit strings (see :mod:`facelib.fdl.timing`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from facelib import data
from facelib.checks import did_you_mean
from facelib.errors import FdlError
from facelib.fdl.context import Context
from facelib.fdl.timing import parse_time
from facelib.fdl.values import LuaTable, LuaValue, lua_kind
from facelib.mpeg4.tables import fap_table

if TYPE_CHECKING:
    from facelib.fdl.functions import StoryboardFunction

__all__ = [
    "DraftCharacter",
    "DraftCue",
    "DraftSpeech",
    "ModernParts",
    "read_define_expression",
    "read_define_gaze",
    "read_look",
    "read_say",
    "read_show",
    "table_of",
    "who_of",
]

_SAY_RANGES = {"rate": (0.5, 2.5), "pitch": (0.0, 100.0)}
_MAX_FAP_VALUE = 100_000.0


@dataclass(frozen=True, slots=True)
class DraftCue:
    """An expression or gaze cue whose start may still be open (``at_ms`` None)."""

    name: str
    args: tuple[str | float, ...]
    at_ms: int | None
    duration_ms: int
    line: int | None
    intensity: float = 1.0
    ramp_in_ms: int | None = None
    ramp_out_ms: int | None = None
    who: str | None = None


@dataclass(frozen=True, slots=True)
class DraftSpeech:
    """A ``say`` call: files still unresolved; visemes as (name, duration_ms, line)."""

    line: int | None
    at_ms: int
    text: str | None = None
    transcript: str | None = None
    audio: str | None = None
    visemes: tuple[tuple[str, int, int | None], ...] | None = None
    lang: str | None = None
    voice: str | None = None
    rate: float = 1.0
    pitch: float = 50.0
    style: str | float = "normal"
    who: str | None = None


@dataclass(frozen=True, slots=True)
class DraftCharacter:
    """One entry of ``characters { name = { face = ..., hair = ... } }``: the face still
    unresolved (None: the bundled head)."""

    name: str
    line: int | None
    face: str | None = None
    hair: str | None = None


@dataclass(slots=True)
class ModernParts:
    """Everything the storyboard-function calls asked for, in call order.

    ``speech`` is the one ``say`` of a storyboard of one face; ``speeches`` holds the
    ``say`` calls of each character (``who =``) of a storyboard that names ``characters``;
    ``turns`` the ``say`` calls after the first of one character's part."""

    speech: DraftSpeech | None = None
    speeches: dict[str, list[DraftSpeech]] = field(default_factory=dict)
    turns: list[DraftSpeech] = field(default_factory=list)
    characters: list[DraftCharacter] = field(default_factory=list)
    expressions: list[DraftCue] = field(default_factory=list)
    gaze: list[DraftCue] = field(default_factory=list)
    expression_defs: dict[str, Mapping[str, float]] = field(default_factory=dict)
    expression_mixes: dict[str, Mapping[str, float]] = field(default_factory=dict)
    gaze_defs: dict[str, Mapping[str, Any]] = field(default_factory=dict)
    camera: list[DraftCue] = field(default_factory=list)
    moods: list[DraftCue] = field(default_factory=list)


def table_of(
    arg: object, fn: str, ctx: Context, line: int | None, *, allowed: tuple[str, ...] | None
) -> LuaTable:
    """``arg``, the one table argument of a storyboard function, as a table; FdlError if it
    is not one or has a field outside ``allowed`` (None: any field)."""
    if not isinstance(arg, LuaTable):
        raise FdlError(
            f'{fn} takes a table, like {fn} {{ "name", ... }}; got a {lua_kind(arg)} {arg!r}',
            path=ctx.path,
            line=line,
        )
    for key in arg.fields:
        if allowed is not None and key not in allowed:
            raise FdlError(
                f"{fn}: unknown field {key!r}{did_you_mean(key, allowed)}"
                f" (fields: {', '.join(allowed)})",
                path=ctx.path,
                line=line,
            )
    return arg


def _name(
    arg: LuaTable, fn: str, ctx: Context, line: int | None, *, named: str | None = None
) -> str:
    """The name that opens ``fn { "name", ... }``. With ``named`` (what the rest must be,
    e.g. "times and intensity (at = ..., dur = ...)"), nothing but named fields may follow."""
    if not arg.items or not isinstance(arg.items[0], str) or not arg.items[0].strip():
        raise FdlError(
            f'{fn} needs a name first, like {fn} {{ "joy", ... }}', path=ctx.path, line=line
        )
    name = arg.items[0]
    if named is not None and len(arg.items) > 1:
        raise FdlError(
            f"{fn} {{ {name!r}, ... }}: unexpected value {arg.items[1]!r} after the name; "
            f"give {named} as named fields",
            path=ctx.path,
            line=line,
        )
    return name


def who_of(t: LuaTable, fn: str, ctx: Context, line: int | None) -> str | None:
    """The ``who = "name"`` field of a call (None when absent); FdlError if it is not a
    name. Whether the storyboard names that character is checked once all calls are read
    (:func:`facelib.fdl.cast.check_who`)."""
    who = t.fields.get("who")
    if who is not None and not (isinstance(who, str) and who.strip()):
        raise FdlError(f'{fn}: who must be a character name like who = "ada"; got {who!r}',
                       path=ctx.path, line=line)
    return None if who is None else who.strip()


def _time(value: object, what: str, ctx: Context, line: int | None) -> int:
    return parse_time(value, fps=ctx.fps, what=what, path=ctx.path, line=line)


def _opt_time(
    fields: dict[str, Any], key: str, fn: str, ctx: Context, line: int | None
) -> int | None:
    return None if key not in fields else _time(fields[key], f"{fn}: {key}", ctx, line)


@cache
def _library_names(kind: str) -> tuple[str, ...]:
    """Names of the built-in expressions or eye behaviours, read from the package data
    (this layer cannot import the libraries), for hints in errors found before them."""
    if kind == "expressions":
        return tuple(row["name"] for _, row in data.csv_rows("catalog/expressions.csv"))
    return tuple(data.json_data("gaze/behaviours.json"))


def _unknown(name: str, known: Sequence[str], what: str) -> str:
    """`` (and 'x' is not a known expression; did you mean 'y'?)`` when ``name`` is not in
    ``known`` and one is close; else ``""``."""
    hint = "" if name in known else did_you_mean(name, known)
    return f" (and {name!r} is not a known {what}{hint})" if hint else ""


def read_show(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``show { "name", dur = ..., at, intensity, ease_in, ease_out }``: an expression."""
    t = table_of(arg, "show", ctx, line, allowed=fn.fields)
    name = _name(t, "show", ctx, line, named="times and intensity (at = ..., dur = ...)")
    if "dur" not in t.fields:
        known = (*_library_names("expressions"), *parts.expression_defs)
        raise FdlError(f"show {{ {name!r} }} needs dur = ...{_unknown(name, known, 'expression')}",
                       path=ctx.path, line=line)
    duration = _time(t.fields["dur"], "show: dur", ctx, line)
    intensity = t.fields.get("intensity", 1.0)
    if (
        isinstance(intensity, bool)
        or not isinstance(intensity, int | float)
        or not (0.0 <= intensity <= 1.0)
    ):
        raise FdlError(
            f"show: intensity must be a number from 0 to 1; got {intensity!r}",
            path=ctx.path,
            line=line,
        )
    ease_in = _opt_time(t.fields, "ease_in", "show", ctx, line)
    ease_out = _opt_time(t.fields, "ease_out", "show", ctx, line)
    if (ease_in or 0) + (ease_out or 0) > duration:
        raise FdlError(
            f"show {{ {name!r} }}: ease_in + ease_out ({(ease_in or 0) + (ease_out or 0)} ms) "
            f"is longer than dur ({duration} ms)",
            path=ctx.path,
            line=line,
        )
    parts.expressions.append(
        DraftCue(
            name=name,
            args=(),
            at_ms=_opt_time(t.fields, "at", "show", ctx, line),
            duration_ms=duration,
            line=line,
            intensity=float(intensity),
            ramp_in_ms=ease_in,
            ramp_out_ms=ease_out,
            who=who_of(t, "show", ctx, line),
        )
    )


def read_look(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``look { "behaviour", args..., dur = ..., at }``: an eye behaviour."""
    t = table_of(arg, "look", ctx, line, allowed=fn.fields)
    name = _name(t, "look", ctx, line)
    if "dur" not in t.fields:
        known = (*_library_names("behaviours"), *parts.gaze_defs)
        raise FdlError(f"look {{ {name!r} }} needs dur = ..."
                       f"{_unknown(name, known, 'eye behaviour')}", path=ctx.path, line=line)
    args: list[str | float] = []
    for value in t.items[1:]:
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise FdlError(
                f"look {{ {name!r} }}: value {value!r} must be a string or a number",
                path=ctx.path,
                line=line,
            )
        args.append(value if isinstance(value, str) else float(value))
    parts.gaze.append(
        DraftCue(
            name=name,
            args=tuple(args),
            at_ms=_opt_time(t.fields, "at", "look", ctx, line),
            duration_ms=_time(t.fields["dur"], "look: dur", ctx, line),
            line=line,
            who=who_of(t, "look", ctx, line),
        )
    )


def read_say(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``say "text"`` or ``say { "text" or transcript/audio/visemes, at, who }``: the
    speech (of character ``who`` in a storyboard with characters)."""
    who = who_of(arg, "say", ctx, line) if isinstance(arg, LuaTable) else None
    _check_first_say(parts, ctx, line)
    if isinstance(arg, str):
        parts.speech = DraftSpeech(line=line, at_ms=0, text=arg)
        return
    t = table_of(arg, "say", ctx, line, allowed=fn.fields)
    f = t.fields
    first = t.items[0] if t.items else None
    if len(t.items) > 1 or (t.items and not isinstance(first, str)):
        raise FdlError(
            "say takes the spoken text first, then named fields (audio = ..., at = ...)",
            path=ctx.path,
            line=line,
        )
    strings = {key: _string(f, key, "say", ctx, line)
               for key in ("text", "transcript", "audio", "lang", "voice")}
    text = first if isinstance(first, str) else strings["text"]
    if t.items and "text" in f:
        raise FdlError(
            "say: the text is given twice (first value and text =)", path=ctx.path, line=line
        )
    if text is not None and "transcript" in f:
        raise FdlError(
            "say: give either the text or a transcript file, not both", path=ctx.path, line=line
        )
    numbers = {key: _ranged(f, key, low, high, ctx=ctx, line=line)
               for key, (low, high) in _SAY_RANGES.items()}
    visemes = None if "visemes" not in f else _visemes(f["visemes"], ctx, line)
    if text is None and "transcript" not in f and "audio" not in f and visemes is None:
        raise FdlError("say needs text, a transcript, audio or visemes", path=ctx.path, line=line)
    said = DraftSpeech(
        line=line,
        who=who,
        at_ms=_opt_time(f, "at", "say", ctx, line) or 0,
        text=text,
        transcript=strings["transcript"],
        audio=strings["audio"],
        visemes=visemes,
        lang=strings["lang"],
        voice=strings["voice"],
        rate=numbers["rate"] if numbers["rate"] is not None else 1.0,
        pitch=numbers["pitch"] if numbers["pitch"] is not None else 50.0,
        style=_style(f, ctx, line),
    )
    if who is None:
        parts.speech = said
    else:
        parts.speeches.setdefault(who, []).append(said)


def _check_first_say(parts: ModernParts, ctx: Context, line: int | None) -> None:
    """FdlError when the storyboard already has its one ``say`` (a character of a
    storyboard with characters, ``who = ...``, may speak several times)."""
    if parts.speech is not None:
        raise FdlError(
            f"say is called a second time (the first call is on line {parts.speech.line}); "
            "a storyboard has one speech (characters, say { who = ... }, may have several)",
            path=ctx.path,
            line=line,
        )


def _style(fields: Mapping[str, LuaValue], ctx: Context, line: int | None) -> str | float:
    """``say``'s ``style``: a style name or a number ("normal" when absent); the speech
    generator checks the name and range against its table."""
    value = fields.get("style", "normal")
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise FdlError(f"say: style must be a name (mumble, normal, emphatic) or a number; "
                       f"got {value!r}", path=ctx.path, line=line)
    return value if isinstance(value, str) else float(value)


def _ranged(
    fields: Mapping[str, LuaValue], key: str, low: float, high: float, *, ctx: Context,
    line: int | None,
) -> float | None:
    """Field ``key`` as a number in ``[low, high]`` (None when absent); FdlError otherwise."""
    value = fields.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not low <= value <= high:
        raise FdlError(f"say: {key} must be a number from {low:g} to {high:g}; got {value!r}",
                       path=ctx.path, line=line)
    return float(value)


def _string(
    fields: Mapping[str, LuaValue], key: str, fn: str, ctx: Context, line: int | None
) -> str | None:
    """Field ``key`` as a string (None when absent); FdlError if it is something else."""
    value = fields.get(key)
    if value is not None and not isinstance(value, str):
        raise FdlError(f"{fn}: {key} must be a string; got {value!r}", path=ctx.path, line=line)
    return value


def _visemes(
    value: object, ctx: Context, line: int | None
) -> tuple[tuple[str, int, int | None], ...]:
    if not isinstance(value, LuaTable) or value.fields:
        raise FdlError(
            'say: visemes must be a list like { {"sil", 0.2}, {"aa", "120ms"} }',
            path=ctx.path,
            line=line,
        )
    out = []
    for index, entry in enumerate(value.items, start=1):
        where = entry.line if isinstance(entry, LuaTable) and entry.line else line
        if (
            not isinstance(entry, LuaTable)
            or entry.fields
            or len(entry.items) != 2
            or not isinstance(entry.items[0], str | int)
            or isinstance(entry.items[0], bool)
        ):
            raise FdlError(
                f"say: visemes[{index}] must be {{viseme, duration}}; got {entry!r}",
                path=ctx.path,
                line=where,
            )
        name, duration = entry.items
        out.append((str(name), _time(duration, f"visemes[{index}] duration", ctx, where), where))
    return tuple(out)


def read_define_expression(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``define_expression { "name", FAP = value..., mix = {...} }``."""
    t = table_of(arg, "define_expression", ctx, line, allowed=fn.fields)
    name = _name(t, "define_expression", ctx, line,
                 named="FAP values (raise_l_cornerlip_o = 120)")
    valid = {f.name: f for f in fap_table() if f.kind != "special"}
    values: dict[str, float] = {}
    mix: dict[str, float] = {}
    for key, value in t.fields.items():
        if key == "mix":
            mix = _mix(value, name, ctx, line)
            continue
        if key not in valid:
            raise FdlError(
                f"define_expression {{ {name!r} }}: {key!r} is not a FAP name"
                f"{did_you_mean(key, [*valid, 'mix'])}",
                path=ctx.path,
                line=ctx.line_of(key, after=line) or line,
            )
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not (math.isfinite(value) and abs(value) <= _MAX_FAP_VALUE)
        ):
            raise FdlError(
                f"define_expression {{ {name!r} }}: {key} must be a FAP value (a number); "
                f"got {value!r}",
                path=ctx.path,
                line=line,
            )
        values[key] = float(value)
    local = {
        k: v
        for k, v in mix.items()
        if k in parts.expression_defs and k not in parts.expression_mixes
    }
    if mix and len(local) == len(mix):
        combined: dict[str, float] = {}
        for component, weight in mix.items():
            for fap_name, v in parts.expression_defs[component].items():
                combined[fap_name] = combined.get(fap_name, 0.0) + weight * v
        values = {**combined, **values}
        mix = {}
    parts.expression_defs[name] = MappingProxyType(values)
    if mix:
        parts.expression_mixes[name] = MappingProxyType(mix)
    else:
        parts.expression_mixes.pop(name, None)


def _mix(value: object, name: str, ctx: Context, line: int | None) -> dict[str, float]:
    if not isinstance(value, LuaTable) or value.items or not value.fields:
        raise FdlError(
            f"define_expression {{ {name!r} }}: mix must map expression names to weights, "
            "like mix = { joy = 0.5, sadness = 0.5 }",
            path=ctx.path,
            line=line,
        )
    out = {}
    for component, weight in value.fields.items():
        if (
            isinstance(weight, bool)
            or not isinstance(weight, int | float)
            or not (math.isfinite(weight) and abs(weight) <= 10.0)
        ):
            raise FdlError(
                f"define_expression {{ {name!r} }}: mix weight of {component!r} must be a "
                f"number from -10 to 10; got {weight!r}",
                path=ctx.path,
                line=line,
            )
        if component == name:
            raise FdlError(
                f"define_expression {{ {name!r} }}: an expression cannot mix itself",
                path=ctx.path,
                line=line,
            )
        out[component] = float(weight)
    return out


def read_define_gaze(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``define_gaze { "name", parameter = value... }``: an eye behaviour."""
    t = table_of(arg, "define_gaze", ctx, line, allowed=fn.fields)
    name = _name(t, "define_gaze", ctx, line, named="parameters (rate = 2.0)")
    params: dict[str, Any] = {}
    for key, value in t.fields.items():
        if isinstance(value, str | bool | int | float):
            params[key] = value if isinstance(value, str | bool) else float(value)
        elif isinstance(value, LuaTable) and not value.fields and len(
            numbers := [v for v in value.items
                        if isinstance(v, int | float) and not isinstance(v, bool)]
        ) == len(value.items):
            params[key] = tuple(float(v) for v in numbers)
        else:
            raise FdlError(
                f"define_gaze {{ {name!r} }}: parameter {key} must be a string, number, "
                f"boolean or list of numbers; got a {lua_kind(value)}",
                path=ctx.path,
                line=ctx.line_of(key, after=line) or line,
            )
    parts.gaze_defs[name] = MappingProxyType(params)
