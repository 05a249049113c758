"""The names a storyboard may use, with a line on each: ``facelib list KIND``.

Expressions come from the library (descriptions in ``facelib/data/catalog/expressions.csv``),
eye behaviours from ``facelib/data/gaze/behaviours.json``, visemes from the MPEG-4 table
``facelib/data/mpeg4_visemes.csv`` (every alias a script may use is listed with its viseme),
hair styles from the bundled head's hair mesh (descriptions in
``facelib/data/head/hair_styles.json``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache

from facelib import data
from facelib.errors import DataError, FacelibError

__all__ = ["KINDS", "Entry", "catalog"]

KINDS = ("expressions", "visemes", "behaviours", "voices", "languages", "hair", "characters")

EXPRESSION_GALLERY = "docs/images/expressions.png"
CHARACTER_SHEET = "docs/images/characters.png"


@dataclass(frozen=True, slots=True)
class Entry:
    """One listed name: ``name``, a one-line ``description`` and, for expressions, the
    gallery image (a path in the facelib source tree) that shows it, else ``""``."""

    name: str
    description: str
    image: str = ""
    languages: tuple[str, ...] = ()


def catalog(kind: str, *, lang: str | None = None) -> tuple[Entry, ...]:
    """The entries of ``kind``, one of :data:`KINDS`, in library order; ``lang`` keeps only
    the voices that speak a language whose code starts with it."""
    if kind not in KINDS:
        raise FacelibError(f"unknown kind {kind!r}; choose one of {', '.join(KINDS)}")
    listers: dict[str, Callable[[], tuple[Entry, ...]]] = {
        "expressions": _expressions, "visemes": _visemes, "behaviours": _behaviours,
        "voices": _voices, "languages": _languages, "hair": _hair,
        "characters": _characters}
    entries = listers[kind]()
    if lang and kind == "voices":
        wanted = lang.lower()
        entries = tuple(e for e in entries if any(
            code.startswith(wanted) for code in e.languages))
    return entries


@cache
def _expressions() -> tuple[Entry, ...]:
    from facelib.expressions import default_library

    described = {row["name"]: (line, row) for line, row in
                 data.csv_rows("catalog/expressions.csv")}
    entries = []
    for name in default_library().names:
        if name not in described:
            raise DataError(f"expression {name!r} has no description",
                            path=str(data.path("catalog/expressions.csv")))
        row = described[name][1]
        entries.append(Entry(name, f"{row['description']} ({row['source']})",
                             EXPRESSION_GALLERY))
    return tuple(entries)


@cache
def _visemes() -> tuple[Entry, ...]:
    entries = []
    for _, row in data.csv_rows("mpeg4_visemes.csv"):
        aliases = row["thesis_names"].split()
        entries.append(Entry(
            row["name"], f"viseme {row['id']}: {row['example_words']} "
            f"(script names: {', '.join(aliases)})"))
    return tuple(entries)


@cache
def _behaviours() -> tuple[Entry, ...]:
    library = data.json_data("gaze/behaviours.json")
    return tuple(Entry(name, str(spec.get("description", "")))
                 for name, spec in library.items() if not name.startswith("_"))


def _voices() -> tuple[Entry, ...]:
    from facelib.speech.espeak import list_voices

    return tuple(
        Entry(v.identifier, f"{v.name} ({', '.join(v.languages)}"
                            + (f", {v.gender})" if v.gender else ")"), languages=v.languages)
        for v in list_voices())


def _languages() -> tuple[Entry, ...]:
    from facelib.speech.synth import languages

    return tuple(Entry(lang.lang, f"{lang.name} (espeak-ng voice {lang.voice}); e.g. "
                                  f"{lang.sentence!r}") for lang in languages().values())


@cache
def _hair() -> tuple[Entry, ...]:
    from facelib.engine import hair_style_names

    styles = data.json_data("head/hair_styles.json")["styles"]
    return tuple(Entry(name, "bald: no hair" if name == "none" else str(
        styles.get(name, {}).get("description", ""))) for name in hair_style_names())


@cache
def _characters() -> tuple[Entry, ...]:
    from facelib.engine.characters import characters

    return tuple(Entry(c.name, c.description, CHARACTER_SHEET) for c in characters())
