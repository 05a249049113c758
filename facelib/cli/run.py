"""``facelib run STORY.fdl``: animate a storyboard into a .fap file (or stdout)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console, UsageError
from facelib.cli.options import COMMON
from facelib.cli.outputs import STDOUT, check_suffix, default_output, emit_text
from facelib.mpeg4 import format_fap


def add(commands: Any) -> None:
    run = commands.add_parser("run", help="animate a storyboard into a .fap file",
                              parents=[COMMON])
    run.add_argument("story", help="the .fdl storyboard")
    run.add_argument("-o", "--output", help="OUT.fap, or - for stdout (default: the "
                     "storyboard's output, else STEM.fap in the current directory)")
    run.add_argument("--seed", type=int, help="seed of the random processes")
    run.add_argument("--dialect", default="standard",
                     choices=("standard", "xface", "greta", "extended"))
    run.set_defaults(run=_run)


def _run(args: argparse.Namespace, console: Console) -> int:
    from facelib.cli.options import character_file, read_source

    if args.output is not None:
        check_suffix(args.output, (".fap",), "run")
    animation = read_source(args.story, args.seed, console, scenes=True)
    out = args.output or str(default_output(args.story, animation.storyboard.output, ".fap"))
    check_suffix(out, (".fap",), "run")
    parts = getattr(animation, "parts", None)
    if parts is None:
        return _emit(animation.faps, out, args, console)
    if out == STDOUT:
        raise UsageError("the storyboard names characters: one .fap per character is written "
                         "(-o OUT.fap writes OUT.NAME.fap), not to stdout")
    for name, part in parts.items():
        _emit(part.faps, str(character_file(out, name)), args, console)
    return EXIT_OK


def _emit(stream: Any, out: str, args: argparse.Namespace, console: Console) -> int:
    name = Path(args.story).stem if out == STDOUT else Path(out).stem
    emit_text(format_fap(stream, dialect=args.dialect, name=name), out, console,
              f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    return EXIT_OK
