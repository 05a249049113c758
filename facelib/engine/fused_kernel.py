"""The compiled half of :mod:`facelib.engine.fused`: one pass per frame over its output.

Imported only by :func:`facelib.engine.fused.available`, the first time a face deforms with
numba installed (never by ``import facelib``); ``cache=True`` keeps the machine code beside
this file (or in numba's user cache where that folder is read-only), so later processes load
it instead of compiling it again.

Per frame: the rest shape, plus the operator's runs, into the output row; then the rigid
steps on that row while it is in the CPU cache. Every index is ``uint64``: numba then emits
no negative-index wrap-around and LLVM vectorises the loops. A vertex set is a ``(S, 3+)``
array of spans (first vertex, stop vertex, index of the first in the set's per-vertex
arrays, ...). Arithmetic mirrors the numpy path's dtypes step by step (float32, with the
jaw's float64 intermediates), without fused multiply-adds; sines and cosines are a float64
series rounded to float32 (vectorisable, unlike a call into libm).

Measured while writing it: cutting the mesh into tiles that a block of frames goes through
together (to keep each tile's inputs in the cache) was slower, the calls per tile and the
strided writes costing more than the reuse saved.
"""

# numba kernels take their arrays positionally (keyword-only arguments do not compile)
# ruff: noqa: PLR0917

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["deform_frames"]

_U1, _U2, _U3 = np.uint64(1), np.uint64(2), np.uint64(3)
# sin and cos of |r| <= pi/4 by their Taylor series (the first terms left out are under
# 3e-14 there, far below float32's rounding)
_S3, _S5, _S7, _S9, _S11, _S13 = (-1 / 6, 1 / 120, -1 / 5040, 1 / 362880, -1 / 39916800,
                                  1 / 6227020800)
_C2, _C4, _C6, _C8, _C10, _C12, _C14 = (-1 / 2, 1 / 24, -1 / 720, 1 / 40320, -1 / 3628800,
                                        1 / 479001600, -1 / 87178291200)
_PIO2_HI, _PIO2_LO = 1.5707963267341256, 6.077100506506192e-11  # pi/2 in two parts


@njit(cache=True, nogil=True, inline="always")
def _sincos(x):
    """``(sin x, cos x)`` in float64 for ``|x|`` up to about 1e5, branch-free (so that loops
    calling it vectorise): the quadrant ``q`` by rounding, then the series about it."""
    q = np.floor(x * (2 / np.pi) + 0.5)
    r = (x - q * _PIO2_HI) - q * _PIO2_LO
    r2 = r * r
    s = r + r * r2 * (_S3 + r2 * (_S5 + r2 * (_S7 + r2 * (_S9 + r2 * (_S11 + r2 * _S13)))))
    c = 1.0 + r2 * (_C2 + r2 * (_C4 + r2 * (_C6 + r2 * (_C8 + r2 * (_C10 + r2 * (
        _C12 + r2 * _C14))))))
    m = q - 4.0 * np.floor(q * 0.25)  # the quadrant, 0-3
    odd = (m == 1.0) | (m == 3.0)
    sin = c if odd else s
    cos = s if odd else c
    if m >= 2.0:
        sin = -sin
    if (m == 1.0) | (m == 2.0):
        cos = -cos
    return sin, cos


@njit(cache=True, nogil=True)
def _product(o, ft, runs, data, lo, hi):
    """``o (3V,) += ft @ A`` over runs ``lo:hi``: rows of ``runs`` (R, 4) uint64 are (first
    column, stop column, offset into ``data`` (float32), FAP column)."""
    for r in range(lo, hi):
        fk = ft[runs[r, 3]]
        if fk != 0.0:
            first, at = runs[r, 0], runs[r, 2]
            for c in range(first, runs[r, 1]):
                o[c] += data[at + (c - first)] * fk


@njit(cache=True, nogil=True)
def _lid_trig(weights, angles, total, cos, sin):
    """Each lid vertex's angle: its regions' ``angles`` (R,) float64 weighted by ``weights``
    (R, K) float64, added in region order into ``total`` (K,) float64; its cosine and sine
    into ``cos``, ``sin`` (K,) float32 (of the angle rounded to float32, as numpy's)."""
    total[:] = 0.0
    for j in range(weights.shape[0]):
        a = angles[j]
        for k in range(total.shape[0]):
            total[k] += a * weights[j, k]
    for k in range(total.shape[0]):
        s, c = _sincos(np.float64(np.float32(total[k])))
        sin[k], cos[k] = np.float32(s), np.float32(c)


@njit(cache=True, nogil=True)
def _lids(o, spans, lo, hi, pivots, cos, sin):
    """Turn the lid vertices of spans ``lo:hi`` about x by their ``cos``, ``sin`` (K,)
    float32, about their eye centres ``pivots`` (2, K) float32 (y, z)."""
    for r in range(lo, hi):
        first, at = spans[r, 0], spans[r, 2]
        for v in range(first, spans[r, 1]):
            i, k = _U3 * v, at + (v - first)
            y = o[i + _U1] - pivots[0, k]
            z = o[i + _U2] - pivots[1, k]
            o[i + _U1] = y * cos[k] - z * sin[k] + pivots[0, k]
            o[i + _U2] = y * sin[k] + z * cos[k] + pivots[1, k]


