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
    from facelib.animation import animate, animate_scene
    from facelib.clip import check_hair, storyboard_definition
    from facelib.fdl import describe, load

    storyboard = load(args.story, seed=args.seed)
    parts = [c.part for c in storyboard.characters] or [storyboard]
    for part in parts:
        definition = storyboard_definition(part)  # an unknown character, at its line
        if part.hair is not None:  # render would refuse it when it loads the face
            check_hair(definition, part.hair, path=args.story,
                       line=part.setting_lines.get("hair"))
    # what run rejects, check rejects
    if storyboard.characters:
        faps = next(iter(animate_scene(storyboard, seed=args.seed).parts.values())).faps
    else:
        faps = animate(storyboard, seed=args.seed).faps
    print(describe(storyboard))
    target = str(default_output(args.story, storyboard.output, ".fap"))
    if storyboard.characters:
        names = ", ".join(c.name for c in storyboard.characters)
        target += f" as one file per character ({names})"
    console.status(f"ok: {faps.n_frames} frames at {faps.fps:g} fps "
                   f"({faps.duration:.2f} s); 'facelib run' without -o writes "
                   f"{target}")
    return EXIT_OK
