"""Throughput of ``Face.deform`` on the default head: a 60 s stream at 25 fps.

Run from the repository root (one thread, so the figure is per core)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/engine_deform.py

Prints frames per second for three streams: every translational FAP moving (lips, brows,
cheeks...), the same plus eye and lid motion, and everything including the jaw and head
rotations (every rigid step active in every frame). Each stream runs through both paths, the
compiled kernel (:mod:`facelib.engine.fused`, numba) and the numpy path it replaces where
numba is installed, beside the memory-write ceiling for the same output (a fresh
``(n_frames, V, 3)`` float32 array filled with the neutral head), measured in the same run,
interleaved, best of five; the ratios are to that ceiling.

The first call in a process pays for the operating system's first touch of the output's
pages (a few times slower for all three); a warm-up call runs before the timings. Then, in
fresh processes, the cost of the first deformation of a 3 s clip with each path: numba's
import and the load of its cached machine code (or, the very first time, its compilation)
against the numpy path's first call (``deform`` itself keeps streams this short on the numpy
path; see ``facelib.engine.face._KERNEL_FROM``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np

from facelib.engine import fused, load_face
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap_table

FPS, SECONDS = 25.0, 60.0
# the first deformation of a short clip in a fresh process (see the module docstring)
FIRST_CALL = """
import time
start = time.perf_counter()
import numpy as np
from facelib.engine import fused, load_face
face = load_face()
values = np.zeros((75, 84), np.float32)
values[:, 48] = 5000.0 * np.sin(np.arange(75) / 10.0)
loaded = time.perf_counter()
face._deform(values, kernel=fused.available())  # deform() itself takes numpy for 75 frames
print(time.perf_counter() - loaded)
"""


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


def measure(runs, s: FapStream, repeats: int = 5) -> list[float]:
    """Frames per second of each of ``runs`` on ``s``, best of ``repeats`` interleaved."""
    best = [np.inf] * len(runs)
    for _ in range(repeats):
        for k, run in enumerate(runs):
            start = time.perf_counter()
            run(s)
            best[k] = min(best[k], time.perf_counter() - start)
    return [s.n_frames / b for b in best]


def first_call(jit: str) -> float:
    """Seconds of the first ``deform`` of a 3 s clip in a fresh process, ``FACELIB_JIT=jit``."""
    env = {**os.environ, "FACELIB_JIT": jit}
    out = subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, capture_output=True,
                         text=True, check=True)
    return float(out.stdout.split()[-1])


def main() -> None:
    face = load_face()
    linear = {f.id for f in fap_table() if f.kind == "translation"} - {3, 14, 15, 19, 20, 21,
                                                                        22, 27, 28}
    eyes = linear | {19, 20, 21, 22, 23, 24, 25, 26}
    everything = eyes | {3, 14, 15, 27, 28, 48, 49, 50}
    compiled = fused.available()
    print(f"default head: {face.n_vertices} vertices, operator nnz {face.operator.nnz}, "
          f"numba kernel {'on' if compiled else 'missing: numpy path only'}")
    face.deform(stream(everything))  # first touch of fresh pages (see the docstring)

    def numpy_path(s: FapStream) -> None:
        face._deform_numpy(np.asarray(s.values, np.float32))

    assert not compiled or face._kernel_for(int(FPS * SECONDS))  # deform() takes the kernel
    runs = [face.deform, numpy_path, lambda s: ceiling(face, s)]
    for name, kinds in (("translations only", linear), ("+ eyes and lids", eyes),
                        ("everything (jaw, head)", everything)):
        s = stream(kinds)
        fps, numpy_fps, top = measure(runs, s)
        print(f"{name:24s} {s.n_frames} frames: kernel {fps:6.0f} frames/s ({fps / top:.2f}), "
              f"numpy {numpy_fps:6.0f} ({numpy_fps / top:.2f}), ceiling {top:6.0f}")
    if compiled:
        times = {jit: min(first_call(jit) for _ in range(3)) for jit in ("1", "0")}
        print(f"first deform of a 3 s clip in a fresh process: kernel {times['1']:.2f} s, "
              f"numpy {times['0']:.2f} s (best of 3, machine code cached)")


if __name__ == "__main__":
    main()
