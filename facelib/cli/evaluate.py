"""``facelib evaluate -o DIR``: deformers compared by lip roughness."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON, FACE_HELP


def add(commands: Any) -> None:
    evaluate = commands.add_parser(
        "evaluate", help="compare deformers by lip roughness (CSV, Markdown, contact sheet)",
        parents=[COMMON])
    evaluate.add_argument("-o", "--output", required=True, help="folder for the results")
    evaluate.add_argument("--deformers", help="comma-separated names (default: all seven)")
    evaluate.add_argument("--region", default="lips", help="region or group to switch")
    evaluate.add_argument("--poses", default="viseme,expression,syllable",
                          help="comma-separated pose kinds: viseme, expression, syllable")
    evaluate.add_argument("--face", help=f"{FACE_HELP} (default: the bundled head)")
    evaluate.add_argument("--stem", default="deformers", help="file name stem")
    evaluate.add_argument("--no-sheet", action="store_true", help="skip the mouth contact sheet")
    evaluate.set_defaults(run=_evaluate)


def _evaluate(args: argparse.Namespace, console: Console) -> int:
    from facelib.evaluate import DEFORMERS, evaluate_deformers, evaluation_poses, write_evaluation

    names = tuple(n.strip() for n in args.deformers.split(",")) if args.deformers else DEFORMERS
    kinds = tuple(k.strip() for k in args.poses.split(","))
    ev = evaluate_deformers(names, group=args.region, poses=evaluation_poses(kinds),
                            face_path=args.face)
    for path in write_evaluation(ev, args.output, sheet=not args.no_sheet, stem=args.stem,
                                 face_path=args.face):
        console.status(f"wrote {path}")
    return EXIT_OK

