"""Time the eye generator: one hour of each mode at 25 fps, and a 60 s pursuit at 50 fps.

Run: PYTHONPATH=. .venv/bin/python benchmarks/gaze_simulate.py
"""

from __future__ import annotations

import time

import numpy as np

from facelib.gaze import pursue, simulate


def main() -> None:
    for mode in ("talking", "listening", "thinking"):
        t0 = time.perf_counter()
        anim = simulate("default", mode, seconds=3600, seed=0)
        dt = time.perf_counter() - t0
        print(
            f"default {mode:9s} 3600 s: {dt:6.2f} s wall, {len(anim.saccades)} saccades, "
            f"{len(anim.blinks) / 60:.1f} blinks/min, {anim.track.n_frames / dt:,.0f} frames/s"
        )
    t = np.arange(60 * 50) / 50
    target = np.column_stack([15 * np.sin(t), 5 * np.cos(0.7 * t)])
    t0 = time.perf_counter()
    anim = pursue(target, fps=50)
    dt = time.perf_counter() - t0
    catch = sum(s.kind == "catch_up" for s in anim.saccades)
    print(f"pursue 60 s at 50 fps: {dt:6.2f} s wall, {catch} catch-up saccades")


if __name__ == "__main__":
    main()
