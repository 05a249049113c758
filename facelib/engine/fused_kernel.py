"""The compiled half of :mod:`facelib.engine.fused`: one pass per frame over its output.

Imported only by :func:`facelib.engine.fused.kernel`, the first time a face deforms with
numba installed (never by ``import facelib``); ``cache=True`` keeps the machine code beside
this file (or in numba's user cache where that folder is read-only), so later processes load
it instead of compiling it again.

Every index array is ``uint64`` and every loop counts in ``uint64``: numba then emits no
negative-index wrap-around, and LLVM vectorises the long loops (the product's runs, the head
turn). Arithmetic mirrors the numpy path's dtypes step by step (float32, with the jaw's
float64 intermediates), without fused multiply-adds; only the order of the product's sums
differs from the BLAS product there.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["deform_frames"]

_U0, _U1, _U2, _U3 = np.uint64(0), np.uint64(1), np.uint64(2), np.uint64(3)


@njit(cache=True, nogil=True)
def _product(o, rest, ft, runs, data):  # type: ignore[no-untyped-def]
    """``o (3V,) = rest + ft @ A``, ``A`` as dense runs: rows of ``runs`` (R, 4) uint64 are
    (FAP column, first output column, length, offset into ``data`` (float32))."""
    o[:] = rest
    for r in range(runs.shape[0]):
        fk = ft[runs[r, 0]]
        if fk != 0.0:
            first, size, at = runs[r, 1], runs[r, 2], runs[r, 3]
            for j in range(size):
                o[first + j] += data[at + j] * fk


@njit(cache=True, nogil=True)
def _lids(o, cols, pivots, cos, sin):  # type: ignore[no-untyped-def]
    """Turn the lid vertices about x: ``cols`` (2, K) uint64 y and z columns, ``pivots``
    (2, K) float32 their eye centres, ``cos``/``sin`` (K,) float32 of each vertex's angle."""
    for k in range(cols.shape[1]):
        cy, cz = cols[0, k], cols[1, k]
        y = o[cy] - pivots[0, k]
        z = o[cz] - pivots[1, k]
        o[cy] = y * cos[k] - z * sin[k] + pivots[0, k]
        o[cz] = y * sin[k] + z * cos[k] + pivots[1, k]


@njit(cache=True, nogil=True)
def _eye(o, cols, local, centre, rot, thrust):  # type: ignore[no-untyped-def]
    """Place an eyeball: vertex k at columns ``cols[3k:3k+3]`` (uint64) is
    ``rot @ local[k] + (0, 0, thrust) + centre`` (float32 throughout)."""
    for k in range(local.shape[0]):
        x, y, z = local[k, 0], local[k, 1], local[k, 2]
        base = _U3 * np.uint64(k)
        o[cols[base]] = (x * rot[0, 0] + y * rot[0, 1] + z * rot[0, 2]) + centre[0]
        o[cols[base + _U1]] = (x * rot[1, 0] + y * rot[1, 1] + z * rot[1, 2]) + centre[1]
        o[cols[base + _U2]] = ((x * rot[2, 0] + y * rot[2, 1] + z * rot[2, 2]) + thrust
                               + centre[2])


@njit(cache=True, nogil=True)
def _jaw(o, cols, pivot, jaw):  # type: ignore[no-untyped-def]
    """Hinge the jaw's vertices (``cols`` (3, K) uint64 x, y, z columns) about x through
    ``pivot`` (3,) float64; ``jaw`` (4,) float32 is cos, sin, the thrust and the shift."""
    c, s = np.float64(jaw[0]), np.float64(jaw[1])
    thrust, shift = np.float64(jaw[2]), jaw[3]
    for k in range(cols.shape[1]):
        cx, cy, cz = cols[0, k], cols[1, k], cols[2, k]
        y = np.float64(o[cy]) - pivot[1]
        z = np.float64(o[cz]) - pivot[2]
        o[cy] = np.float32(y * c - z * s + pivot[1])
        o[cz] = np.float32((y * s + z * c + pivot[2]) + thrust)
        o[cx] -= shift


