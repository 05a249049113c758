"""``facelib run STORY.fdl``: animate a storyboard into a .fap file (or stdout)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console
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
    from facelib.animation import run_fdl

    if args.output is not None:
        check_suffix(args.output, (".fap",), "run")
    animation = run_fdl(args.story, seed=args.seed,
                        progress=console.progress("animating", unit="stages", show=False))
    out = args.output or str(default_output(args.story, animation.storyboard.output, ".fap"))
    check_suffix(out, (".fap",), "run")
    stream = animation.faps
    name = Path(args.story).stem if out == STDOUT else Path(out).stem
    emit_text(format_fap(stream, dialect=args.dialect, name=name), out, console,
              f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    return EXIT_OK