@njit(cache=True, nogil=True)
def _eyes(o, spans, lo, hi, local, centre, on, rot, thrust):
    """Place the eyeballs that move (``on`` (2,) bool) over spans ``lo:hi`` (the eye in
    column 3): a vertex is ``rot[e] @ local + (0, 0, thrust[e]) + centre[e]``, ``local``
    (E, 3) float32 its rest position about the eye's centre."""
    for r in range(lo, hi):
        first, at, e = spans[r, 0], spans[r, 2], spans[r, 3]
        if not on[e]:
            continue
        m, ce, forward = rot[e], centre[e], thrust[e]
        for v in range(first, spans[r, 1]):
            i, k = _U3 * v, at + (v - first)
            x, y, z = local[k, 0], local[k, 1], local[k, 2]
            o[i] = (x * m[0, 0] + y * m[0, 1] + z * m[0, 2]) + ce[0]
            o[i + _U1] = (x * m[1, 0] + y * m[1, 1] + z * m[1, 2]) + ce[1]
            o[i + _U2] = ((x * m[2, 0] + y * m[2, 1] + z * m[2, 2]) + forward) + ce[2]


@njit(cache=True, nogil=True)
def _jaw(o, spans, lo, hi, pivot, jaw):
    """Hinge the jaw's vertices (spans ``lo:hi``) about x through ``pivot`` (3,) float64;
    ``jaw`` (4,) float32 is cos, sin, the thrust and the shift. The turn runs in float64,
    as the numpy path's does."""
    c, s = np.float64(jaw[0]), np.float64(jaw[1])
    thrust, shift = np.float64(jaw[2]), jaw[3]
    py, pz = pivot[1], pivot[2]
    for r in range(lo, hi):
        for v in range(spans[r, 0], spans[r, 1]):
            i = _U3 * v
            y = np.float64(o[i + _U1]) - py
            z = np.float64(o[i + _U2]) - pz
            o[i + _U1] = np.float32(y * c - z * s + py)
            o[i + _U2] = np.float32((y * s + z * c + pz) + thrust)
            o[i] -= shift


@njit(cache=True, nogil=True)
def _neck(o, spans, lo, hi, pivot, weights, cross, angle, out):
    """The partly turned neck vertices of spans ``lo:hi`` (Rodrigues), into ``out`` (3K,)
    float32: vertex k turns about ``pivot`` (3,) by ``weights[k]`` (float32) of ``angle``
    (float64) about the axis whose cross-product matrix is ``cross`` (3, 3):
    ``v + (v @ cross) sin + (v @ cross @ cross) (1 - cos)``."""
    for r in range(lo, hi):
        first, at = spans[r, 0], spans[r, 2]
        for v in range(first, spans[r, 1]):
            i, k = _U3 * v, at + (v - first)
            sin64, cos64 = _sincos(np.float64(np.float32(angle * np.float64(weights[k]))))
            sin, vers = np.float32(sin64), np.float32(1.0) - np.float32(cos64)
            v0, v1, v2 = o[i] - pivot[0], o[i + _U1] - pivot[1], o[i + _U2] - pivot[2]
            k0 = v0 * cross[0, 0] + v1 * cross[1, 0] + v2 * cross[2, 0]
            k1 = v0 * cross[0, 1] + v1 * cross[1, 1] + v2 * cross[2, 1]
            k2 = v0 * cross[0, 2] + v1 * cross[1, 2] + v2 * cross[2, 2]
            kk0 = k0 * cross[0, 0] + k1 * cross[1, 0] + k2 * cross[2, 0]
            kk1 = k0 * cross[0, 1] + k1 * cross[1, 1] + k2 * cross[2, 1]
            kk2 = k0 * cross[0, 2] + k1 * cross[1, 2] + k2 * cross[2, 2]
            j = _U3 * k
            out[j] = v0 + k0 * sin + kk0 * vers + pivot[0]
            out[j + _U1] = v1 + k1 * sin + kk1 * vers + pivot[1]
            out[j + _U2] = v2 + k2 * sin + kk2 * vers + pivot[2]


@njit(cache=True, nogil=True)
def _put(o, spans, lo, hi, values):
    """Write ``values`` (3K,) float32 to the vertices of spans ``lo:hi``."""
    for r in range(lo, hi):
        first, at = spans[r, 0], spans[r, 2]
        for v in range(first, spans[r, 1]):
            i, j = _U3 * v, _U3 * (at + (v - first))
            o[i], o[i + _U1], o[i + _U2] = values[j], values[j + _U1], values[j + _U2]


