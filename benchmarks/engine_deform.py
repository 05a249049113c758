"""Throughput of ``Face.deform`` on the default head: a 60 s stream at 25 fps.

Run from the repository root (one thread, so the figure is per core)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/engine_deform.py

Prints frames per second for three streams: every translational FAP moving (lips, brows,
cheeks...), the same plus eye and lid motion, and everything including the jaw and head
rotations (every rigid step active in every frame), each beside the memory-write ceiling for
the same output (a fresh ``(n_frames, V, 3)`` float32 array filled with the neutral head),
measured in the same run, interleaved, best of five.

The first call in a process pays for the operating system's first touch of the output's
pages (a few times slower for both); a warm-up call runs before the timings.
"""

from __future__ import annotations

import time

import numpy as np

from facelib.engine import load_face
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap_table

FPS, SECONDS = 25.0, 60.0


def stream(kinds: set[int], *, seed: int = 0) -> FapStream:
    n = int(FPS * SECONDS)
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FPS
    values = np.zeros((n, 84), np.float32)
    for f in fap_table():
        if f.id in kinds:
            phase, freq = rng.uniform(0, 2 * np.pi), rng.uniform(0.2, 2.0)
            amp = 20000.0 if f.kind == "rotation" else 200.0
            values[:, f.index] = amp * np.sin(2 * np.pi * freq * t + phase)
    values[:, 2] = np.abs(values[:, 2])
    return FapStream(FPS, values, values != 0)


def ceiling(face, s: FapStream) -> None:
    """The least any deformation must do: write a fresh array of the output's shape."""
    out = np.empty((s.n_frames, face.n_vertices, 3), np.float32)
    out.reshape(s.n_frames, -1)[:] = face.vertices.reshape(-1)


def measure(face, s: FapStream, repeats: int = 5) -> tuple[float, float]:
    """(deform, ceiling) frames per second, best of ``repeats`` interleaved runs."""
    best = [np.inf, np.inf]
    for _ in range(repeats):
        for k, run in enumerate((face.deform, lambda s: ceiling(face, s))):
            start = time.perf_counter()
            run(s)
            best[k] = min(best[k], time.perf_counter() - start)
    return s.n_frames / best[0], s.n_frames / best[1]


def main() -> None:
    face = load_face()
    linear = {f.id for f in fap_table() if f.kind == "translation"} - {3, 14, 15, 19, 20, 21,
                                                                        22, 27, 28}
    eyes = linear | {19, 20, 21, 22, 23, 24, 25, 26}
    everything = eyes | {3, 14, 15, 27, 28, 48, 49, 50}
    print(f"default head: {face.n_vertices} vertices, operator nnz {face.operator.nnz}")
    face.deform(stream(everything))  # first touch of fresh pages (see the docstring)
    for name, kinds in (("translations only", linear), ("+ eyes and lids", eyes),
                        ("everything (jaw, head)", everything)):
        s = stream(kinds)
        fps, top = measure(face, s)
        print(f"{name:24s} {s.n_frames} frames: {fps:7.0f} frames/s, ceiling {top:7.0f}, "
              f"ratio {fps / top:.2f}")


if __name__ == "__main__":
    main()
