"""``Face.deform`` as one compiled kernel (numba), where numba is installed.

The numpy path of :class:`facelib.engine.Face` deforms a block of frames step by step: the
sparse product, then eyelids, eyeballs, jaw and head, each a pass over the block. Here numpy
computes only the per-frame scalars of those steps (hinge angles, rotation matrices) for the
whole call, and one compiled kernel (:mod:`facelib.engine.fused_kernel`) does the rest,
frame by frame: the rest shape plus the product into the output row, then the rigid steps
on that row while it is in the CPU cache.

numba is optional (the ``fast`` extra; the ``speech`` extra's librosa pulls it in too): it is
imported on the first deformation, never by ``import facelib``, and ``FACELIB_JIT=0`` in the
environment keeps the numpy path. Each frame is computed on its own (every step is applied
to the frames that move it, not to whole blocks), so a stream deformed in chunks is bit for
bit the stream deformed at once. The results equal the numpy path's to float32 rounding
(a few units in the last place): the product's terms add in another order, the kernel uses
no fused multiply-adds where BLAS may, and its sines and cosines (a series in float64,
rounded) are not numpy's float32 ones.
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

__all__ = ["Plan", "available", "deform", "make_plan"]

_RUN_GAP = 24  # zero columns a run of the product may carry to join its neighbour


@cache
def _kernel() -> Callable[..., None] | None:
    """The compiled kernel, or None where numba is missing or turned off (``FACELIB_JIT=0``)."""
    if os.environ.get("FACELIB_JIT", "1") == "0":
        return None
    try:
        from facelib.engine.fused_kernel import deform_frames
    except ImportError:
        return None
    return deform_frames


def available() -> bool:
    """Whether :func:`deform` can run (numba importable and not turned off)."""
    return _kernel() is not None


@dataclass(frozen=True, eq=False)
class Plan:
    """A face's constant inputs of the kernel. Vertex sets are spans: ``(S, 3+)`` uint64 rows
    (first vertex, stop vertex, index of the first in the set's per-vertex arrays), sorted.

    rest: (3V,) float32 neutral positions, flattened ``(V, 3)``.
    runs: (R, 4) uint64 (first column, stop column, offset into ``data``, FAP column): the
        operator's rows cut into dense runs; data: float32 their values (zeros between
        non-zeros closer than ``_RUN_GAP``).
    lid_spans: the eyelid vertices; lid_pivots: (2, K) float32 their eye centres' y and z;
        lid_weights: (R, K) float64 each lid region's weight of each.
    eye_spans: (S, 4), both eyeballs, the eye (0, 1) in the last column; eye_local: (E, 3)
        float32 their rest shape about their centres; eye_centre: (2, 3) float32.
    jaw_spans: the lower teeth and tongue; jaw_pivot: (3,) float64.
    head_spans: the vertices the head turns (all but those it leaves still) that another step
        moves too; plain_spans: those it alone moves (turned straight from the rest shape);
        busy_spans: all but the plain ones; neck_spans: the
        partly turned neck vertices, neck_weights (N,) float32 how far; head_pivot: (3,)
        float32.
    columns: the FAP columns the terms read (``jaw``: open, thrust, shift; ``head``: pitch,
        yaw, roll).
    rig: the face's precomputed rigid steps (``Face._rigid``: hinges, FAP columns);
    fapu: the face's FAPU.
    """

    rest: np.ndarray
    runs: np.ndarray
    data: np.ndarray
    lid_spans: np.ndarray
    lid_pivots: np.ndarray
    lid_weights: np.ndarray
    eye_spans: np.ndarray
    eye_local: np.ndarray
    eye_centre: np.ndarray
    jaw_spans: np.ndarray
    jaw_pivot: np.ndarray
    head_spans: np.ndarray
    plain_spans: np.ndarray
    busy_spans: np.ndarray
    neck_spans: np.ndarray
    neck_weights: np.ndarray
    head_pivot: np.ndarray
    columns: Mapping[str, tuple[int, int, int]]
    rig: Any
    fapu: Mapping[str, float]


def _runs(operator: sp.csr_array) -> tuple[np.ndarray, np.ndarray]:
    """Each row's non-zero columns joined into dense runs: ``(runs (R, 4) int64, data)``."""
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
            runs.append((c[0], c[-1] + 1, at, k))
            data.append(dense)
            at += dense.size
    if not runs:
        return np.zeros((0, 4), np.int64), np.zeros(0, np.float32)
    return np.array(runs, np.int64), np.concatenate(data)


