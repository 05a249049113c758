"""CPU time of ``import facelib`` and of ``facelib --help``, as a ratio to a bare interpreter
measured side by side in the same run (the figure of issue 30, item 6).

Each round starts, in turn, a bare ``python -c pass``, ``python -c "import facelib"`` and
``facelib --help`` (the console script's ``main``) as fresh processes, and reads each child's
user + system CPU time from ``getrusage``; the figure is the median over the rounds. With
``--before DIR`` the same commands also run with the facelib checkout at ``DIR`` first on the
path (e.g. ``/work/main``), interleaved in the same rounds, for a before/after comparison on
one machine under one load. Bytecode is compiled once, into a temporary
``PYTHONPYCACHEPREFIX`` (nothing is written into the trees), before the counted rounds, as an
installed package has it; a first round warms it and is not counted.

Run: ``PYTHONPATH=. python benchmarks/import_time.py [--rounds 15] [--before DIR]``.

Measured (issue 30, item 6; shared 2-core Xeon, load 13, ``--rounds 7 --before`` main, after
merging main with ``cli.py`` still one module): before, ``import facelib`` 1.75 s = 41 x
bare, ``facelib --help`` 1.82 s = 43 x bare; after (no ``scipy.signal``, no scipy at all, the
engine loaded on first use), 0.33 s = 7.5 x and 0.35 s = 8.0 x. numpy alone is about 4 x
bare on this machine; the rest is facelib's own modules and the standard library.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from machine import describe

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "bare interpreter": "pass",
    "import facelib": "import facelib",
    "facelib --help": ("import sys; from facelib.cli import main; sys.argv = ['facelib', "
                       "'--help']; sys.exit(main())"),
}


def _cpu(code: str, tree: Path, pycache: str) -> float:
    """User + system CPU seconds of a fresh ``python -c code`` with ``tree`` on the path."""
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONPYCACHEPREFIX": pycache}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", code], cwd=tree, env=env, check=True,
                   stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--before", type=Path, help="another facelib checkout to compare")
    args = parser.parse_args()
    trees = {"this tree": ROOT}
    if args.before is not None:
        trees = {"before": args.before.resolve(), "after": ROOT}
    times: dict[tuple[str, str], list[float]] = {}
    with tempfile.TemporaryDirectory(prefix="facelib-pycache-") as pycache:
        for round_ in range(args.rounds + 1):
            for tree_name, tree in trees.items():
                for label, code in COMMANDS.items():
                    cpu = _cpu(code, tree, pycache)
                    if round_:
                        times.setdefault((tree_name, label), []).append(cpu)
    print(f"machine: {describe()}")
    print(f"median CPU (user + system) of {args.rounds} fresh processes each, interleaved")
    for tree_name in trees:
        bare = statistics.median(times[(tree_name, "bare interpreter")])
        print(f"{tree_name}:")
        for label in COMMANDS:
            cpu = statistics.median(times[(tree_name, label)])
            print(f"  {label:<18} {cpu:6.3f} s  {cpu / bare:6.1f} x bare")


if __name__ == "__main__":
    main()
