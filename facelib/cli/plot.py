"""``facelib plot SOURCE -o curves.png``: the FAP curves of a storyboard or .fap file."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON, read_source
from facelib.cli.outputs import check_suffix


def add(commands: Any) -> None:
    plot = commands.add_parser("plot", help="plot FAP curves of a storyboard or .fap",
                               parents=[COMMON])
    plot.add_argument("source", help="STORY.fdl or FILE.fap")
    plot.add_argument("-o", "--output", required=True, help="curves.png (or .svg, .pdf)")
    plot.add_argument("--seed", type=int)
    plot.set_defaults(run=_plot)


def _plot(args: argparse.Namespace, console: Console) -> int:
    from facelib.plot import plot_curves

    check_suffix(args.output, (".png", ".svg", ".pdf"), "plot")
    out = plot_curves(read_source(args.source, args.seed, console), args.output,
                      title=args.source)
    console.status(f"wrote {out}")
    return EXIT_OK

