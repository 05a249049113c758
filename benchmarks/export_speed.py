"""Exports of a 60 s storyboard-like stream (25 fps) on the default head: time and size.

Run from the repository root (one thread, so the figures are per core)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/export_speed.py

Prints, for the glTF export, the seconds, the file size and the number of morph targets;
for the ARKit solve, frames per second and the fit residual (RMS over the ARKit vertices and
the median relative residual); for the import of those curves, frames per second.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from facelib.export import export_gltf, from_arkit, to_arkit
from facelib.mpeg4.highlevel import expression_table, viseme_table
from facelib.mpeg4.stream import FapStream

FPS, SECONDS = 25.0, 60.0


def speech_like(*, seed: int = 0) -> FapStream:
    """Visemes every 120 ms blended into a slow expression, with blinks and head motion."""
    rng = np.random.default_rng(seed)
    n = int(FPS * SECONDS)
    t = np.arange(n) / FPS
    visemes = viseme_table()[rng.integers(1, 15, int(SECONDS / 0.12) + 2)]
    k = t / 0.12
    i, a = k.astype(int), (k % 1)[:, None]
    values = (1 - a) * visemes[i] + a * visemes[i + 1]
    mood = expression_table()[1 + (t // 10 % 6).astype(int)]
    values += (0.5 + 0.5 * np.sin(t / 3))[:, None] * mood
    blink = np.exp(-(((t % 4.0) - 2.0) / 0.08) ** 2) * 1024
    values[:, 18:20] = blink[:, None]
    values[:, 47:50] = 8000 * np.sin(t[:, None] / np.array([2.0, 3.0, 5.0]))
    return FapStream(FPS, values.astype(np.float32))


def main() -> None:
    stream = speech_like()
    with tempfile.TemporaryDirectory() as folder:
        started = time.perf_counter()
        result = export_gltf(stream, Path(folder) / "bench.glb")
        took = time.perf_counter() - started
        size = result.path.stat().st_size
    print(f"glTF: {stream.n_frames} frames in {took:.2f} s, {size / 1e6:.2f} MB, "
          f"{len(result.targets)} morph targets")
    started = time.perf_counter()
    curves = to_arkit(stream)
    took = time.perf_counter() - started
    moving = curves.relative[curves.relative > 0]
    print(f"ARKit solve: {stream.n_frames / took:.0f} frames/s, residual RMS "
          f"{1000 * float(curves.residual.mean()):.2f} mm, median relative "
          f"{float(np.median(moving)):.2f}")
    started = time.perf_counter()
    from_arkit(curves)
    print(f"ARKit import: {stream.n_frames / (time.perf_counter() - started):.0f} frames/s")


if __name__ == "__main__":
    main()
