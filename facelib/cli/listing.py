"""``facelib list KIND``: the names a storyboard may use (expressions, voices, ...)."""

from __future__ import annotations

import argparse
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON


def add(commands: Any) -> None:
    from facelib.catalog import KINDS

    listing = commands.add_parser(
        "list", parents=[COMMON],
        help="list the names a storyboard may use: " + ", ".join(KINDS))
    listing.add_argument("kind", choices=KINDS)
    listing.add_argument("--lang", help="voices: only those of this language (e.g. de)")
    listing.set_defaults(run=_list)


def _list(args: argparse.Namespace, console: Console) -> int:
    from facelib.catalog import catalog

    entries = catalog(args.kind, lang=args.lang)
    width = max((len(e.name) for e in entries), default=0)
    for entry in entries:
        extra = f"  [{entry.image}]" if entry.image else ""
        print(f"{entry.name:<{width}}  {entry.description}{extra}")
    return EXIT_OK

