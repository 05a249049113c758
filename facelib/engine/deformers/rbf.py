"""Radial basis function interpolation as linear weights (Peña Araya eq. 2.17-2.21).

An RBF interpolant through sources ``s_i`` with values ``g_i`` is
``s(x) = sum_i alpha_i phi(|x - s_i|) + p(x)`` with ``p`` a polynomial of degree ``k`` and the
side condition ``sum_i alpha_i q(s_i) = 0`` for every polynomial ``q`` of degree ``<= k``
(eq. 2.18-2.21). The interpolant is linear in ``g``, so fitting the identity (source ``j``
has value ``e_j``) gives the weights ``W (P, S)`` with ``s(x) = W(x) @ g`` for *any* values:
one solve serves every frame, every coordinate and every FAP. The same system with
``phi(r) = r`` (or ``r^2 log r``) and an affine ``p`` is the thin-plate-spline warp of
Orvalho's rig transfer, so both use :func:`interpolation_weights` and :func:`warp`.

Kernels are scipy's :class:`~scipy.interpolate.RBFInterpolator` ones, plus two that scipy
lacks and facelib solves itself: ``"multiquadric_eck"``, the per-source multiquadric of
facelib's own thesis (eq. 4.8-4.10), ``phi_j(r) = sqrt(r^2 + sc_j^2)`` with ``sc_j`` the
distance from ``s_j`` to its nearest other source, which no single shape parameter
expresses; and ``"wendland"``, Wendland's compactly supported C2 function ``phi(r) = (1 -
r/rho)_+^4 (4 r/rho + 1)`` (positive definite in 3-D; one of the bases Jakobsson & Amoignon
compare, second seed section 2.4.4) with support ``rho = 1 / epsilon``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.distance import cdist

from facelib.engine.deformers.base import Deformer, RegionSetup
from facelib.errors import FaceModelError

__all__ = ["KERNELS", "RBF", "interpolation_weights", "warp"]

SCIPY_KERNELS = ("linear", "thin_plate_spline", "cubic", "quintic", "multiquadric",
                 "inverse_multiquadric", "inverse_quadratic", "gaussian")
KERNELS = ("multiquadric_eck", "wendland", *SCIPY_KERNELS)
"""Kernel names accepted by :func:`interpolation_weights`."""

_SHAPED = ("multiquadric", "inverse_multiquadric", "inverse_quadratic", "gaussian")


def _nearest_other(sources: np.ndarray) -> np.ndarray:
    """``(S,)`` distance from each source to its nearest other source."""
    d = cdist(sources, sources)
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def _polynomial(points: np.ndarray, degree: int) -> np.ndarray:
    """``(P, 0 | 1 | 4)`` monomials of degree ``<= degree`` (at most 1) at ``points (P, 3)``."""
    if degree < 0:
        return np.zeros((len(points), 0))
    if degree == 0:
        return np.ones((len(points), 1))
    return np.hstack([np.ones((len(points), 1)), points])


def _wendland(r: np.ndarray, support: float) -> np.ndarray:
    t = np.clip(r / support, 0.0, 1.0)
    return (1.0 - t) ** 4 * (4.0 * t + 1.0)


def _own_weights(kernel: str, sources: np.ndarray, points: np.ndarray, *, degree: int,
                 smoothing: float, support: float) -> np.ndarray:
    """Solve the system of eq. 2.20-2.21 directly (kernels scipy does not have)."""
    if kernel == "wendland":
        h = _wendland(cdist(sources, sources), support)
        hx = _wendland(cdist(points, sources), support)
    else:
        sc = _nearest_other(sources)
        h = np.sqrt(cdist(sources, sources) ** 2 + sc[None, :] ** 2)
        hx = np.sqrt(cdist(points, sources) ** 2 + sc[None, :] ** 2)
    if smoothing:
        h = h + smoothing * np.eye(len(sources))
    try:
        if degree < 0:
            # points @ H^-1: the system of eq. 4.9-4.10 without a polynomial
            return np.linalg.solve(h.T, hx.T).T
        p = _polynomial(sources, degree)
        n, m = p.shape
        system = np.block([[h, p], [p.T, np.zeros((m, m))]])
        rhs = np.hstack([hx, _polynomial(points, degree)])
        return np.linalg.solve(system.T, rhs.T).T[:, :n]
    except np.linalg.LinAlgError as exc:
        raise FaceModelError(f"RBF system is singular: {exc}") from exc


def interpolation_weights(
    sources: np.ndarray,
    points: np.ndarray,
    *,
    kernel: str = "thin_plate_spline",
    degree: int = 1,
    smoothing: float = 0.0,
    epsilon: float | None = None,
) -> np.ndarray:
    """Weights of the RBF interpolant through ``sources``, evaluated at ``points``.

    Parameters
    ----------
    sources: (S, 3) float, distinct source positions.
    points: (P, 3) float, where to evaluate.
    kernel: one of :data:`KERNELS`.
    degree: polynomial degree: -1 (none), 0 (constant) or 1 (affine, eq. 2.17).
    smoothing: >= 0; 0 interpolates, larger values approximate (scipy's ``smoothing``).
    epsilon: shape parameter of the shaped kernels (1 / length); None takes 1 / the median
        distance from a source to its nearest other source, so the result is unit-free.
        For ``wendland`` the support is ``1 / epsilon``; None takes the largest distance
        between two sources (every source then reaches every other).

    Returns
    -------
    (P, S) float64 ``W`` with ``value(points) = W @ values(sources)``. Rows sum to 1 when
    ``degree >= 0``; ``W`` at the sources is the identity when ``smoothing == 0``.

    Raises
    ------
    FaceModelError: unknown kernel, fewer than two or duplicate sources, a singular system.
    """
    src = np.asarray(sources, dtype=np.float64)
    pts = np.asarray(points, dtype=np.float64)
    if kernel not in KERNELS:
        raise FaceModelError(f"RBF kernel {kernel!r} is unknown; known: {', '.join(KERNELS)}")
    if degree not in (-1, 0, 1):
        raise FaceModelError(f"RBF polynomial degree must be -1, 0 or 1, got {degree!r}")
    if not (np.isfinite(smoothing) and smoothing >= 0):
        raise FaceModelError(f"RBF smoothing must be >= 0, got {smoothing!r}")
    gap = _nearest_other(src) if len(src) > 1 else np.zeros(1)
    if len(src) < 2 or not np.all(gap > 0):
        raise FaceModelError("RBF sources must be at least two distinct points")
    if kernel in ("multiquadric_eck", "wendland"):
        support = (float(cdist(src, src).max()) if epsilon is None else 1.0 / float(epsilon))
        return _own_weights(kernel, src, pts, degree=degree, smoothing=smoothing,
                            support=support)
    from scipy.interpolate import RBFInterpolator

    eps = 1.0 / float(np.median(gap)) if epsilon is None else float(epsilon)
    try:
        fit = RBFInterpolator(src, np.eye(len(src)), kernel=kernel, degree=degree,
                              smoothing=smoothing, epsilon=eps if kernel in _SHAPED else 1.0)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise FaceModelError(f"RBF fit failed ({kernel}, degree {degree}): {exc}") from exc
    return np.asarray(fit(pts), dtype=np.float64)


def warp(sources: np.ndarray, targets: np.ndarray, points: np.ndarray, **options: object
         ) -> np.ndarray:
    """Move ``points (P, 3)`` by the RBF map taking ``sources (S, 3)`` to ``targets (S, 3)``.

    The default (thin-plate spline, affine polynomial) is the TPS warp of landmark-based
    rig transfer; ``options`` are those of :func:`interpolation_weights`.
    Returns (P, 3) float64.
    """
    w = interpolation_weights(sources, points, **options)  # type: ignore[arg-type]
    return w @ np.asarray(targets, dtype=np.float64)


def _rbf(setup: RegionSetup) -> np.ndarray:
    p = setup.params
    pos = setup.vertices
    sources = pos[np.concatenate([setup.controls, setup.anchors])]
    kernel = str(p["kernel"])
    degree = p["polynomial"]
    if degree is None:
        degree = -1 if kernel == "multiquadric_eck" else 1
    try:
        w = interpolation_weights(sources, pos[setup.members], kernel=kernel,
                                  degree=int(degree), smoothing=float(p["smoothing"]),
                                  epsilon=p["epsilon"])
    except FaceModelError as exc:
        raise setup.fail(exc.message) from exc
    # anchors stay still: only the control columns carry motion
    return w[:, : setup.controls.size]


RBF = Deformer(
    "rbf", _rbf,
    {"kernel": "multiquadric_eck", "polynomial": None, "smoothing": 0.0, "epsilon": None},
    "radial basis functions through controls and static anchors",
    "second seed eq. 2.17-2.21; first seed eq. 4.8-4.10 (kernel multiquadric_eck)")
