"""Find the MediaPipe embedding of facelib's default head afresh and package it.

Usage (from the repository root; needs the ``render`` and ``track`` extras)::

    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/build_tracking_embedding.py
    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/build_tracking_embedding.py --check

Runs :func:`facelib.tracking.embedding.embed_landmarks` on ``default_face()`` and writes the
vertex ids into ``facelib/data/tracking/default_head_mediapipe.json`` (its other keys kept);
``--check`` only reports. Either way it prints how far the packaged ids are from the fresh
ones, the figures ``tests/tracking/test_closed_loop.py``'s
``test_packaged_embedding_matches_a_fresh_one`` asks of them (at least 95 % of the landmarks
on the same vertex, none more than 3 mm off).

Run it whenever the default head's render changes: its shape, shading or teeth
(``tools/build_teeth.py`` calls it after its bake), and also its hair: the render leaves the
hair out but is framed with it (``framing_points(face, "head")``, all vertices but the
bust's), so a regroomed head is rendered at another scale and place and MediaPipe's fit
moves. The tracker's observation model (``tools/build_tracking_observation.py``) is learned
from renders and their true FAPs, not from this embedding, and needs no rebuild for it; the
embedding serves ``rig="default"`` (:func:`facelib.tracking.faps.default_rig`) and the tests
that put landmarks on the mesh.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
EMBEDDING = ROOT / "facelib" / "data" / "tracking" / "default_head_mediapipe.json"


def agreement(face, fresh: np.ndarray, packaged: np.ndarray) -> tuple[float, float]:
    """Share of landmarks on the same vertex and the largest gap (m) between the two."""
    vertices = np.asarray(face.vertices, np.float64)
    gap = np.linalg.norm(vertices[fresh] - vertices[packaged], axis=1)
    return float((fresh == packaged).mean()), float(gap.max())


def main(*, write: bool = True) -> np.ndarray:
    """Find the embedding, report its agreement with the packaged one, write it (``write``);
    returns the fresh ids."""
    from facelib.engine import default_face
    from facelib.tracking.embedding import embed_landmarks

    face = default_face()
    fresh = embed_landmarks(face)
    doc = json.loads(EMBEDDING.read_text())
    packaged = np.asarray(doc["vertices"], np.int64)
    same, gap = agreement(face, fresh, packaged)
    print(f"packaged embedding against a fresh one: {same:.1%} of landmarks on the same "
          f"vertex, largest gap {gap * 1000:.2f} mm")
    if write:
        doc["vertices"] = [int(i) for i in fresh]
        EMBEDDING.write_text(json.dumps(doc) + "\n")
        print(f"wrote {EMBEDDING.relative_to(ROOT)}")
    return fresh


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="report, write nothing")
    main(write=not parser.parse_args().check)
