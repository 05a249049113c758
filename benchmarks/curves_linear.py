"""Time exponents of the expression curves (``expressions.animate``) and the viseme blend
(``visemes.coarticulation.blend``) over 5, 10, 20 and 40-minute synthetic storyboards (the
figure of issue 30, item 7).

A storyboard of L minutes has an expression cue every 3 s lasting 4 s (so neighbours
overlap; the shipped library's expressions in turn, seeded intensities) and speech of
viseme spans 60-160 ms long with a silence now and then, at 25 fps. Each length is timed
with ``time.process_time`` (best of ``--repeat``), all in one process; the exponent between
two lengths is ``log(t2 / t1) / log(L2 / L1)`` (1 is linear time). With ``--before DIR`` the
same is measured, interleaved in the same run, with ``expressions/curves.py`` and
``visemes/coarticulation.py`` loaded from the facelib checkout at ``DIR`` (their other
imports, the data tables included, come from this tree), so before and after share a
machine and its load.

Run: ``OMP_NUM_THREADS=1 PYTHONPATH=. python benchmarks/curves_linear.py [--before DIR]``
(one BLAS thread: ``process_time`` adds up every thread, so a threaded product on a
loaded machine blurs the figure).

Measured (issue 30, item 7; shared 2-core Xeon, load 1-3, ``--before`` main, best of 2),
CPU seconds at 5/10/20/40 minutes and the exponent from 5 to 40 minutes:

====================  ================================  ===========
                      5 / 10 / 20 / 40 min (s)           exponent
====================  ================================  ===========
animate, before       0.414 / 1.624 / 6.762 / 34.615     2.13
animate, after        0.023 / 0.052 / 0.070 / 0.133      0.85
blend, before         0.059 / 0.117 / 0.234 / 0.437      0.96
blend, after          0.058 / 0.117 / 0.235 / 0.447      0.98
====================  ================================  ===========

The blend was already linear on one thread: it takes frames in chunks of 512 with only the
spans within its window (``window_ms``), so it is left as it is (a finer span structure
would change which far spans enter each sum, by up to the window's 1e-7 relative). The
exponent of 1.2 seen before came from timing a threaded BLAS product on a loaded machine.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import ModuleType

import numpy as np
from machine import describe

from facelib.cues import ExpressionCue
from facelib.expressions import curves, default_library
from facelib.visemes import coarticulation
from facelib.visemes.timeline import VisemeSpan

FPS = 25.0
MINUTES = (5, 10, 20, 40)


def storyboard(minutes: int) -> tuple[list[ExpressionCue], list[VisemeSpan], int]:
    """(expression cues, viseme spans, n_frames) of a synthetic ``minutes``-long storyboard."""
    rng = np.random.default_rng(minutes)
    length_ms = minutes * 60_000
    names = sorted(default_library().names)
    cues = [ExpressionCue(names[k % len(names)], start, 4000,
                          intensity=float(rng.uniform(0.3, 1.0)))
            for k, start in enumerate(range(0, length_ms - 4000, 3000))]
    spans, t = [], 0
    while t < length_ms:
        viseme = 0 if rng.random() < 0.08 else int(rng.integers(1, 15))
        step = int(rng.integers(60, 160)) * (4 if viseme == 0 else 1)
        spans.append(VisemeSpan(viseme, f"v{viseme}", t, min(t + step, length_ms)))
        t += step
    return cues, spans, int(length_ms * FPS / 1000) + 1


def _load(tree: Path, relative: str, name: str) -> ModuleType:
    """The module at ``tree / relative`` loaded as ``name`` (its imports from this tree)."""
    spec = importlib.util.spec_from_file_location(name, tree / relative)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _best(run: Callable[[], object], repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        started = time.process_time()
        run()
        best = min(best, time.process_time() - started)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--before", type=Path, help="a facelib checkout to compare against")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    versions: dict[str, tuple[ModuleType, ModuleType]] = {}
    if args.before is not None:
        versions["before"] = (
            _load(args.before, "facelib/expressions/curves.py", "before_curves"),
            _load(args.before, "facelib/visemes/coarticulation.py", "before_coarticulation"))
    versions["after" if args.before is not None else "this tree"] = (curves, coarticulation)
    boards = {m: storyboard(m) for m in MINUTES}
    times: dict[tuple[str, str, int], float] = {}
    for minutes, (cues, spans, n_frames) in boards.items():
        frame_ms = coarticulation.frame_times_ms(n_frames, FPS)
        for label, (expr, coart) in versions.items():
            times[label, "expressions.animate", minutes] = _best(
                partial(expr.animate, cues, fps=FPS, n_frames=n_frames), args.repeat)
            times[label, "coarticulation.blend", minutes] = _best(
                partial(coart.blend, spans, frame_ms), args.repeat)
    print(f"machine: {describe()}")
    print(f"CPU seconds (process_time, best of {args.repeat}) at "
          f"{', '.join(f'{m} min' for m in MINUTES)}; exponents between neighbours and 5-40")
    for label in versions:
        for what in ("expressions.animate", "coarticulation.blend"):
            t = [times[label, what, m] for m in MINUTES]
            steps = [math.log(t[i + 1] / t[i]) / math.log(MINUTES[i + 1] / MINUTES[i])
                     for i in range(len(MINUTES) - 1)]
            overall = math.log(t[-1] / t[0]) / math.log(MINUTES[-1] / MINUTES[0])
            print(f"{label:<9} {what:<21} " + " ".join(f"{x:7.3f}" for x in t)
                  + "  exp " + " ".join(f"{x:.2f}" for x in steps) + f"  5-40: {overall:.2f}")


if __name__ == "__main__":
    main()
