"""ARKit-52 blendshape curves from FAP streams, and FAP streams from ARKit captures.

The default head carries the 52 ARKit targets of the MakeHuman base mesh it is cut from
(``facelib/data/head/arkit_targets.npz``, built by ``tools/build_arkit_targets.py``). Per frame,
the weights ``w`` in [0, 1] minimise ``|B w - d|`` (bounded least squares, scipy's
``lsq_linear``), where ``d`` is facelib's skin deformation of the frame without head and eye
rotation, and ``B`` the targets' displacements; the fit's residual is reported. Eye-look
weights come from the eye angles (the eyeballs are rigid joints), head and eye angles go to
Live Link Face's extra columns (radians; signs follow FAPs 23-26 and 48-50). TongueOut moves
no skin: it is how far the tongue tip reaches past the upper incisors (``arkit.json``), and an
import turns it back into the tongue-tip thrust that puts the tip there.

The inverse (:func:`from_arkit`) maps weights back to FAPs with one linear map per face:
the ridge-regularised least-squares FAPs whose deformation best matches ``B w``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from facelib import data
from facelib.engine import Face, default_face
from facelib.errors import FaceModelError, ParameterError
from facelib.export.source import Source, export_clip, face_of
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import N_FAPS, N_STANDARD_FAPS

__all__ = ["ANGLE_NAMES", "ArkitCurves", "arkit_names", "from_arkit", "live_link_names",
           "live_link_order", "to_arkit"]

ANGLE_NAMES = ("HeadYaw", "HeadPitch", "HeadRoll", "LeftEyeYaw", "LeftEyePitch", "LeftEyeRoll",
               "RightEyeYaw", "RightEyePitch", "RightEyeRoll")
"""Live Link Face's columns after the 52 weights (radians)."""
# FAP number of each angle column (0: none; eye roll does not exist in MPEG-4)
_ANGLE_FAPS = (49, 48, 50, 23, 25, 0, 24, 26, 0)
_RIGID_FAPS = (23, 24, 25, 26, 27, 28, 48, 49, 50)
_LIDS = (19, 20, 21, 22)


@dataclass(frozen=True, eq=False)
class ArkitCurves:
    """ARKit blendshape curves at a fixed frame rate.

    weights: (n, 52) float32 in [0, 1], columns in :func:`arkit_names` order.
    angles: (n, 9) float32 radians, columns ``ANGLE_NAMES``.
    residual: (n,) float32, RMS distance (metres) over the head's ARKit vertices between
        facelib's deformation and the weighted targets; NaN where not solved (imports).
    relative: (n,) float32, ``|B w - d| / |d|`` (0 where the frame does not move).
    """

    fps: float
    weights: np.ndarray
    angles: np.ndarray
    residual: np.ndarray
    relative: np.ndarray

    @property
    def n_frames(self) -> int:
        return int(self.weights.shape[0])


@cache
def _table() -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """(names, regions, solve kinds) from ``facelib/data/export/arkit.csv``."""
    rows = [row for _, row in data.csv_rows("export/arkit.csv")]
    return (tuple(r["name"] for r in rows), tuple(r["region"] for r in rows),
            tuple(r["solve"] for r in rows))


@cache
def _live_link_order() -> tuple[int, ...]:
    rows = [(int(row["live_link_face"]), row["name"]) for _, row in
            data.csv_rows("export/arkit.csv")]
    by_column = sorted(rows)
    if [c for c, _ in by_column] != list(range(len(rows))):
        raise FaceModelError("export/arkit.csv: live_link_face is not a permutation of 0-51")
    return tuple(arkit_names().index(name) for _, name in by_column)


def arkit_names() -> tuple[str, ...]:
    """The 52 ARKit names in facelib's order (Unreal's ``EARFaceBlendShape``: ``EyeBlinkLeft``
    ... ``TongueOut``), the columns of :attr:`ArkitCurves.weights`."""
    return _table()[0]