@njit(cache=True, nogil=True)
def _head(o, spans, lo, hi, pivot, turned):
    """Turn the vertices of spans ``lo:hi`` about ``pivot`` (3,) float32 in place:
    ``p' = (p - pivot) @ turned + pivot``, ``turned`` (3, 3) float32 = R^T."""
    px, py, pz = pivot[0], pivot[1], pivot[2]
    t00, t01, t02 = turned[0, 0], turned[0, 1], turned[0, 2]
    t10, t11, t12 = turned[1, 0], turned[1, 1], turned[1, 2]
    t20, t21, t22 = turned[2, 0], turned[2, 1], turned[2, 2]
    for s in range(lo, hi):
        for v in range(spans[s, 0], spans[s, 1]):
            i = _U3 * v
            x, y, z = o[i] - px, o[i + _U1] - py, o[i + _U2] - pz
            o[i] = x * t00 + y * t10 + z * t20 + px
            o[i + _U1] = x * t01 + y * t11 + z * t21 + py
            o[i + _U2] = x * t02 + y * t12 + z * t22 + pz


@njit(cache=True, nogil=True)
def _start(o, rest, plain, busy, pivot, turned):
    """Start a turning frame: the vertices only the head moves (spans ``plain``) turned
    straight from ``rest`` (as :func:`_head` turns them), the others (``busy``) copied."""
    px, py, pz = pivot[0], pivot[1], pivot[2]
    t00, t01, t02 = turned[0, 0], turned[0, 1], turned[0, 2]
    t10, t11, t12 = turned[1, 0], turned[1, 1], turned[1, 2]
    t20, t21, t22 = turned[2, 0], turned[2, 1], turned[2, 2]
    for s in range(plain.shape[0]):
        for v in range(plain[s, 0], plain[s, 1]):
            i = _U3 * v
            x, y, z = rest[i] - px, rest[i + _U1] - py, rest[i + _U2] - pz
            o[i] = x * t00 + y * t10 + z * t20 + px
            o[i + _U1] = x * t01 + y * t11 + z * t21 + py
            o[i + _U2] = x * t02 + y * t12 + z * t22 + pz
    for s in range(busy.shape[0]):
        a, b = _U3 * busy[s, 0], _U3 * busy[s, 1]
        o[a:b] = rest[a:b]


@njit(cache=True, nogil=True)
def _rigid(o, lids, eyes, jaw, head, on):
    """The rigid steps of one frame on ``o`` (3V,): lids, eyes, jaw, head (each its argument
    tuple; ``on`` (lids, jaw, head) says which move this frame)."""
    if on[0]:
        spans, pivots, weights, angles, total, cos, sin = lids
        _lid_trig(weights, angles, total, cos, sin)
        _lids(o, spans, 0, spans.shape[0], pivots, cos, sin)
    spans, local, centre, moving, rot, thrust = eyes
    _eyes(o, spans, 0, spans.shape[0], local, centre, moving, rot, thrust)
    if on[1]:
        _jaw(o, jaw[0], 0, jaw[0].shape[0], jaw[1], jaw[2])
    if on[2]:
        spans, neck, pivot, weights, cross, angle, turned, scratch = head
        _neck(o, neck, 0, neck.shape[0], pivot, weights, cross, angle, scratch)
        _head(o, spans, 0, spans.shape[0], pivot, turned)
        _put(o, neck, 0, neck.shape[0], scratch)


@njit(cache=True, nogil=True)
def deform_frames(out, f, rest, runs, data,
                  lid_spans, lid_pivots, lid_weights, lid_on, lid_angles,
                  eye_spans, eye_local, eye_centre, eye_on, eye_rot, eye_thrust,
                  jaw_spans, jaw_pivot, jaw_on, jaw,
                  head_spans, plain_spans, busy_spans, neck_spans, neck_weights, head_pivot,
                  head_on, head_turned, neck_cross, neck_angle):
    """Deform ``out`` (n, 3V) float32 from ``f`` (n, 84) float32, frame by frame.

    ``head_spans`` are the vertices the head turns that another step moves too (those it
    alone moves, ``plain_spans``, it turns from the rest shape; ``busy_spans`` are all but
    those). The ``*_on`` (n,) flags say which steps move each frame; the per-frame terms are
    :func:`facelib.engine.fused.deform`'s, the constant ones those of
    :class:`facelib.engine.fused.Plan` (shapes there).
    """
    k = lid_weights.shape[1]
    total = np.zeros(k)
    cos, sin = np.zeros(k, np.float32), np.zeros(k, np.float32)
    scratch = np.empty(3 * neck_weights.shape[0], np.float32)
    for t in range(out.shape[0]):
        o = out[t]
        if head_on[t]:
            _start(o, rest, plain_spans, busy_spans, head_pivot, head_turned[t])
        else:
            o[:] = rest
        _product(o, f[t], runs, data, 0, runs.shape[0])
        _rigid(o, (lid_spans, lid_pivots, lid_weights, lid_angles[t], total, cos, sin),
               (eye_spans, eye_local, eye_centre, eye_on[t], eye_rot[t], eye_thrust[t]),
               (jaw_spans, jaw_pivot, jaw[t]),
               (head_spans, neck_spans, head_pivot, neck_weights, neck_cross[t],
                neck_angle[t], head_turned[t], scratch),
               (lid_on[t], jaw_on[t], head_on[t]))
