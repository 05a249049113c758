"""``facelib view SOURCE``: play a storyboard or .fap file in a window."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON, FACE_HELP, add_hair, output_face, read_source


def add(commands: Any) -> None:
    view = commands.add_parser(
        "view", parents=[COMMON],
        help="play a .fap or storyboard in a window (space: pause, arrows: step, q: quit)")
    view.add_argument("source", help="STORY.fdl or FILE.fap")
    view.add_argument("--face", help=f"{FACE_HELP} (default: the storyboard's face, else the "
                      "bundled head)")
    add_hair(view)
    view.add_argument("--loop", action="store_true", help="replay until the window is closed")
    view.add_argument("--mute", action="store_true", help="do not play the speech audio")
    view.add_argument("--seed", type=int)
    view.set_defaults(run=_view)


def _view(args: argparse.Namespace, console: Console) -> int:
    from facelib.rendering.viewer import view

    source = read_source(args.source, args.seed, console)
    view(source, face=output_face(args, source), loop=args.loop, sound=not args.mute)
    return EXIT_OK