@njit(cache=True, nogil=True)
def _neck(o, cols, pivot, cross, sin, vers, out):  # type: ignore[no-untyped-def]
    """The neck's partly turned vertices (Rodrigues), into ``out`` (3K,) float32: vertex k
    at ``cols[3k:3k+3]`` turns about ``pivot`` by ``sin[k]``, ``vers[k]`` (1 - cos) of its
    angle about the axis whose cross-product matrix is ``cross`` (3, 3)."""
    for k in range(sin.shape[0]):
        base = _U3 * np.uint64(k)
        v0 = o[cols[base]] - pivot[0]
        v1 = o[cols[base + _U1]] - pivot[1]
        v2 = o[cols[base + _U2]] - pivot[2]
        for a in range(3):
            kv = v0 * cross[0, a] + v1 * cross[1, a] + v2 * cross[2, a]
            out[base + np.uint64(a)] = kv
        k0, k1, k2 = out[base], out[base + _U1], out[base + _U2]
        for a in range(3):
            kkv = k0 * cross[0, a] + k1 * cross[1, a] + k2 * cross[2, a]
            v = (v0, v1, v2)[a]
            out[base + np.uint64(a)] = v + out[base + np.uint64(a)] * sin[k] + kkv * vers[k] \
                + pivot[a]


@njit(cache=True, nogil=True)
def _head(o, spans, pivot, turned):  # type: ignore[no-untyped-def]
    """Turn vertices ``spans`` (S, 2) uint64 (first, stop vertex) about ``pivot`` (3,)
    float32 in place: ``p' = (p - pivot) @ turned + pivot``, ``turned`` (3, 3) = R^T."""
    px, py, pz = pivot[0], pivot[1], pivot[2]
    t00, t01, t02 = turned[0, 0], turned[0, 1], turned[0, 2]
    t10, t11, t12 = turned[1, 0], turned[1, 1], turned[1, 2]
    t20, t21, t22 = turned[2, 0], turned[2, 1], turned[2, 2]
    for s in range(spans.shape[0]):
        for v in range(spans[s, 0], spans[s, 1]):
            i = _U3 * v
            x, y, z = o[i] - px, o[i + _U1] - py, o[i + _U2] - pz
            o[i] = x * t00 + y * t10 + z * t20 + px
            o[i + _U1] = x * t01 + y * t11 + z * t21 + py
            o[i + _U2] = x * t02 + y * t12 + z * t22 + pz


@njit(cache=True, nogil=True)
def deform_frames(out, f, rest, runs, data, lid_cols, lid_pivots, lid_on, lid_cos, lid_sin,
                  eye_cols, eye_local, eye_bounds, eye_centre, eye_on, eye_rot, eye_thrust,
                  jaw_cols, jaw_pivot, jaw_on, jaw,
                  spans, neck_cols, head_pivot, head_on, head_turned, neck_cross, neck_sin,
                  neck_vers):  # type: ignore[no-untyped-def]
    """Deform ``out`` (n, 3V) float32 from ``f`` (n, 84) float32, frame by frame.

    The ``*_on`` (n,) bool flags say which steps move each frame; the per-frame terms are
    :func:`facelib.engine.fused.frame_terms`'s, the constant ones
    :class:`facelib.engine.fused.Plan`'s (shapes there).
    """
    scratch = np.empty(neck_cols.shape[0], np.float32)
    for t in range(out.shape[0]):
        o = out[t]
        _product(o, rest, f[t], runs, data)
        if lid_on[t]:
            _lids(o, lid_cols, lid_pivots, lid_cos[t], lid_sin[t])
        for e in range(eye_on.shape[1]):
            if eye_on[t, e]:
                first, stop = eye_bounds[e, 0], eye_bounds[e, 1]
                _eye(o, eye_cols[_U3 * first:_U3 * stop], eye_local[first:stop],
                     eye_centre[e], eye_rot[t, e], eye_thrust[t, e])
        if jaw_on[t]:
            _jaw(o, jaw_cols, jaw_pivot, jaw[t])
        if head_on[t]:
            _neck(o, neck_cols, head_pivot, neck_cross[t], neck_sin[t], neck_vers[t], scratch)
            _head(o, spans, head_pivot, head_turned[t])
            for k in range(neck_cols.shape[0]):
                o[neck_cols[k]] = scratch[k]