def _vertex_spans(ids: np.ndarray) -> np.ndarray:
    """``(S, 3) int64`` spans of ``ids`` (sorted, unique vertex ids)."""
    ids = np.asarray(ids, np.int64)
    if ids.size == 0:
        return np.zeros((0, 3), np.int64)
    cuts = np.flatnonzero(np.diff(ids) != 1) + 1
    starts = np.r_[0, cuts]
    stops = np.r_[cuts, ids.size]
    return np.stack([ids[starts], ids[stops - 1] + 1, starts], 1)


def _ids(columns: np.ndarray) -> np.ndarray:
    """The vertex ids of ``(3K,)`` x, y, z columns (see ``facelib.engine.face._columns``)."""
    return np.asarray(columns, np.int64)[::3] // 3


def _eye_parts(eyes: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both eyes' spans (S, 4), rest shapes about their centres (E, 3) and centres (2, 3)."""
    spans, local, at = [], [], 0
    for e, (cols, rest, *_) in enumerate(eyes):
        ids = _ids(cols)
        order = np.argsort(ids, kind="stable")
        part = _vertex_spans(ids[order])
        part[:, 2] += at
        spans.append(np.c_[part, np.full(len(part), e, np.int64)])
        local.append(rest[order])
        at += ids.size
    return (np.concatenate(spans), np.concatenate(local).astype(np.float32),
            np.array([tiled[:3] for _, _, tiled, *_ in eyes], np.float32))


def _lists(vertices: np.ndarray, operator: sp.csr_array, rig: Any) -> dict[str, np.ndarray]:
    """The kernel's lists: runs (in columns); lids, eyes, jaw, neck, and the head's vertices
    in three (``head``: turned and moved by another step too, ``plain``: turned and moved
    by nothing else, ``busy``: all but ``plain``) (in vertices)."""
    turned = np.ones(len(vertices), bool)
    turned[_ids(rig.still)] = False
    runs, _ = _runs(operator)
    eyes, _, _ = _eye_parts(rig.eyes)
    lists = {"runs": runs,
             "lids": _vertex_spans(np.asarray(rig.lids.y, np.int64) // 3),
             "eyes": eyes,
             "jaw": _vertex_spans(np.unique(np.asarray(rig.jaw_x, np.int64) // 3)),
             "neck": _vertex_spans(_ids(rig.neck))}
    # the vertices the head alone moves turn straight from the rest shape
    plain = turned.copy()
    for first, stop, *_ in runs:
        plain[first // 3 : (stop + 2) // 3] = False
    for name in ("lids", "eyes", "jaw", "neck"):
        for first, stop, *_ in lists[name]:
            plain[first:stop] = False
    lists["head"] = _vertex_spans(np.flatnonzero(turned & ~plain))
    lists["plain"] = _vertex_spans(np.flatnonzero(plain))
    lists["busy"] = _vertex_spans(np.flatnonzero(~plain))
    return lists


def make_plan(vertices: np.ndarray, operator: sp.csr_array, rig: Any, fapu: Mapping[str, float],
              *, jaw: tuple[int, int, int], head: tuple[int, int, int]) -> Plan:
    """The kernel's inputs for a face: its ``(V, 3)`` rest shape, ``(84, 3V)`` operator, its
    precomputed rigid steps (``Face._rigid``), FAPU and the FAP columns of jaw and head."""
    lists = {name: spans.astype(np.uint64)
             for name, spans in _lists(vertices, operator, rig).items()}
    _, eye_local, eye_centre = _eye_parts(rig.eyes)
    return Plan(
        rest=np.array(vertices.reshape(-1), np.float32),
        runs=lists["runs"], data=_runs(operator)[1],
        lid_spans=lists["lids"],
        lid_pivots=np.stack([rig.lids.pivot_y, rig.lids.pivot_z]).astype(np.float32),
        lid_weights=np.array(rig.lids.weights, np.float64).reshape(-1, len(rig.lids.y)),
        eye_spans=lists["eyes"], eye_local=eye_local, eye_centre=eye_centre,
        jaw_spans=lists["jaw"], jaw_pivot=np.array(rig.jaw_pivot, np.float64),
        head_spans=lists["head"], plain_spans=lists["plain"], busy_spans=lists["busy"],
        neck_spans=lists["neck"],
        neck_weights=np.array(rig.head_weights, np.float32),
        head_pivot=np.array(rig.head_pivot, np.float32),
        columns={"jaw": jaw, "head": head}, rig=rig, fapu=fapu,
    )


def _lid_angles(plan: Plan, f: np.ndarray) -> np.ndarray:
    """Each lid region's hinge angle (n, R) float64 for ``f`` (n, 84) float64, zero in the
    frames where its FAP is."""
    hinges = plan.rig.lids.hinges
    angles = np.zeros((len(f), len(hinges)))
    for j, (fap_index, dy_per_unit, pivot, rest) in enumerate(hinges):
        moving = f[:, fap_index] != 0
        if moving.any():
            angles[moving, j] = rigid.hinge_angle(rest, pivot, f[moving, fap_index] * dy_per_unit)
    return angles


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
    """Per frame: the head turns (n,) bool, R^T (n, 3, 3) float32, and the rotation's axis
    (as a cross-product matrix, (n, 3, 3) float32) and angle (n,) float64 for the neck."""
    au = plan.fapu["AU"]
    pitch, yaw, roll = (f[:, c] * au for c in plan.columns["head"])
    rot = rigid.rotation_matrices(pitch, yaw, roll)
    turned = np.ascontiguousarray(rot.transpose(0, 2, 1), dtype=np.float32)
    cross, angle = rigid.axis_angle(rot, np.float32)
    on = (pitch != 0) | (yaw != 0) | (roll != 0)
    return on, turned, np.ascontiguousarray(cross), angle


def deform(plan: Plan, f: np.ndarray) -> np.ndarray:
    """Vertex positions ``(n, V, 3) float32`` for ``f`` (n, 84) float32 FAP values (high-level
    FAPs already decoded); requires :func:`available`."""
    kernel = _kernel()
    if kernel is None:
        raise RuntimeError("fused.deform() needs numba (check fused.available() first)")
    # a writable copy, so that every call has the one signature numba compiled and cached
    f = np.array(f, dtype=np.float32, order="C")
    f64 = f.astype(np.float64)
    angles = _lid_angles(plan, f64)
    eye_on, eye_rot, eye_thrust = _eye_terms(plan, f64)
    jaw_on, jaw = _jaw_terms(plan, f64)
    head_on, turned, cross, angle = _head_terms(plan, f64)
    n, width = len(f), plan.rest.size
    out = np.empty((n, width), np.float32)
    kernel(out, f, plan.rest, plan.runs, plan.data,
           plan.lid_spans, plan.lid_pivots, plan.lid_weights, angles.any(axis=1), angles,
           plan.eye_spans, plan.eye_local, plan.eye_centre, eye_on, eye_rot, eye_thrust,
           plan.jaw_spans, plan.jaw_pivot, jaw_on, jaw,
           plan.head_spans, plan.plain_spans, plan.busy_spans, plan.neck_spans,
           plan.neck_weights, plan.head_pivot, head_on,
           turned, cross, angle)
    return out.reshape(n, width // 3, 3)
