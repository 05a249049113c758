"""Deformers compared: compile time and per-frame cost of each deformer on the lips, and the
roughness evaluation table of the second seed (chapter 4) written into ``docs/``.

Run from the repository root (``make bench`` does)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/engine_deformers.py

Prints, per deformer (lips of the default head switched to it): the time to load and compile
the face, the operator's non-zeros, and frames per second of ``Face.deform`` on a 20 s
viseme stream; the frame-based ones also in ``mode="exact"`` (a per-frame step). Then runs
``facelib.evaluate`` and writes ``docs/deformers_table.md``, ``docs/deformers_table.csv`` and
``docs/images/deformers_mouths.png`` (``facelib evaluate`` also writes the seed's per-frame
rows).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from facelib.engine import load_face
from facelib.evaluate import (
    DEFORMERS,
    evaluate_deformers,
    write_contact_sheet,
    write_evaluation,
)
from facelib.mpeg4.stream import FapStream
from facelib.visemes.tables import viseme_targets

DOCS = Path(__file__).resolve().parent.parent / "docs"


def viseme_stream(seconds: float = 20.0, fps: float = 25.0, *, seed: int = 0) -> FapStream:
    """Random walk through the 15 visemes, 4 frames per transition."""
    rng = np.random.default_rng(seed)
    targets = viseme_targets()
    n = int(seconds * fps)
    keys = targets[rng.integers(0, len(targets), n // 4 + 2)]
    s = (np.arange(n) % 4) / 4.0
    values = (1 - s)[:, None] * keys[np.arange(n) // 4] + s[:, None] * keys[np.arange(n) // 4 + 1]
    return FapStream(fps, values.astype(np.float32))


def timing(label: str, override: object, stream: FapStream) -> None:
    start = time.perf_counter()
    face = load_face(deformers={"lips": override})  # type: ignore[dict-item]
    compile_s = time.perf_counter() - start
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        face.deform(stream)
        best = min(best, time.perf_counter() - start)
    print(f"{label:<28} load+compile {compile_s:6.2f} s   operator nnz {face.operator.nnz:6d}"
          f"   deform {stream.n_frames / best:8.0f} frames/s")


def main() -> None:
    stream = viseme_stream()
    print(f"lips deformers on the default head; deform of {stream.n_frames} frames")
    for name in DEFORMERS:
        timing(name, name, stream)
    for name in ("soffd", "planar_bones"):
        timing(f"{name} (exact step)", {"deformer": name, "mode": "exact"}, stream)
    start = time.perf_counter()
    ev = evaluate_deformers(DEFORMERS)
    write_evaluation(ev, DOCS, stem="deformers_table", sheet=False, frames=False)
    write_contact_sheet(DEFORMERS, DOCS / "images" / "deformers_mouths.png")
    print(f"evaluation of {len(DEFORMERS)} deformers: {time.perf_counter() - start:.1f} s")
    print((DOCS / "deformers_table.md").read_text())


if __name__ == "__main__":
    main()
