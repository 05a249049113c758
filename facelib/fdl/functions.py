"""Every name a storyboard may set or call, declared once.

:data:`FUNCTIONS` is the registry of the modern syntax's storyboard functions: the sandbox
exposes exactly these (and suggests them for a misspelt call), :func:`read_calls`
dispatches each recorded call to its reader, the readers check named fields against
:attr:`StoryboardFunction.fields`, and the loader's known-globals check counts them.
:data:`SETTINGS` and :data:`THESIS_GLOBALS` are the globals a storyboard may assign.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

from facelib.errors import FdlError
from facelib.fdl import camera, cast, modern, moods
from facelib.fdl.context import Context
from facelib.fdl.thesis import SCRIPT_GLOBALS

__all__ = [
    "FUNCTIONS",
    "SETTINGS",
    "THESIS_GLOBALS",
    "StoryboardFunction",
    "function_names",
    "known_globals",
    "read_calls",
]

Reader = Callable[[object, "StoryboardFunction", Context, int | None, modern.ModernParts], None]
"""``reader(argument, function, ctx, line, parts)``: validate one call into ``parts``."""


@dataclass(frozen=True, slots=True)
class StoryboardFunction:
    """One storyboard function of the modern syntax.

    name: what the script calls (``show``).
    fields: the named fields its table takes, or None where the names are open (FAP names
        for ``define_expression``, behaviour parameters for ``define_gaze``).
    usage: one example call, shown in errors and ``docs/fdl.md``.
    read: the reader that validates a call (see :data:`Reader`).
    takes_string: the single argument may also be a plain string (``say "Hello"``).
    """

    name: str
    fields: tuple[str, ...] | None
    usage: str
    read: Reader
    takes_string: bool = False


FUNCTIONS: Mapping[str, StoryboardFunction] = MappingProxyType({
    f.name: f
    for f in (
        StoryboardFunction(
            "say", ("text", "transcript", "audio", "visemes", "at", "lang", "voice", "rate",
                    "pitch", "style", "who"),
            'say { "Hello.", audio = "hello.wav", at = 0.5 }', modern.read_say,
            takes_string=True,
        ),
        StoryboardFunction(
            "show", ("at", "dur", "intensity", "ease_in", "ease_out", "who"),
            'show { "joy", dur = 2, intensity = 0.8 }', modern.read_show,
        ),
        StoryboardFunction(
            "look", ("at", "dur", "who"), 'look { "lookTo", "left", 17, "yes", dur = 2 }',
            modern.read_look,
        ),
        StoryboardFunction(
            "camera", ("framing", "at", "dur", "who"),
            'camera { framing = "head", at = 2, dur = 0.5 }', camera.read_camera,
        ),
        StoryboardFunction(
            "mood", ("at", "intensity", "ease", "who"),
            'mood { "happy", at = 2, intensity = 0.6 }', moods.read_mood,
        ),
        StoryboardFunction(
            "characters", None,
            'characters { ada = { hair = "long" }, ben = { face = "ben.json", hair = "short" } }',
            cast.read_characters,
        ),
        StoryboardFunction(
            "define_expression", None, 'define_expression { "smirk", raise_l_cornerlip = 120 }',
            modern.read_define_expression,
        ),
        StoryboardFunction(
            "define_gaze", None, 'define_gaze { "shy", base = "default", p_mutual = 0.2 }',
            modern.read_define_gaze,
        ),
    )
})  # fmt: skip
"""The storyboard functions by name, in the order ``docs/fdl.md`` presents them."""

SETTINGS: Mapping[str, str] = MappingProxyType({
    "fps": "frames per second of the animation (default 25)",
    "seed": "seed of every random process (default 0)",
    "output": 'the .fap file to write, relative to the storyboard, or "none"',
    "face": "a bundled character's name (`facelib list characters`) or the face "
            "definition JSON to play on, relative to the storyboard "
            "(e.g. made by facelib face setup; default: the bundled head)",
    "hair": 'the hair style the face wears ("short", "long", "tied", "none": bald; '
            "default: the face definition's)",
    "language": 'language of speech that names none ("pt", "de", ...; default English)',
})  # fmt: skip
"""Globals that set storyboard options, with what each means."""

THESIS_GLOBALS: tuple[str, ...] = ("FDL", *SCRIPT_GLOBALS.values())
"""Globals of the thesis's format: the ``FDL`` table and the lists it may name."""


def function_names() -> tuple[str, ...]:
    """Names of the storyboard functions (what the sandbox exposes)."""
    return tuple(FUNCTIONS)


def known_globals() -> tuple[str, ...]:
    """Every global a storyboard may set or call besides the sandbox's whitelist."""
    return (*FUNCTIONS, *SETTINGS, *THESIS_GLOBALS)


def read_calls(
    calls: Sequence[tuple[str, object, int | None, int]], ctx: Context
) -> modern.ModernParts:
    """Validate recorded calls ``(function, argument, line, n_arguments)`` into parts."""
    parts = modern.ModernParts()
    for name, arg, line, n_args in calls:
        if n_args != 1:
            raise FdlError(
                f"{name} takes one table, like {name} {{ ... }}; got {n_args} arguments",
                path=ctx.path,
                line=line,
            )
        function = FUNCTIONS[name]
        function.read(arg, function, ctx, line, parts)
    return parts
