"""The thin-plate spline warp of face set-up (third seed, eq. 4.1-4.5).

A warp ``T`` maps 3-D points so that ``T(source_i) = target_i`` exactly for every landmark
pair, with the least bending energy. Per output coordinate::

    T_c(x) = sum_i w_ic U(|x - source_i|) + a_1c + a_xc x + a_yc y + a_zc z       (4.1)

with ``U(r) = r``, the fundamental solution of the biharmonic equation in three dimensions,
and the side condition ``P^T W = 0`` (eq. 4.2-4.5). The system is solved by
:class:`scipy.interpolate.RBFInterpolator` (its ``"linear"`` kernel is ``-r``, the same
space of functions; ``"thin_plate_spline"``, ``r^2 log r``, the two-dimensional kernel, is
offered as an option). The coefficients ``W`` and ``A`` are read back in the seed's
convention for the analytic Jacobian and the bending energy. The general RBF weights of the
deformers (any kernel, fitted on the identity) are :mod:`facelib.engine.deformers.rbf`; its ``warp``
gives the same map (a test checks it), without the coefficients this module needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.interpolate import RBFInterpolator

from facelib.errors import FaceModelError, ParameterError

__all__ = ["KERNELS", "ThinPlateSpline", "check_landmarks", "fit_tps"]

# kernel name (scipy's) -> sign that turns scipy's phi(r) into the seed's U(r)
KERNELS = {"linear": -1.0, "thin_plate_spline": 1.0}


def _kernel(r: np.ndarray, kernel: str) -> np.ndarray:
    """U(r) of the seed's convention: ``r`` or ``r^2 log r`` (0 at r = 0)."""
    if kernel == "linear":
        return r
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(r > 0, r * r * np.log(np.where(r > 0, r, 1.0)), 0.0)


