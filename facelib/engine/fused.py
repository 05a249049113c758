"""``Face.deform`` in one compiled pass per frame (numba), where numba is installed.

The numpy path of :class:`facelib.engine.Face` deforms a block of frames step by step: the
sparse product, then eyelids, eyeballs, jaw and head, each a pass over the block. Here the
per-frame terms of those steps (angles, their sines and cosines, rotation matrices) are
still computed with numpy for a block of frames at once (:func:`frame_terms`), and one
compiled kernel (:mod:`facelib.engine.fused_kernel`) writes each output frame: the rest
shape plus the product, then the rigid steps on the same cache-warm frame.

numba is optional (the ``fast`` extra; the ``speech`` extra's librosa pulls it in too): it is
imported on the first deformation, never by ``import facelib``, and ``FACELIB_JIT=0`` in the
environment keeps the numpy path. Each frame is computed on its own (every step is applied
to the frames that move it, not to whole blocks), so a stream deformed in chunks is bit for
bit the stream deformed at once. The results equal the numpy path's to float32 rounding:
the product's terms add in another order, the kernel uses no fused multiply-adds where BLAS
may, and numba's sines and cosines are not numpy's.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
import scipy.sparse as sp

from facelib.engine import rigid

__all__ = ["Plan", "available", "deform", "frame_terms", "make_plan"]

_RUN_GAP = 24  # zero columns a run of the product may carry to join its neighbour
_BLOCK = 32  # frames whose per-frame terms numpy computes together


@cache
def _kernel() -> Callable[..., None] | None:
    """The compiled kernel, or None where numba is missing or turned off (``FACELIB_JIT=0``)."""
    if os.environ.get("FACELIB_JIT", "1") == "0":
        return None
    try:
        from facelib.engine.fused_kernel import deform_frames  # noqa: PLC0415
    except ImportError:
        return None
    return deform_frames  # type: ignore[no-any-return]


def available() -> bool:
    """Whether :func:`deform` can run (numba importable and not turned off)."""
    return _kernel() is not None


@dataclass(frozen=True, eq=False)
class Plan:
    """A face's constant inputs of the kernel; columns index flattened ``(V, 3)`` positions.

    rest: (3V,) float32 neutral positions.
    runs: (R, 4) uint64 (FAP column, first output column, length, offset into ``data``) of
        the operator's rows cut into dense runs; data: float32 their values (zeros between
        non-zeros closer than ``_RUN_GAP``).
    lid_cols: (2, K) uint64 y and z columns of the eyelid vertices; lid_pivots: (2, K)
        float32 their eye centres' y and z.
    eye_cols: (3E,) uint64 columns of both eyeballs; eye_local: (E, 3) float32 their rest
        shape about their centres; eye_bounds: (2, 2) uint64 each eye's first and stop
        vertex in those; eye_centre: (2, 3) float32.
    jaw_cols: (3, J) uint64 x, y, z columns of the lower teeth and tongue; jaw_pivot: (3,)
        float64.
    spans: (S, 2) uint64 first and stop vertices the head turns (all but those it leaves
        still); neck_cols: (3N,) uint64 columns of the partly turned neck vertices;
        head_pivot: (3,) float32.
    columns: the FAP columns the terms read (``jaw``: open, thrust, shift; ``head``: pitch,
        yaw, roll).
    rig: the face's precomputed rigid steps (``Face._rigid``: hinges, weights, FAP columns);
    fapu: the face's FAPU.
    """

    rest: np.ndarray
    runs: np.ndarray
    data: np.ndarray
    lid_cols: np.ndarray
    lid_pivots: np.ndarray
    eye_cols: np.ndarray
    eye_local: np.ndarray
    eye_bounds: np.ndarray
    eye_centre: np.ndarray
    jaw_cols: np.ndarray
    jaw_pivot: np.ndarray
    spans: np.ndarray
    neck_cols: np.ndarray
    head_pivot: np.ndarray
    columns: Mapping[str, tuple[int, int, int]]
    rig: Any
    fapu: Mapping[str, float]


def _runs(operator: sp.csr_array) -> tuple[np.ndarray, np.ndarray]:
    """Each row's non-zero columns joined into dense runs: ``(runs (R, 4) uint64, data)``."""
    runs, data, at = [], [], 0
    for k in range(operator.shape[0]):
        lo, hi = operator.indptr[k], operator.indptr[k + 1]
        cols, vals = operator.indices[lo:hi].astype(np.int64), operator.data[lo:hi]
        if cols.size == 0:
            continue
        cuts = np.flatnonzero(np.diff(cols) > _RUN_GAP + 1) + 1
        for c, v in zip(np.split(cols, cuts), np.split(vals, cuts), strict=True):
            dense = np.zeros(c[-1] - c[0] + 1, np.float32)
            dense[c - c[0]] = v
            runs.append((k, c[0], dense.size, at))
            data.append(dense)
            at += dense.size
    if not runs:
        return np.zeros((0, 4), np.uint64), np.zeros(0, np.float32)
    return np.array(runs, np.uint64), np.concatenate(data)