def live_link_names() -> tuple[str, ...]:
    """The 52 names in the column order of the Live Link Face app's CSV (``JawRight`` before
    ``JawLeft``, ``MouthRight`` before ``MouthLeft``)."""
    return tuple(arkit_names()[k] for k in _live_link_order())


def live_link_order() -> tuple[int, ...]:
    """For each Live Link Face CSV column 0-51, its index in :func:`arkit_names`."""
    return _live_link_order()


def arkit_regions() -> tuple[str, ...]:
    """Region of each name: ``lid``, ``gaze``, ``jaw``, ``mouth``, ``brow`` ..."""
    return _table()[1]


@dataclass(frozen=True, eq=False)
class _Basis:
    """The ARKit targets on a face, restricted to the vertices they move.

    ids: (S,) vertex ids; targets: (3S, 52) float64 displacements (metres) at weight 1;
    shape: (K,) int64 columns solved by least squares; q, r: the QR factors of
    ``targets[:, shape]``; to_faps: (84, 52) FAP values per unit weight (import);
    tongue: the tongue tip's reach past the upper incisors at rest and per unit of FAP 45
    (metres along +z), see :func:`_tongue_reach`.
    """

    ids: np.ndarray
    targets: np.ndarray
    shape: np.ndarray
    q: np.ndarray
    r: np.ndarray
    to_faps: np.ndarray
    tongue: tuple[float, float]


def _load_targets(face: Face) -> tuple[np.ndarray, np.ndarray]:
    with data.path("head/arkit_targets.npz").open("rb") as f:
        raw = dict(np.load(f))
    names = tuple(str(n) for n in raw["names"])
    if names != arkit_names():
        raise FaceModelError("head/arkit_targets.npz does not list the names of export/arkit.csv"
                             " in order: rebuild it with tools/build_arkit_targets.py")
    with data.path("head/default_head.npz").open("rb") as f:
        reference = np.load(f)["vertices"]
    own = face.vertices[: len(reference)]  # hair and bust are appended after the head's
    if own.shape != reference.shape or not np.allclose(own, reference, atol=1e-6):
        raise FaceModelError("ARKit curves need the default head (its ARKit targets come from "
                             "the same base mesh); this face has other vertices")
    ids = np.unique(raw["vertices"])
    at = np.asarray(np.searchsorted(ids, np.asarray(raw["vertices"])), np.int64)
    targets = np.zeros((len(ids), 3, len(names)))
    offsets = [int(o) for o in raw["offsets"]]
    shifts = np.asarray(raw["displacements"], np.float64)
    for k in range(len(names)):
        part = slice(offsets[k], offsets[k + 1])
        targets[at[part], :, k] = shifts[part]
    return ids, targets.reshape(-1, len(names))