def _kernel_gradient_factor(r: np.ndarray, kernel: str) -> np.ndarray:
    """``U'(r) / r``, so that ``grad U(|x - p|) = factor * (x - p)``; 0 at r = 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        if kernel == "linear":
            return np.where(r > 0, 1.0 / np.where(r > 0, r, 1.0), 0.0)
        return np.where(r > 0, 2.0 * np.log(np.where(r > 0, r, 1.0)) + 1.0, 0.0)


def check_landmarks(points: np.ndarray, *, what: str = "landmarks") -> np.ndarray:
    """Validate landmark positions for a TPS fit; ``(n, 3)`` float64 out.

    Raises FaceModelError for fewer than 4 points, non-finite values, two points closer
    than 1e-9 of the landmarks' extent, or points that lie in one plane (rank < 3), each
    of which makes the system (4.2) singular.
    """
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise FaceModelError(f"{what} must be (n, 3) points, got shape {pts.shape}")
    if len(pts) < 4:
        raise FaceModelError(f"{what}: {len(pts)} given, a 3-D warp needs at least 4 that do "
                             "not lie in one plane (20-35 are recommended)")
    if not np.all(np.isfinite(pts)):
        raise FaceModelError(f"{what} contain a non-finite coordinate")
    extent = float(np.ptp(pts, axis=0).max())
    from scipy.spatial import cKDTree

    close = cKDTree(pts).query_pairs(max(extent, 1e-300) * 1e-9, output_type="ndarray")
    if len(close):
        i, j = (int(k) for k in close[0])
        raise FaceModelError(f"{what} {i} and {j} are at the same position {pts[i].tolist()}; "
                             "each landmark must be a different point")
    centred = pts - pts.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    if sv[2] <= 1e-6 * sv[0]:
        raise FaceModelError(f"{what} all lie in one plane (or on one line); add points off "
                             "that plane, e.g. the nose tip and the ears")
    return pts


@dataclass(frozen=True, eq=False)
class ThinPlateSpline:
    """A fitted warp (eq. 4.1).

    source: (n, 3) float64 landmark positions on the source.
    target: (n, 3) float64 landmark positions on the target.
    weights: (n, 3) float64, ``W`` of eq. 4.2 (kernel weights ``w_ic``).
    affine: (4, 3) float64, ``A`` of eq. 4.4, rows ``(a_1, a_x, a_y, a_z)``.
    kernel: ``"linear"`` (``U = r``, the seed's) or ``"thin_plate_spline"``.
    """

    source: np.ndarray
    target: np.ndarray
    weights: np.ndarray
    affine: np.ndarray
    kernel: str
    interpolator: Any

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Warp points: ``(m, 3) -> (m, 3)`` float64 (O(m n))."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if not len(pts):
            return np.zeros((0, 3))
        return np.asarray(self.interpolator(pts), dtype=np.float64)

    def jacobian(self, points: np.ndarray) -> np.ndarray:
        """Analytic Jacobian ``dT_c / dx_k``: ``(m, 3) -> (m, 3, 3)`` float64 ``[i, c, k]``."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        diff = pts[:, None, :] - self.source[None, :, :]  # (m, n, 3)
        factor = _kernel_gradient_factor(np.linalg.norm(diff, axis=2), self.kernel)
        kernel_part = np.einsum("mn,nc,mnk->mck", factor, self.weights, diff)
        return kernel_part + self.affine[1:].T[None]

    def bending_energy(self) -> float:
        """Bending energy of the fit (non-negative; 0 exactly for an affine warp).

        ``-sum_c w_c^T K w_c`` for ``U = r`` (``K`` of eq. 4.2), ``+sum_c w_c^T K w_c``
        for ``r^2 log r``: the quadratic form on which the kernel is definite.
        """
        k = _kernel(np.linalg.norm(self.source[:, None] - self.source[None], axis=2),
                    self.kernel)
        return float(KERNELS[self.kernel] * np.einsum("ic,ij,jc->", self.weights, k,
                                                      self.weights))


def fit_tps(source: np.ndarray, target: np.ndarray, *, kernel: str = "linear",
            smoothing: float = 0.0) -> ThinPlateSpline:
    """Fit the warp with ``T(source_i) = target_i`` (eq. 4.2); ``(n, 3)`` each.

    ``smoothing`` > 0 gives the approximating spline (``K + smoothing I``); 0 interpolates.
    Raises FaceModelError for landmark sets that make the system singular (see
    :func:`check_landmarks`) and ParameterError for an unknown kernel.
    """
    if kernel not in KERNELS:
        raise ParameterError(f"kernel {kernel!r} is not one of {tuple(KERNELS)}")
    src = check_landmarks(source, what="source landmarks")
    dst = np.asarray(target, dtype=np.float64)
    if dst.shape != src.shape or not np.all(np.isfinite(dst)):
        raise FaceModelError(f"target landmarks must be finite with shape {src.shape}, got "
                             f"{dst.shape}")
    interp = RBFInterpolator(src, dst, kernel=kernel, degree=1, smoothing=smoothing)
    weights, affine = _coefficients(interp, len(src), kernel)
    return ThinPlateSpline(source=src, target=dst, weights=weights, affine=affine,
                           kernel=kernel, interpolator=interp)


def _coefficients(interp: Any, n: int, kernel: str) -> tuple[np.ndarray, np.ndarray]:
    """``W (n, 3)`` and ``A (4, 3)`` of eq. 4.1 from a fitted RBFInterpolator.

    scipy evaluates its polynomial on ``(x - shift) / scale`` with monomial ``powers``;
    this rewrites it as ``a_1 + a_x x + a_y y + a_z z`` and flips the kernel's sign.
    """
    coeffs = np.asarray(interp._coeffs, dtype=np.float64)
    shift = np.asarray(interp._shift, dtype=np.float64)
    scale = np.asarray(interp._scale, dtype=np.float64)
    powers = np.asarray(interp.powers)
    if float(interp.epsilon) != 1.0:
        raise ParameterError(f"the TPS needs kernel scale 1, got epsilon={interp.epsilon}")
    weights = coeffs[:n] * KERNELS[kernel]
    affine = np.zeros((4, coeffs.shape[1]))
    for row, power in zip(coeffs[n:], powers, strict=True):
        if power.sum() == 0:
            affine[0] += row
        else:
            k = int(np.argmax(power))
            affine[1 + k] += row / scale[k]
            affine[0] -= row * shift[k] / scale[k]
    return weights, affine