def _spans(n_vertices: int, still: np.ndarray) -> np.ndarray:
    """``(S, 2) uint64`` runs of the vertices not in ``still`` (columns (3S,))."""
    turned = np.ones(n_vertices, bool)
    turned[np.asarray(still, np.int64)[::3] // 3] = False
    edges = np.diff(np.r_[0, turned.astype(np.int8), 0])
    return np.stack([np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)], 1).astype(
        np.uint64)


def make_plan(vertices: np.ndarray, operator: sp.csr_array, rig: Any, fapu: Mapping[str, float],
              *, jaw: tuple[int, int, int], head: tuple[int, int, int]) -> Plan:
    """The kernel's inputs for a face: its ``(V, 3)`` rest shape, ``(84, 3V)`` operator, its
    precomputed rigid steps (``Face._rigid``), FAPU and the FAP columns of jaw and head."""
    runs, data = _runs(operator)
    lids = rig.lids
    eyes = rig.eyes
    sizes = np.array([0] + [local.shape[0] for _, local, *_ in eyes]).cumsum()
    u64 = np.uint64
    return Plan(
        rest=np.array(vertices.reshape(-1), np.float32),
        runs=runs, data=data,
        lid_cols=np.stack([lids.y, lids.z]).astype(u64).reshape(2, -1),
        lid_pivots=np.stack([lids.pivot_y, lids.pivot_z]).astype(np.float32).reshape(2, -1),
        eye_cols=np.concatenate([cols for cols, *_ in eyes]).astype(u64),
        eye_local=np.concatenate([local for _, local, *_ in eyes]).astype(np.float32),
        eye_bounds=np.stack([sizes[:-1], sizes[1:]], 1).astype(u64),
        eye_centre=np.array([tiled[:3] for _, _, tiled, *_ in eyes], np.float32),
        jaw_cols=np.stack([rig.jaw_x, rig.jaw_y, rig.jaw_z]).astype(u64).reshape(3, -1),
        jaw_pivot=np.array(rig.jaw_pivot, np.float64),
        spans=_spans(vertices.shape[0], rig.still),
        neck_cols=np.asarray(rig.neck).astype(u64),
        head_pivot=np.array(rig.head_pivot, np.float32),
        columns={"jaw": jaw, "head": head},
        rig=rig, fapu=fapu,
    )


