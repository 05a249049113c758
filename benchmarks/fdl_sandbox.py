"""How fast the FDL sandbox loads storyboards and stops hostile ones (prints figures).

Run: PYTHONPATH=. .venv/bin/python benchmarks/fdl_sandbox.py
"""

from __future__ import annotations

import time
from pathlib import Path

from facelib import fdl
from facelib.errors import FdlError
from facelib.fdl.sandbox import Sandbox

DATA = Path(__file__).parents[1] / "tests" / "data" / "fdl" / "thesis"


def timed(label: str, fn, repeat: int = 5) -> None:
    best = float("inf")
    outcome = ""
    for _ in range(repeat):
        t0 = time.perf_counter()
        try:
            fn()
            outcome = "ok"
        except FdlError as exc:
            outcome = exc.message[:60]
        best = min(best, time.perf_counter() - t0)
    print(f"{label:38s} {best * 1000:9.1f} ms  {outcome}")


def main() -> None:
    box = Sandbox()
    timed("new Sandbox()", Sandbox)
    timed("thesis storyboard (3 files)", lambda: fdl.load(DATA / "storyboard.fdl", sandbox=box))
    loop = "\n".join("show { 'joy', dur = 0.04 }" for _ in range(1000))
    timed("1000 show cues", lambda: fdl.loads(loop, sandbox=box))
    timed("endless loop (budget 1e8)", lambda: fdl.loads("while true do end", sandbox=box), 2)
    timed(
        "string doubling (64 MiB cap)",
        lambda: fdl.loads('local s = "x" while true do s = s .. s end', sandbox=box),
        2,
    )
    timed(
        "table growth (64 MiB cap)",
        lambda: fdl.loads("local t = {} for i = 1, 1e12 do t[i] = {i} end", sandbox=box),
        2,
    )


if __name__ == "__main__":
    main()
