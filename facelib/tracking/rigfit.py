"""FAPs by fitting a face's own deformation to the tracked landmark motion.

Eq. 4.16 reads each FAP off one feature point. On a real face (and on any MPEG-4 head)
one FAP moves many points and one point is moved by many FAPs: opening the jaw lowers the
lip corners, a smile lifts the cheeks. Here the avatar's deformation is linearised at the
neutral face, ``J[k]`` = how every embedded landmark moves (face frame x, y) per unit of
FAP k in units of that FAP's FAPU, and each frame's landmark displacements ``d`` (neutral
head frame, pixels) are explained as ``d ≈ Σ_k f_k U_k r_k J[k]``: ``U_k`` is the user's
FAPU of FAP k measured on the tracker's landmarks, ``r_k`` the face's own FAPU over the
same measurement on the face (the tracker's landmarks may place 9.15 or the lips a little
differently from the face definition: measured alike on both sides, the user's proportions
carry over and the FAPs come out in the face's units). A ridge-regularised least-squares
solve for all frames at once.

Only translational x/y FAPs that move some landmark take part (jaw, lips, lids, brows,
cheeks, nose); gaze and head pose are measured directly (:mod:`facelib.tracking.faps`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from facelib.checks import check_number
from facelib.engine import Face
from facelib.mpeg4 import N_FAPS, FapStream, fap_table

__all__ = ["RigModel", "fit_faps", "rig_model", "rigid_columns"]

_STEP = 200.0
"""FAP units of the finite difference (large enough to linearise the hinged jaw and lids
over their working range)."""
_SKIP_GROUPS = {1, 6, 7, 10}
"""High-level FAPs, tongue, head and ears: not seen as skin landmarks."""


@dataclass(frozen=True)
class RigModel:
    """A face's landmark motion per FAP.

    Attributes
    ----------
    faps: ``(m,) int64`` FAP ids in the model.
    units: FAPU name of each FAP (``m`` of them).
    landmarks: ``(L,) int64`` the tracker's landmark indices used.
    jacobian: ``(m, L, 2) float64`` face-frame x/y motion of each landmark per FAP unit,
        in units of that FAP's FAPU (dimensionless).
    anchors: ``(L,) int64`` for each landmark, the position in ``landmarks`` of the anchor
        its motion is measured against (itself for anchors, -1 for landmarks far from every
        anchor, whose motion stays in the head frame); empty when there are no anchors.
    fapu_ratio: FAPU name -> the face's FAPU over its FAPU measured on the tracker's
        landmarks (1.0 where they agree).
    """

    faps: np.ndarray
    units: tuple[str, ...]
    landmarks: np.ndarray
    jacobian: np.ndarray
    anchors: np.ndarray
    fapu_ratio: Mapping[str, float]


def rig_model(face: Face, vertex_of_landmark: np.ndarray, landmarks: np.ndarray,
              *, anchors: np.ndarray | None = None,
              landmark_fapu: Mapping[str, float] | None = None,
              min_motion: float = 0.02) -> RigModel:
    """Linearise ``face`` at neutral for the given landmarks.

    Parameters
    ----------
    face: the face whose rig explains the motion (e.g. the default head).
    vertex_of_landmark: ``(K,) int`` the face vertex of each tracker landmark
        (:mod:`facelib.tracking.embedding`).
    landmarks: ``(L,) int`` the landmarks to use (skin points that FAPs move).
    anchors: landmark indices that serve as local references: a landmark near one (within
        0.4 of the anchors' spread on the neutral face) has its motion taken relative to
        the nearest, so that what is left of the head motion after the pose fit mostly
        cancels; the others, and all with None, move in the head frame.
    landmark_fapu: the face's FAPU measured on the tracker's landmarks (as the user's
        are); None takes the face's own.
    min_motion: drop FAPs that move no landmark by more than this many FAPU per FAP unit.
    """
    anchors = np.zeros(0, np.int64) if anchors is None else np.asarray(anchors, np.int64)
    verts = np.asarray(vertex_of_landmark, np.int64)[np.asarray(landmarks, np.int64)]
    rest = face.vertices[verts, :2].astype(np.float64)
    ids, units, columns = [], [], []
    for fap in fap_table():
        if fap.kind != "translation" or fap.axis not in ("x", "y") or fap.group in _SKIP_GROUPS:
            continue
        values = np.zeros((2, N_FAPS), np.float32)
        values[0, fap.index] = _STEP
        values[1, fap.index] = -_STEP if fap.bidirectional is not False else 0.0
        moved = face.deform(FapStream(25.0, values))[:, verts, :2].astype(np.float64)
        span = _STEP if fap.bidirectional is False else 2 * _STEP
        motion = (moved[0] - (moved[1] if fap.bidirectional is not False else rest)) / span
        motion /= face.fapu[fap.fapu]
        if np.abs(motion).max() < min_motion:
            continue
        ids.append(fap.id)
        units.append(fap.fapu)
        columns.append(motion)
    jac = np.stack(columns)
    jac.flags.writeable = False
    measured = face.fapu if landmark_fapu is None else landmark_fapu
    ratio = {name: float(face.fapu[name] / measured[name]) for name in face.fapu}
    return RigModel(np.array(ids, np.int64), tuple(units), np.asarray(landmarks, np.int64), jac,
                    _nearest_anchor(rest, np.asarray(landmarks, np.int64), anchors), ratio)


def _nearest_anchor(rest: np.ndarray, landmarks: np.ndarray, anchors: np.ndarray,
                    reach: float = 0.4) -> np.ndarray:
    """For each of ``landmarks`` (neutral x/y ``rest``), the position in ``landmarks`` of
    the nearest of ``anchors`` if it lies within ``reach`` times the anchors' spread, else
    -1 (the landmark's motion stays in the head frame). Empty if there are no anchors."""
    where = np.flatnonzero(np.isin(landmarks, anchors))
    if not where.size:
        return np.zeros(0, np.int64)
    spread = float(np.max(np.linalg.norm(rest[where, None] - rest[None, where], axis=2)))
    dist = np.linalg.norm(rest[:, None, :] - rest[None, where, :], axis=2)
    out = np.where(dist.min(axis=1) <= reach * spread, where[np.argmin(dist, axis=1)], -1)
    out.flags.writeable = False
    return out


def rigid_columns(rest: np.ndarray) -> np.ndarray:
    """``(6, L, 2)`` x/y motion of points ``rest`` ``(L, 3)`` per unit of a small rotation
    about x, y, z (radians, about their centroid), a scale change and an x and a y shift."""
    centred = np.asarray(rest, np.float64) - np.asarray(rest, np.float64).mean(axis=0)
    x, y, z = centred.T
    zero, one = np.zeros_like(x), np.ones_like(x)
    return np.stack([np.stack(c, axis=-1) for c in (
        (zero, -z), (z, zero), (-y, x), (x, y), (one, zero), (zero, one))])


def _at_anchor(motion: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """``(..., L, 2)`` motion of each landmark's anchor (0 where it has none)."""
    return np.where((anchors >= 0)[:, None], motion[..., np.maximum(anchors, 0), :], 0.0)


def fit_faps(model: RigModel, displacements: np.ndarray, fapu: Mapping[str, float], *,
             rest: np.ndarray | None = None, ridge: float = 0.01) -> np.ndarray:
    """Solve ``(n, L, 2)`` landmark displacements (neutral head frame, same unit as
    ``fapu``) for ``(n, m) float64`` FAP values of ``model.faps``.

    ``rest`` (``(L, 3)`` neutral positions) adds a small rigid motion per frame to the fit
    (:func:`rigid_columns`), so what is left of the head pose after the stable-point fit
    is explained as pose, not as expression. Motions are taken relative to each landmark's
    anchor (``model.anchors``) on both sides of the fit.

    ``ridge`` (>= 0) is the Tikhonov weight on the FAPs relative to the mean diagonal of
    ``J^T J``: it splits motion between FAPs that move the same points alike (inner and
    outer lip FAPs) and keeps unobservable combinations at 0.
    """
    ridge = check_number("ridge", ridge, low=0)
    scale = np.array([fapu[u] * model.fapu_ratio[u] for u in model.units])
    jac = model.jacobian * scale[:, None, None]  # (m, L, 2)
    m = len(jac)
    if rest is not None:
        jac = np.concatenate([jac, rigid_columns(rest)])
    anchored = model.anchors.size > 0
    if anchored:
        jac = jac - _at_anchor(jac, model.anchors)
    jac = jac.reshape(len(jac), -1)
    penalty = ridge * float(np.einsum("ij,ij->", jac[:m], jac[:m])) / m
    gram = jac @ jac.T
    gram[np.arange(m), np.arange(m)] += penalty
    # rigid columns that anchoring cancels (the shifts) get a tiny weight, not a singularity
    gram[np.arange(m, len(gram)), np.arange(m, len(gram))] += 1e-9 * penalty + 1e-12
    moved = np.asarray(displacements, np.float64)
    if anchored:
        moved = moved - _at_anchor(moved, model.anchors)
    rhs = moved.reshape(len(moved), -1) @ jac.T
    return np.linalg.solve(gram, rhs.T).T[:, :m]