def _lid_terms(plan: Plan, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame of ``f`` (n, 84) float64: whether a lid moves (n,) bool, and the cosine and
    sine of each lid vertex's angle (n, K) float32 (zeros where none moves)."""
    lids = plan.rig.lids
    n, k = len(f), plan.lid_cols.shape[1]
    angles = np.zeros((n, len(lids.hinges)))
    for j, (fap_index, dy_per_unit, pivot, rest) in enumerate(lids.hinges):
        moving = f[:, fap_index] != 0
        if moving.any():
            angles[moving, j] = rigid.hinge_angle(rest, pivot, f[moving, fap_index] * dy_per_unit)
    on = angles.any(axis=1)
    if not on.any():
        return on, np.zeros((n, k), np.float32), np.zeros((n, k), np.float32)
    # the regions' angles add up per vertex, in a fixed order (the same for any block)
    total = np.zeros((n, k))
    for j in range(len(lids.hinges)):
        total += angles[:, j, None] * lids.weights[j]
    total32 = total.astype(np.float32)
    return on, np.cos(total32), np.sin(total32)


def _eye_terms(plan: Plan, f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frame and eye: moves (n, 2) bool, rotation (n, 2, 3, 3) float32, forward motion
    (n, 2) float32."""
    au, es = plan.fapu["AU"], plan.fapu["ES"]
    on, rots, thrusts = [], [], []
    for *_, yaw, pitch, thrust in plan.rig.eyes:
        y, p, t = f[:, yaw] * au, f[:, pitch] * au, f[:, thrust]
        on.append((y != 0) | (p != 0) | (t != 0))
        rots.append(rigid.rotation_matrices(p, y, np.zeros_like(p)).astype(np.float32))
        thrusts.append((t * es).astype(np.float32))
    return (np.stack(on, 1), np.ascontiguousarray(np.stack(rots, 1)),
            np.ascontiguousarray(np.stack(thrusts, 1)))


def _jaw_terms(plan: Plan, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: the jaw moves (n,) bool; cos, sin, thrust, shift (n, 4) float32."""
    r, fapu = plan.rig, plan.fapu
    open_, thrust, shift = (f[:, c] for c in plan.columns["jaw"])
    angle = rigid.hinge_angle(r.chin, r.jaw_pivot, -open_ * r.chin_drop).astype(np.float32)
    terms = np.stack([np.cos(angle), np.sin(angle), (thrust * fapu["MNS"]).astype(np.float32),
                      (shift * fapu["MW"]).astype(np.float32)], 1)
    return (open_ != 0) | (thrust != 0) | (shift != 0), terms


def _head_terms(plan: Plan, f: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per frame: the head turns (n,) bool, R^T (n, 3, 3) float32, and the neck's terms of
    :func:`facelib.engine.rigid.weighted_terms` (zeros where no frame turns)."""
    au = plan.fapu["AU"]
    pitch, yaw, roll = (f[:, c] * au for c in plan.columns["head"])
    on = (pitch != 0) | (yaw != 0) | (roll != 0)
    rot = rigid.rotation_matrices(pitch, yaw, roll)
    turned = np.ascontiguousarray(rot.transpose(0, 2, 1), dtype=np.float32)
    k = plan.neck_cols.size // 3
    if not on.any():
        zero = np.zeros((len(f), k), np.float32)
        return on, turned, np.zeros((len(f), 3, 3), np.float32), zero, zero
    cross, sin, vers = rigid.weighted_terms(rot, plan.rig.head_weights, np.float32)
    return on, turned, np.ascontiguousarray(cross), sin, vers


def frame_terms(plan: Plan, f: np.ndarray) -> tuple[np.ndarray, ...]:
    """The kernel's per-frame arguments for ``f`` (n, 84) float32 FAP values, in its order."""
    f64 = f.astype(np.float64)
    lid_on, lid_cos, lid_sin = _lid_terms(plan, f64)
    eye_on, eye_rot, eye_thrust = _eye_terms(plan, f64)
    jaw_on, jaw = _jaw_terms(plan, f64)
    head_on, turned, cross, sin, vers = _head_terms(plan, f64)
    return (plan.rest, plan.runs, plan.data, plan.lid_cols, plan.lid_pivots, lid_on, lid_cos,
            lid_sin, plan.eye_cols, plan.eye_local, plan.eye_bounds, plan.eye_centre, eye_on,
            eye_rot, eye_thrust, plan.jaw_cols, plan.jaw_pivot, jaw_on, jaw, plan.spans,
            plan.neck_cols, plan.head_pivot, head_on, turned, cross, sin, vers)


def deform(plan: Plan, f: np.ndarray) -> np.ndarray:
    """Vertex positions ``(n, V, 3) float32`` for ``f`` (n, 84) float32 FAP values (high-level
    FAPs already decoded); requires :func:`available`."""
    kernel = _kernel()
    if kernel is None:
        raise RuntimeError("fused.deform() needs numba (check fused.available() first)")
    n, width = len(f), plan.rest.size
    out = np.empty((n, width), np.float32)
    for a in range(0, n, _BLOCK):
        # a writable copy, so that every call has the one signature numba compiled and cached
        block = np.array(f[a : a + _BLOCK], dtype=np.float32, order="C")
        kernel(out[a : a + len(block)], block, *frame_terms(plan, block))
    return out.reshape(n, width // 3, 3)
