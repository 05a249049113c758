"""Storyboards with several characters: ``characters { ... }`` and cues addressed ``who =``.

::

    characters {
      ada = { hair = "long" },                         -- the bundled head
      ben = { face = "ben/face.json", hair = "short" },
    }
    say  { who = "ada", "Hello, Ben.", at = 0.2 }
    show { who = "ben", "joy", at = 1, dur = 2 }
    camera { who = "ben", at = 2 }                     -- cut to Ben
    camera { "two_shot", at = 4 }                      -- both, side by side

A character's ``face`` is a face definition relative to the storyboard, or ``"default"``
(or none) for the bundled head; ``hair`` is a style of that face. The characters stand left
to right in the order the storyboard names them. Each one's ``say``, ``show``, ``look`` and
``mood`` calls make its own one-character storyboard (:attr:`facelib.cues.Character.part`),
read by the same rules as a storyboard of one face; the camera cuts between them.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

from facelib.checks import did_you_mean
from facelib.cues import TWO_SHOT, CameraCue
from facelib.errors import FdlError
from facelib.fdl.context import Context
from facelib.fdl.modern import DraftCharacter, DraftCue, ModernParts, table_of
from facelib.fdl.values import LuaTable, lua_kind

if TYPE_CHECKING:
    from facelib.fdl.functions import StoryboardFunction

__all__ = ["CHARACTER_FIELDS", "DEFAULT_FACE", "check_who", "part_of", "read_characters",
           "scene_camera", "single_camera"]

CHARACTER_FIELDS = ("face", "hair")
"""What a character's table may set."""
DEFAULT_FACE = "default"
"""``face = "default"``: the bundled head."""


def read_characters(
    arg: object, fn: StoryboardFunction, ctx: Context, line: int | None, parts: ModernParts
) -> None:
    """``characters { name = { face = ..., hair = ... }, ... }``: the storyboard's cast,
    left to right in the order of their lines."""
    if parts.characters:
        raise FdlError(f"characters is called a second time (the first call is on line "
                       f"{parts.characters[0].line}); name every character in one call",
                       path=ctx.path, line=line)
    t = table_of(arg, "characters", ctx, line, allowed=None)
    if t.items or not t.fields:
        raise FdlError('characters names each character with its face and hair, like '
                       'characters { ada = { hair = "long" }, ben = { hair = "short" } }',
                       path=ctx.path, line=line)
    found = []
    for name, spec in t.fields.items():
        where = ctx.line_of(name, after=line) or line
        if not isinstance(spec, LuaTable) or spec.items:
            raise FdlError(f"characters: {name} must be a table like {name} = {{ face = "
                           f'"default", hair = "long" }}; got a {lua_kind(spec)}',
                           path=ctx.path, line=where)
        for key in spec.fields:
            if key not in CHARACTER_FIELDS:
                raise FdlError(f"characters: {name}: unknown field {key!r}"
                               f"{did_you_mean(key, CHARACTER_FIELDS)} (fields: "
                               f"{', '.join(CHARACTER_FIELDS)})", path=ctx.path, line=where)
        values = {key: spec.fields.get(key) for key in CHARACTER_FIELDS}
        for key, value in values.items():
            if value is not None and not (isinstance(value, str) and value.strip()):
                raise FdlError(f"characters: {name}: {key} must be a name; got {value!r}",
                               path=ctx.path, line=where)
        face, hair = (None if v is None else str(v).strip() for v in values.values())
        found.append(DraftCharacter(name=name, line=where,
                                    face=None if face == DEFAULT_FACE else face, hair=hair))
    parts.characters.extend(sorted(found, key=lambda c: (c.line or 0, c.name)))


def _drafts(parts: ModernParts) -> Iterable[tuple[str, DraftCue]]:
    for kind, drafts in (("show", parts.expressions), ("look", parts.gaze),
                         ("camera", parts.camera), ("mood", parts.moods)):
        for d in drafts:
            yield kind, d


