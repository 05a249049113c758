"""``facelib check STORY.fdl``: run every generator of a storyboard (no rendering), list
its cues and say where ``facelib run`` would write."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON
from facelib.cli.outputs import default_output


def add(commands: Any) -> None:
    check = commands.add_parser(
        "check", parents=[COMMON],
        help="check a storyboard (every generator, no rendering) and list its cues")
    check.add_argument("story", help="the .fdl storyboard")
    check.add_argument("--seed", type=int)
    check.set_defaults(run=_check)


def _check(args: argparse.Namespace, console: Console) -> int:
    from facelib.animation import animate
    from facelib.clip import check_hair, storyboard_definition
    from facelib.fdl import describe, load

    storyboard = load(args.story, seed=args.seed)
    definition = storyboard_definition(storyboard)  # an unknown character, at its line
    if storyboard.hair is not None:  # render would refuse it when it loads the face
        check_hair(definition, storyboard.hair, path=args.story,
                   line=storyboard.setting_lines.get("hair"))
    animation = animate(storyboard, seed=args.seed)  # what run rejects, check rejects
    print(describe(storyboard))
    target = default_output(args.story, storyboard.output, ".fap")
    console.status(f"ok: {animation.faps.n_frames} frames at {animation.faps.fps:g} fps "
                   f"({animation.faps.duration:.2f} s); 'facelib run' without -o writes "
                   f"{target}")
    return EXIT_OK