def _fap_jacobian(face: Face, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Skin displacement per FAP unit at the basis vertices: ``(faps (F,), (3S, F))``.

    Linear FAPs come from the compiled operator; the eyelids are linearised around
    ``lid_linearisation`` (a finite difference of the real rotation).
    """
    columns = (ids[:, None] * 3 + np.arange(3)).ravel()
    op = face.operator.tocsr()[:, columns].toarray().astype(np.float64)
    faps = [j for j in range(3, N_STANDARD_FAPS + 1)
            if j not in _RIGID_FAPS and j not in _LIDS and np.any(op[j - 1])]
    cols = [op[j - 1] for j in faps]
    step = float(data.json_data("export/arkit.json")["lid_linearisation"])
    rest = face.vertices[ids].astype(np.float64).ravel()
    for j in _LIDS:
        values = np.zeros(N_FAPS, np.float32)
        values[j - 1] = step
        cols.append((face.deform_frame(values)[ids].astype(np.float64).ravel() - rest) / step)
        faps.append(j)
    return np.array(faps), np.stack(cols, 1)


@cache
def _basis_of_default() -> _Basis:
    return _make_basis(_default())


def _make_basis(face: Face) -> _Basis:
    ids, targets = _load_targets(face)
    shape = np.flatnonzero([k == "shape" for k in _table()[2]])
    q, r = np.linalg.qr(targets[:, shape])
    faps, jac = _fap_jacobian(face, ids)
    ridge = float(data.json_data("export/arkit.json")["ridge"])
    gram = jac.T @ jac
    solved = np.linalg.solve(gram + ridge * np.max(np.diag(gram)) * np.eye(len(faps)),
                             jac.T @ targets)
    to_faps = np.zeros((N_FAPS, targets.shape[1]))
    to_faps[faps - 1] = solved
    to_faps[:, [k for k, s in enumerate(_table()[2]) if s != "shape"]] = 0.0
    return _Basis(ids, targets, shape, q, r, to_faps, _tongue_reach(face))


_TONGUE_TIP = "6.1"
_THRUST = 45  # thrust_tongue_tip


def _tongue_reach(face: Face) -> tuple[float, float]:
    """How far (metres, +z) the tongue tip lies past the front of the upper incisors at
    rest (negative: behind them), and how far it moves forward per unit of FAP 45."""
    tip = face.feature_points[_TONGUE_TIP]
    front = float(np.max(face.vertices[face.parts["teeth_upper"].vertex_ids, 2]))
    step = np.zeros(N_FAPS, np.float32)
    step[_THRUST - 1] = 1000.0
    per_unit = float(face.deform_frame(step)[tip, 2] - face.vertices[tip, 2]) / 1000.0
    return float(face.vertices[tip, 2]) - front, per_unit


def _tongue_out(moved_tip_z: np.ndarray, face: Face, reach: tuple[float, float]) -> np.ndarray:
    """``(n,)`` TongueOut weights from the deformed tongue tip's ``z`` (metres)."""
    rest, _ = reach
    past = moved_tip_z - face.vertices[face.feature_points[_TONGUE_TIP], 2] + rest
    full = float(data.json_data("export/arkit.json")["tongue_out_reach_m"])
    return np.clip(past / full, 0.0, 1.0)


@cache
def _default() -> Face:
    return default_face()


def _basis(face: Face | None) -> tuple[Face, _Basis]:
    if face is None or face is _default():
        return _default(), _basis_of_default()
    return face, _make_basis(face)


def _eye_look(angles: np.ndarray) -> np.ndarray:
    """(n, 9) angles -> (n, 52) weights with only the eyeLook columns set."""
    full = data.json_data("export/arkit.json")["eye_look_full_deg"]
    h, v = np.radians(full["horizontal"]), np.radians(full["vertical"])
    names = arkit_names()
    out = np.zeros((len(angles), len(names)), np.float32)
    for side, yaw, pitch, toward_x in (("Left", 3, 4, "Out"), ("Right", 6, 7, "In")):
        away_x = "In" if toward_x == "Out" else "Out"
        # yaw > 0 turns the eye toward +x, the face's left: out for the left eye
        out[:, names.index(f"EyeLook{toward_x}{side}")] = np.clip(angles[:, yaw] / h, 0, 1)
        out[:, names.index(f"EyeLook{away_x}{side}")] = np.clip(-angles[:, yaw] / h, 0, 1)
        out[:, names.index(f"EyeLookDown{side}")] = np.clip(angles[:, pitch] / v, 0, 1)
        out[:, names.index(f"EyeLookUp{side}")] = np.clip(-angles[:, pitch] / v, 0, 1)
    return out


def to_arkit(source: Source, *, face: Face | None = None) -> ArkitCurves:
    """ARKit curves of a FapStream (or animation) on the default head.

    Raises ``FaceModelError`` for a face other than the default head (its ARKit targets
    belong to that mesh).
    """
    from scipy.optimize import lsq_linear

    clip = export_clip(source, face=face)
    stream = apply_high_level(clip.stream)
    face, basis = _basis(face_of(clip))
    au = face.fapu["AU"]
    angles = np.zeros((stream.n_frames, len(ANGLE_NAMES)), np.float32)
    for k, j in enumerate(_ANGLE_FAPS):
        if j:
            angles[:, k] = stream.values[:, j - 1] * au
    local = np.array(stream.values, np.float32)
    local[:, [j - 1 for j in _RIGID_FAPS]] = 0.0
    whole = face.deform(FapStream(stream.fps, local, stream.mask))
    moved = whole[:, basis.ids]
    d = (moved - face.vertices[basis.ids]).reshape(stream.n_frames, -1).astype(np.float64)
    weights = _eye_look(angles)
    weights[:, arkit_names().index("TongueOut")] = _tongue_out(
        whole[:, face.feature_points[_TONGUE_TIP], 2], face, basis.tongue)
    residual = np.zeros(stream.n_frames, np.float32)
    relative = np.zeros(stream.n_frames, np.float32)
    projected = d @ basis.q  # (n, K)
    for i in range(stream.n_frames):
        norm2 = float(d[i] @ d[i])
        if norm2 == 0.0:
            continue
        fit = lsq_linear(basis.r, projected[i], bounds=(0.0, 1.0), method="bvls")
        weights[i, basis.shape] = np.clip(fit.x, 0.0, 1.0)
        err2 = max(2 * fit.cost + norm2 - float(projected[i] @ projected[i]), 0.0)
        residual[i] = np.sqrt(err2 / len(basis.ids))
        relative[i] = np.sqrt(err2 / norm2)
    return ArkitCurves(float(stream.fps), weights, angles, residual, relative)


@cache
def _correction() -> np.ndarray:
    """``(52, 84) float64``: the learned part of the import (``export/arkit_correction.npz``,
    built by ``tools/build_arkit_correction.py``)."""
    with data.path("export/arkit_correction.npz").open("rb") as f:
        correction = np.asarray(np.load(f)["correction"], np.float64)
    if correction.shape != (len(arkit_names()), N_FAPS):
        raise FaceModelError("export/arkit_correction.npz has the wrong shape: rebuild it with "
                             "tools/build_arkit_correction.py")
    return correction


def from_arkit(curves: ArkitCurves, *, face: Face | None = None) -> FapStream:
    """A FapStream that plays ARKit curves on ``face`` (default: the bundled head).

    The blendshapes become low-level FAPs 3-68: the face's least-squares map (the FAPs whose
    deformation best matches the weighted ARKit targets) plus a learned linear correction
    (``export/arkit_correction.npz``: what that map misses of facelib's own animations,
    mostly the lip FAPs, whose motion lies largely outside the ARKit shapes; see
    ``tools/build_arkit_correction.py``). Head and eye angles become FAPs 48-50 and 23-26.
    Values are FAP units (float).
    """
    if not isinstance(curves, ArkitCurves):
        raise ParameterError(f"from_arkit() takes ArkitCurves, not {type(curves).__name__}")
    face, basis = _basis(face)
    weights = curves.weights.astype(np.float64)
    values = (weights @ basis.to_faps.T + weights @ _correction()).astype(np.float32)
    au = face.fapu["AU"]
    for k, j in enumerate(_ANGLE_FAPS):
        if j:
            values[:, j - 1] = curves.angles[:, k] / au
    out = curves.weights[:, arkit_names().index("TongueOut")].astype(np.float64)
    rest, per_unit = basis.tongue
    if per_unit > 0:
        full = float(data.json_data("export/arkit.json")["tongue_out_reach_m"])
        thrust = np.where(out > 0, (out * full - rest) / per_unit, 0.0)
        values[:, _THRUST - 1] = np.maximum(thrust, 0.0)
    mask = np.zeros(values.shape, bool)
    mask[:, 2:N_STANDARD_FAPS] = True
    values[:, N_STANDARD_FAPS:] = 0.0
    return FapStream(curves.fps, values, mask)
