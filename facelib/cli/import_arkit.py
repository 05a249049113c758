"""``facelib import-arkit CAPTURE.csv -o OUT.fap``: an ARKit capture turned into FAPs."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON
from facelib.cli.outputs import check_suffix, emit_text
from facelib.mpeg4 import format_fap


def add(commands: Any) -> None:
    imp = commands.add_parser(
        "import-arkit", parents=[COMMON],
        help="turn an ARKit capture (Live Link Face CSV) into a .fap")
    imp.add_argument("capture", help="the Live Link Face .csv (or facelib's ARKit .json)")
    imp.add_argument("-o", "--output", required=True, help="OUT.fap, or - for stdout")
    imp.add_argument("--fps", type=float,
                     help="frame base of the timecodes (default: read; the app counts at 60)")
    imp.add_argument("--resample", type=float, help="resample to this frame rate (e.g. 25)")
    imp.add_argument("--dialect", default="standard",
                     choices=("standard", "xface", "greta", "extended"))
    imp.set_defaults(run=_import_arkit)


def _import_arkit(args: argparse.Namespace, console: Console) -> int:
    from facelib.export import import_arkit

    check_suffix(args.output, (".fap",), "import-arkit")
    stream = import_arkit(args.capture, fps=args.fps)
    if args.resample is not None:
        stream = stream.resample(args.resample)
    emit_text(format_fap(stream, dialect=args.dialect, name=Path(args.capture).stem),
              args.output, console, f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    return EXIT_OK

