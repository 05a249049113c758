"""Wall-clock times of the README's commands on this machine, as a user runs them (a fresh
process each, imports included): the figures quoted in README.md.

Run: ``PYTHONPATH=. python benchmarks/cli_timings.py``.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import describe

ROOT = Path(__file__).resolve().parents[1]


def _timed(args: list[str]) -> float:
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "facelib.cli", "-q", *args], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    return time.perf_counter() - started


def main() -> None:
    print(f"machine: {describe()}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        commands = {
            "check examples/hello (7 s)": ["check", "examples/hello/hello.fdl"],
            "run examples/hello -> .fap": ["run", "examples/hello/hello.fdl", "-o",
                                           str(out / "hello.fap")],
            "render examples/hello 640x480 .mp4 (make demo)": [
                "render", "examples/hello/hello.fdl", "-o", str(out / "hello.mp4"),
                "--fap", str(out / "hello2.fap")],
            "run examples/hastalavista (thesis) -> .fap": [
                "run", "examples/hastalavista/hastalavista.fdl", "-o", str(out / "h.fap")],
            "render examples/hastalavista 640x480 .mp4": [
                "render", "examples/hastalavista/hastalavista.fdl", "-o",
                str(out / "hasta.mp4")],
        }
        for label, args in commands.items():
            print(f"{label:<48} {_timed(args):6.1f} s")


if __name__ == "__main__":
    main()
