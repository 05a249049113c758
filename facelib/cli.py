"""The ``facelib`` command. Every subcommand is a thin layer over the Python API."""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Callable, Sequence

import facelib
from facelib.errors import FacelibError
from facelib.mpeg4 import fap, read_fap_file

__all__ = ["main"]


def _info(args: argparse.Namespace) -> int:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        file = read_fap_file(args.file, strict=args.strict)
    stream = file.stream
    print(f"file:      {args.file}")
    print(f"name:      {file.name}   (version {file.version}, dialect {file.dialect})")
    print(f"fps:       {stream.fps:g}")
    print(f"frames:    {stream.n_frames}")
    print(f"duration:  {stream.duration:.3f} s")
    if file.missing_frames:
        print(f"missing:   {len(file.missing_frames)} frames held from the previous frame")
    active = [f for f in stream.active_faps() if f > 2]
    print(f"active:    {len(active)} FAPs")
    if active:
        print(f"  {'id':>3}  {'name':<22} {'unit':<6} {'min':>8} {'max':>8}  frames set")
    for fid in active:
        column = stream.mask[:, fid - 1]
        values = stream.values[column, fid - 1]
        info = fap(fid)
        print(f"  {fid:>3}  {info.name:<22} {info.fapu:<6} {values.min():>8g} "
              f"{values.max():>8g}  {int(column.sum())}")
    for slot, label in ((0, "viseme"), (1, "expression")):
        if stream.mask[:, slot].any():
            print(f"  FAP {slot + 1} ({label}) set in {int(stream.mask[:, slot].sum())} frames")
    for w in caught:
        print(f"warning:   {w.message}", file=sys.stderr)
    return 0


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="facelib", description="Scriptable MPEG-4 facial animation."
    )
    parser.add_argument("--version", action="version", version=f"facelib {facelib.__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    info = commands.add_parser("info", help="summarise a .fap file")
    info.add_argument("file", help="the .fap file")
    info.add_argument("--strict", action="store_true", help="accept only the standard profile")
    info.set_defaults(run=_info)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 facelib error, 2 usage)."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    run: Callable[[argparse.Namespace], int] | None = getattr(args, "run", None)
    if run is None:
        parser.print_help()
        return 2
    try:
        return run(args)
    except FacelibError as exc:
        print(f"facelib: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
