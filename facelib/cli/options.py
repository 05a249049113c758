"""The options and inputs several commands share: ``-q``/``-v`` (:data:`COMMON`, the parent
of every parser), ``--face``, ``--hair`` and a SOURCE that is a storyboard or a ``.fap`` file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import Console, UsageError
from facelib.mpeg4 import read_fap

COMMON = argparse.ArgumentParser(add_help=False)
COMMON.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                    help="print only errors")
COMMON.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                    help="also print log messages, progress of every stage and tracebacks")


FACE_HELP = ("a bundled character (`facelib list characters`), a face definition JSON or a "
             "`facelib face setup` folder")


def face_path(face: str | None) -> Path | None:
    """``--face``: a face definition JSON, the folder ``facelib face setup`` wrote, or a
    bundled character's name (``--face ben``; `facelib list characters`), resolved by
    :func:`facelib.engine.characters.face_definition`; UsageError, with a did-you-mean, for
    an unknown name."""
    from facelib.engine.characters import face_definition
    from facelib.errors import FaceModelError

    try:
        return face_definition(face)
    except FaceModelError as exc:
        raise UsageError(f"--face: {exc.message}") from None


def add_hair(command: argparse.ArgumentParser) -> None:
    """``--hair STYLE``: the hair style the face wears."""
    command.add_argument("--hair", metavar="STYLE",
                         help="the hair style the face wears (the bundled head's: short, long, "
                              "tied; none: bald; default: the storyboard's, else the face's "
                              "own; `facelib list hair`)")


def output_face(args: argparse.Namespace, source: Any) -> Any:
    """What ``--face`` and ``--hair`` give an output of ``source``: the ``--face`` path or
    None, or with ``--hair`` that face (else the storyboard's, else the bundled head) loaded
    wearing the style; UsageError, with a did-you-mean, for a style the face lacks."""
    from facelib.clip import face_for
    from facelib.errors import ParameterError

    try:
        return face_for(source, face_path(args.face), args.hair)
    except ParameterError as exc:
        raise UsageError(f"--hair: {exc.message}") from None


def chosen_face(face: str | None) -> Any:
    """The Face ``--face`` names, else the default head."""
    from facelib.engine import default_face, load_face

    path = face_path(face)
    return default_face() if path is None else load_face(path)


def read_source(path: str, seed: int | None, console: Console, *, scenes: bool = False) -> Any:
    """A storyboard's Animation, or a .fap file's stream; with ``scenes``, a storyboard with
    characters gives its Scene (else UsageError: the command plays one face)."""
    if Path(path).suffix.lower() == ".fap":
        return read_fap(path)
    from facelib.animation import animate, animate_scene
    from facelib.fdl import load

    storyboard = load(Path(path), seed=seed)
    progress = console.progress("animating", unit="stages", show=console.verbose)
    if storyboard.characters:
        if not scenes:
            names = ", ".join(c.name for c in storyboard.characters)
            raise UsageError(f"{path} names characters ({names}); `facelib render` and "
                             "`facelib run` play storyboards with characters, this command "
                             "plays one face")
        return animate_scene(storyboard, seed=seed, progress=progress)
    return animate(storyboard, seed=seed, progress=progress)


def character_file(path: str | Path, name: str) -> Path:
    """The file of character ``name`` for an output ``path`` of a storyboard with
    characters: ``out/dialogue.fap`` -> ``out/dialogue.ada.fap``."""
    path = Path(path)
    return path.with_name(f"{path.stem}.{name}{path.suffix}")