def check_who(parts: ModernParts, ctx: Context) -> None:
    """Every ``who`` names a character of ``characters``, and with characters every
    ``say``, ``show``, ``look`` and ``mood`` names one: FdlError at the call's line, with a
    did-you-mean, otherwise."""
    names = [c.name for c in parts.characters]
    calls: list[tuple[str, str | None, int | None]] = [
        (kind, d.who, d.line) for kind, d in _drafts(parts)]
    calls += [("say", s.who, s.line) for turns in parts.speeches.values() for s in turns]
    if parts.speech is not None:
        calls.append(("say", None, parts.speech.line))
    for kind, who, line in sorted(calls, key=lambda c: c[2] or 0):
        if who is None:
            if names and kind != "camera":
                raise FdlError(f"{kind}: this storyboard names characters "
                               f"({', '.join(names)}); say whose it is with who = "
                               f'"{names[0]}"', path=ctx.path, line=line)
            continue
        if not names:
            raise FdlError(f"{kind}: who = {who!r}, but the storyboard names no characters; "
                           f'name them first: characters {{ {who} = {{ hair = "long" }} }}',
                           path=ctx.path, line=line)
        if who not in names:
            raise FdlError(f"{kind}: who = {who!r} is not one of the characters "
                           f"({', '.join(names)}){did_you_mean(who, names, cutoff=0.6)}",
                           path=ctx.path, line=line)


def part_of(parts: ModernParts, name: str, ctx: Context) -> ModernParts:
    """The calls of character ``name``: its speech (its first ``say``, then its turns, by
    start; FdlError for two starting together), expressions, eye behaviours and moods, and
    the definitions every character shares (no camera, no characters)."""
    def own(drafts: Sequence[DraftCue]) -> list[DraftCue]:
        return [replace(d, who=None) for d in drafts if d.who == name]

    said = sorted(parts.speeches.get(name, ()), key=lambda s: s.at_ms)
    for before, after in itertools.pairwise(said):
        if after.at_ms == before.at_ms:
            raise FdlError(f"say: {name}'s turns on lines {before.line} and {after.line} both "
                           f"start at {after.at_ms} ms; give each turn its own at = ...",
                           path=ctx.path, line=after.line)
    return ModernParts(
        speech=replace(said[0], who=None) if said else None,
        turns=[replace(s, who=None) for s in said[1:]],
        expressions=own(parts.expressions), gaze=own(parts.gaze), moods=own(parts.moods),
        expression_defs=parts.expression_defs, expression_mixes=parts.expression_mixes,
        gaze_defs=parts.gaze_defs)


def scene_camera(cues: Sequence[CameraCue], ctx: Context) -> tuple[CameraCue, ...]:
    """The camera cues of a storyboard with characters: each a cut (no ``dur``) to one
    character (``who``, any framing but the two-shot) or to the two-shot; FdlError at the
    cue's line otherwise."""
    for cue in cues:
        line = cue.origin[1] if cue.origin else None
        if cue.duration_ms:
            raise FdlError("camera: with characters the camera cuts between shots; leave out "
                           "dur", path=ctx.path, line=line)
        if cue.who is None and cue.framing != TWO_SHOT:
            raise FdlError(f"camera: with characters a cue names who = ... (a close shot) "
                           f'or the "{TWO_SHOT}" framing; got framing {cue.framing!r}',
                           path=ctx.path, line=line)
        if cue.who is not None and cue.framing == TWO_SHOT:
            raise FdlError(f'camera: "{TWO_SHOT}" shows every character; leave out who = '
                           f"{cue.who!r}", path=ctx.path, line=line)
    return tuple(cues)


def single_camera(cues: Sequence[CameraCue], ctx: Context) -> tuple[CameraCue, ...]:
    """The camera cues of a storyboard of one face: no two-shot (who was checked)."""
    for cue in cues:
        if cue.framing == TWO_SHOT:
            raise FdlError(f'camera: "{TWO_SHOT}" needs characters {{ ... }} to show',
                           path=ctx.path, line=cue.origin[1] if cue.origin else None)
    return tuple(cues)
