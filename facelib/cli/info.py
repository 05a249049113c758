"""``facelib info FILE.fap``: what a .fap file holds (rate, length, the FAPs it sets)."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON
from facelib.mpeg4 import fap, read_fap_file


def add(commands: Any) -> None:
    info = commands.add_parser("info", help="summarise a .fap file", parents=[COMMON])
    info.add_argument("file", help="the .fap file")
    info.add_argument("--strict", action="store_true", help="accept only the standard profile")
    info.set_defaults(run=_info)


def _info(args: argparse.Namespace, console: Console) -> int:
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
    return EXIT_OK

