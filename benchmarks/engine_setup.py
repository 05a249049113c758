"""Time of face set-up (TPS + dense correspondence + attribute transfer + eyelid fit +
compiling the Face), landmark detection excluded, for heads of about 2.5k, 5k, 10k and 20k
vertices (the issue's goal: under 2 s at 10k).

Run from the repository root (one thread, so the figures are per core)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/engine_setup.py

The heads are the test heads of ``examples/heads`` and their 1-to-4 midpoint subdivisions
(same surface, four times the triangles). Also prints the TPS fit + warp of the default
head's 6026 vertices with its 50 feature points (reference test T-7: measured 0.023 s), and
the seed's figure for comparison: 1.03-1.41 s for its dense step alone on 2702-3412
triangles (third seed, tables 5.1-5.2).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from facelib.engine import default_face
from facelib.engine.setup import read_landmarks, setup_face
from facelib.engine.setup.headmesh import HeadMesh, head_mesh, load_head_mesh
from facelib.engine.setup.tps import fit_tps

HEADS = Path(__file__).resolve().parent.parent / "examples" / "heads"


def subdivide(mesh: HeadMesh) -> HeadMesh:
    """1-to-4 midpoint subdivision of a skin-only mesh."""
    tris = mesh.triangles
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    m = len(mesh.vertices) + inverse.reshape(3, -1).T
    a, b, c = tris.T
    new = np.concatenate([np.c_[a, m[:, 0], m[:, 2]], np.c_[m[:, 0], b, m[:, 1]],
                          np.c_[m[:, 2], m[:, 1], c], np.c_[m[:, 0], m[:, 1], m[:, 2]]])
    verts = np.vstack([mesh.vertices, mesh.vertices[unique].mean(axis=1)])
    return head_mesh(verts, new, name=f"{mesh.name} subdivided")


def best_of(fn, repeats: int = 3) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on {os.cpu_count()} cores")
    source = default_face()
    marks = source.vertices[list(source.feature_points.values())].astype(np.float64)
    moved = marks * 1.05 + np.random.default_rng(0).normal(scale=0.003, size=marks.shape)
    everything = source.vertices.astype(np.float64)
    t = best_of(lambda: fit_tps(marks, moved)(everything), repeats=5)
    print(f"TPS fit + warp, {len(everything)} vertices, {len(marks)} landmarks: {t:.4f} s")
    print(f"{'head':<28} {'vertices':>8} {'triangles':>9} {'set-up s':>9}  (best of 3)")
    for mesh_name, mark_name in (("cartoon_head.obj", "cartoon_landmarks.json"),
                                 ("soma_head.ply", "soma_landmarks.json")):
        mesh = load_head_mesh(HEADS / mesh_name)
        landmarks = read_landmarks(HEADS / mark_name)
        for head in (mesh, subdivide(mesh)):
            t = best_of(lambda h=head, m=landmarks: setup_face(h, landmarks=m, source=source,
                                                               report=True))
            print(f"{head.name:<28} {len(head.vertices):>8} {len(head.triangles):>9} "
                  f"{t:>9.2f}")


if __name__ == "__main__":
    main()
