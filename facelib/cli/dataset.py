"""``facelib dataset SPEC.toml -o DIR``: a synthetic face dataset, locally or on Dask."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from facelib.cli.console import EXIT_ERROR, EXIT_OK, Console
from facelib.cli.options import COMMON


def add(commands: Any) -> None:
    dataset = commands.add_parser(
        "dataset", parents=[COMMON],
        help="generate a synthetic face dataset from a SPEC.toml, locally or on Dask")
    dataset.add_argument("spec", help="the dataset spec (TOML, see docs/batch.md)")
    dataset.add_argument("-o", "--output", required=True, help="the dataset folder")
    dataset.add_argument("-j", "--jobs", type=int,
                         help="local processes (default: CPU count)")
    dataset.add_argument("--scheduler", metavar="ADDRESS",
                         help="a Dask scheduler, e.g. tcp://HOST:8786 (needs facelib[scale])")
    dataset.set_defaults(run=_dataset)


def _dataset(args: argparse.Namespace, console: Console) -> int:
    from facelib.dataset import generate, load_spec

    spec = load_spec(args.spec)
    report = generate(spec, args.output, jobs=args.jobs, scheduler=args.scheduler,
                      progress=console.progress("dataset", unit="clips"))
    console.status(f"{args.output}: {report.written} clips written, {report.skipped} already "
                   f"there, {len(report.failed)} failed")
    for clip, error in report.failed:
        print(f"facelib: error: clip {clip}: {error}", file=sys.stderr)
    return EXIT_ERROR if report.failed else EXIT_OK

