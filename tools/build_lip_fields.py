"""Give the default head's lip protrusion (FAP 16/17) the ARKit pucker as learned fields.

    PYTHONPATH=. python tools/build_lip_fields.py

The face definition's push FAPs (``push_b_lip``, ``push_t_lip``) were RBF regions around the
inner-lip points 2.3/2.2 only: the inner lip moved 6 mm forward while the outer lip and the
corners stayed, so a rounded /u/ or /ʃ/ showed no protrusion. The rows of
``facelib/data/head/fap_targets.csv`` whose side is ``upper`` or ``lower`` (the two push
FAPs) are built here from the head's own ARKit targets (``arkit_targets.npz``, the same
``faceunits01`` targets the other fields come from): the target is cut at the lip line into
its upper and lower halves by what the jaw carries: a vertex's share in the lower half is how
far the head's ``JawOpen`` target moves it relative to the lower-lip point 2.3 (1 on the lower
lip and chin, 0 on the upper lip, in between at the corners), so the two halves add up to the
whole target whatever the lips' shape at rest, and they are written as ``field`` regions (see
:mod:`facelib.engine.deformers.fields`) into ``default_head.json`` and ``default_head.npz``. Rows
already there are replaced. Deterministic; the other rows are left as built by
``tools/build_default_head.py``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"
FIELD_MIN = 1e-5  # metres: displacements below this (at target weight 1) are dropped


def fap_target_rows() -> list[dict[str, str]]:
    lines = [ln for ln in (HEAD / "fap_targets.csv").read_text("utf-8").splitlines()
             if not ln.startswith("#")]
    return list(csv.DictReader(lines))


def arkit_target(name: str, n_vertices: int) -> np.ndarray:
    """``(n_vertices, 3) float64`` metres: ARKit target ``name`` at weight 1 on the head."""
    with np.load(HEAD / "arkit_targets.npz") as data:
        names = [str(n) for n in data["names"]]
        k = names.index(name)
        lo, hi = int(data["offsets"][k]), int(data["offsets"][k + 1])
        out = np.zeros((n_vertices, 3))
        out[data["vertices"][lo:hi]] = data["displacements"][lo:hi]
    return out


def half_weight(jaw: np.ndarray, lower_lip: int, side: str) -> np.ndarray:
    """``(V,)`` in [0, 1]: each vertex's share in the ``upper`` or ``lower`` half, from the
    jaw-opening target ``jaw`` ``(V, 3)``: the lower half is what the jaw carries, in
    proportion to the lower-lip point ``lower_lip``'s motion (the halves sum to 1)."""
    size = np.linalg.norm(jaw, axis=1)
    low = np.clip(size / size[lower_lip], 0.0, 1.0)
    return low if side == "lower" else 1.0 - low


def main() -> None:
    from facelib.mpeg4.tables import fap as fap_info

    doc = json.loads((HEAD / "default_head.json").read_text("utf-8"))
    with np.load(HEAD / "default_head.npz") as data:
        arrays = {k: data[k] for k in data.files}
    pos = arrays["vertices"].astype(np.float64)
    fp = doc["feature_points"]
    start, stop = doc["parts"]["skin"]  # [start, stop) vertex range
    skin = np.zeros(len(pos), bool)
    skin[start:stop] = True
    jaw = arkit_target("JawOpen", len(pos))
    for row in fap_target_rows():
        if row["side"] not in ("upper", "lower"):
            continue
        info = fap_info(row["fap"])
        field = np.zeros_like(pos)
        for term in row["targets"].split("+"):
            scale, _, name = term.rpartition("*")
            field += float(scale or 1.0) * arkit_target(name.strip(), len(pos))
        field *= (half_weight(jaw, fp["2.3"], row["side"]) * skin)[:, None]
        members = np.nonzero(np.linalg.norm(field, axis=1) > FIELD_MIN)[0]
        point = fp[info.feature_points[0]]
        key = f"field_{info.name}"
        print(f"{key}: {members.size} vertices, feature point moves "
              f"{1000 * np.linalg.norm(field[point]):.1f} mm at weight 1")
        arrays[key] = field[members].astype(np.float32)
        region = {"name": key, "deformer": "field", "feature_points": [info.feature_points[0]],
                  "params": {"fap": info.name}, "field": key, "targets": row["targets"],
                  "note": row["note"], "vertices": members.tolist()}
        doc["regions"] = [r for r in doc["regions"] if r["name"] != key] + [region]
    np.savez_compressed(HEAD / "default_head.npz", **arrays)
    (HEAD / "default_head.json").write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
