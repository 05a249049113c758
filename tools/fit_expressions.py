"""Fit expressions' FAP values to their ARKit target mixes (the six universal ones, worry, trust).

Usage (from the repository root, after tools/build_default_head.py)::

    python tools/fit_expressions.py            # rewrites their rows of expressions.csv
    python tools/fit_expressions.py --dry-run  # prints the fit only

For each expression the reference is ``mix_<expression>`` of ``default_head.npz`` (the skin
displacement of the textbook mix in ``facelib/data/head/expression_mixes.csv``). The FAP
values of the FAPs in ``FITTED`` are the bounded least-squares fit of the default head's
linear operator to that displacement over the skin (the eyelid regions excluded, the
feature points of the mouth, cheeks, chin and brows weighted up so they match closely);
the eyelid FAPs, which rotate rather than translate, take the vertical motion of their lid
point in the mix. Rows of FAPs the fit does not cover (head rotations) and of expressions
without a mix are kept as they are. Deterministic.
"""

from __future__ import annotations

import argparse
import csv
import io
from pathlib import Path

import numpy as np
from scipy.optimize import lsq_linear

from facelib import engine
from facelib.mpeg4.tables import fap

ROOT = Path(__file__).resolve().parent.parent
LIBRARY = ROOT / "facelib" / "data" / "expressions.csv"
MIXES = ROOT / "facelib" / "data" / "head" / "expression_mixes.csv"
FITTED = (
    "open_jaw", "lower_t_midlip", "raise_b_midlip", "lower_t_lip_lm", "lower_t_lip_rm",
    "raise_b_lip_lm", "raise_b_lip_rm", "stretch_l_cornerlip", "stretch_r_cornerlip",
    "raise_l_cornerlip", "raise_r_cornerlip", "depress_chin", "push_b_lip", "push_t_lip",
    "raise_l_i_eyebrow", "raise_r_i_eyebrow", "raise_l_m_eyebrow", "raise_r_m_eyebrow",
    "raise_l_o_eyebrow", "raise_r_o_eyebrow", "squeeze_l_eyebrow", "squeeze_r_eyebrow",
    "lift_l_cheek", "lift_r_cheek", "stretch_l_nose", "stretch_r_nose", "raise_nose",
    "nose_l_up", "nose_r_up", "lower_t_midlip_o", "raise_b_midlip_o", "lower_t_lip_lm_o",
    "lower_t_lip_rm_o", "raise_b_lip_lm_o", "raise_b_lip_rm_o", "stretch_l_cornerlip_o",
    "stretch_r_cornerlip_o", "raise_l_cornerlip_o", "raise_r_cornerlip_o",
)
LIDS = ("close_t_l_eyelid", "close_t_r_eyelid", "close_b_l_eyelid", "close_b_r_eyelid")
KEY_POINTS = ("2.1", "2.2", "2.3", "2.4", "2.5", "2.10", "8.1", "8.2", "8.3", "8.4",
              "5.1", "5.2", "5.3", "5.4", "4.1", "4.2", "4.3", "4.4", "4.5", "4.6")
KEY_WEIGHT = 12.0  # a key feature point counts as much as this many ordinary vertices
RIDGE = 0.02  # Tikhonov weight on FAP values (per column norm): keeps unused FAPs near 0
BOUND = 1080.0  # FAP units: the widest range of the FAP table
MIN_VALUE = 5.0  # fitted values below this (FAP units) are dropped


def fit(face: engine.Face, mix: np.ndarray) -> dict[str, float]:
    """FAP name -> value whose deformation best matches ``mix`` ((n_skin, 3) metres)."""
    n_skin = mix.shape[0]
    lid_ids = np.unique(np.concatenate(
        [r.vertices for r in face.regions if r.deformer == "eyelid"]))
    weight = np.ones(n_skin)
    weight[lid_ids[lid_ids < n_skin]] = 0.0
    for key in KEY_POINTS:
        weight[face.feature_points[key]] = KEY_WEIGHT
    cols = [fap(name).index for name in FITTED]
    dense = face.operator[cols].toarray().reshape(len(cols), -1, 3)[:, :n_skin]  # (F, n, 3)
    w = np.sqrt(np.repeat(weight, 3))
    a = (dense.reshape(len(cols), -1).T * w[:, None]).astype(np.float64)
    b = mix.reshape(-1).astype(np.float64) * w
    norms = np.linalg.norm(a, axis=0)
    a_reg = np.vstack([a, np.diag(RIDGE * norms)])
    b_reg = np.concatenate([b, np.zeros(len(cols))])
    # one-way FAPs (the jaw only opens) keep their sign
    lo = np.array([0.0 if fap(n).bidirectional is False else -BOUND for n in FITTED])
    result = lsq_linear(a_reg, b_reg, bounds=(lo, BOUND), method="bvls")
    values = {name: float(v) for name, v in zip(FITTED, result.x, strict=True)}
    for name in LIDS:
        info = fap(name)
        dy = float(mix[face.feature_points[info.feature_points[0]], 1])
        values[name] = dy / (face.fapu["IRISD"] * info.direction[1])
    return {k: round(v) for k, v in values.items() if abs(v) >= MIN_VALUE}


def _report(face: engine.Face, mix: np.ndarray, values: dict[str, float]) -> None:
    """Print the fit's displacement against the mix's at the key points (mm)."""
    frame = np.zeros(84, np.float32)
    for k, v in values.items():
        frame[fap(k).index] = v
    moved = face.deform_frame(frame) - face.vertices
    for key in KEY_POINTS:
        i = face.feature_points[key]
        want, got = mix[i] * 1000, moved[i] * 1000
        err = np.linalg.norm(got - want) / max(np.linalg.norm(want), 1e-9)
        print(f"  {key:5} mix {np.round(want, 1)} fit {np.round(got, 1)} err {err:.0%}")


def _rows_of(text: str) -> tuple[list[str], list[dict[str, str]]]:
    header = [ln for ln in text.splitlines() if ln.startswith("#")]
    body = "\n".join(ln for ln in text.splitlines() if not ln.startswith("#"))
    return header, list(csv.DictReader(io.StringIO(body)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dry-run", action="store_true")
    args = parser.parse_args()
    face = engine.default_face()
    names = list(dict.fromkeys(r["expression"] for r in _rows_of(MIXES.read_text("utf-8"))[1]))
    with np.load(ROOT / "facelib" / "data" / "head" / "default_head.npz") as data:
        mixes = {name: data[f"mix_{name}"] for name in names}
    header, rows = _rows_of(LIBRARY.read_text("utf-8"))
    fitted: list[dict[str, str]] = []
    for name in names:
        values = fit(face, mixes[name])
        print(name, values)
        _report(face, mixes[name], values)
        note = ("fitted to the ARKit mix of expression_mixes.csv on the default head "
                "(tools/fit_expressions.py)")
        fitted += [{"expression": name, "fap": k, "value": str(v), "note": note}
                   for k, v in values.items()]
        # FAPs the fit does not cover (head rotations) keep their rows
        fitted += [r for r in rows
                   if r["expression"] == name and fap(r["fap"]).kind == "rotation"]
    if args.dry_run:
        return
    kept = [r for r in rows if r["expression"] not in names]
    out = io.StringIO()
    out.write("\n".join(header) + "\n")
    writer = csv.DictWriter(out, fieldnames=["expression", "fap", "value", "note"],
                            lineterminator="\n")
    writer.writeheader()
    writer.writerows(fitted + kept)
    LIBRARY.write_text(out.getvalue(), "utf-8")


if __name__ == "__main__":
    main()
