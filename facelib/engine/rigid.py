"""Rotations for the rigid and hinged parts: eyeballs, eyelids, jaw, head.

Angles are radians, arrays carry a leading frame axis ``n``. Conventions (face frame: +x the
face's left, +y up, +z out of the face): a positive rotation about +x turns the front (+z)
down, about +y turns it to the face's left, about +z tips the top (+y) to the face's right.
These match the positive directions of FAPs 23-26 and 48-50.
"""

from __future__ import annotations

import numpy as np

__all__ = ["axis_angle", "hinge_angle", "rotate_about_x", "rotate_weighted",
           "rotation_matrices"]


def rotation_matrices(pitch: np.ndarray, yaw: np.ndarray, roll: np.ndarray) -> np.ndarray:
    """``R = R_y(yaw) @ R_x(pitch) @ R_z(roll)`` per frame.

    Parameters
    ----------
    pitch, yaw, roll: (n,) float, radians.

    Returns
    -------
    (n, 3, 3) float64.
    """
    cp, sp = np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    cr, sr = np.cos(roll), np.sin(roll)
    n = np.broadcast(pitch, yaw, roll).shape
    one, zero = np.ones(n), np.zeros(n)
    rx = np.stack([np.stack([one, zero, zero], -1), np.stack([zero, cp, -sp], -1),
                   np.stack([zero, sp, cp], -1)], -2)
    ry = np.stack([np.stack([cy, zero, sy], -1), np.stack([zero, one, zero], -1),
                   np.stack([-sy, zero, cy], -1)], -2)
    rz = np.stack([np.stack([cr, -sr, zero], -1), np.stack([sr, cr, zero], -1),
                   np.stack([zero, zero, one], -1)], -2)
    return ry @ rx @ rz


def hinge_angle(point: np.ndarray, pivot: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Rotation about the x axis through ``pivot`` that moves ``point`` by ``dy`` vertically.

    The point keeps its distance to the axis, so a target beyond the circle is clamped to the
    lowest (or highest) point of the circle.

    Parameters
    ----------
    point, pivot: (3,) float, positions.
    dy: (n,) float, the wanted vertical displacement of ``point``.

    Returns
    -------
    (n,) float64 angle (positive turns the front down, see :func:`rotate_about_x`).
    """
    y, z = float(point[1] - pivot[1]), float(point[2] - pivot[2])
    rho = np.hypot(y, z)
    phi = np.arctan2(y, z)
    target = np.clip((y + np.asarray(dy, dtype=np.float64)) / rho, -1.0, 1.0)
    return phi - np.arcsin(target)


def rotate_about_x(
    y: np.ndarray, z: np.ndarray, pivot_y: np.ndarray, pivot_z: np.ndarray, angles: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rotate points about x axes through pivots, each point by its own angle.

    Parameters
    ----------
    y, z: (n, K) float coordinates of the points.
    pivot_y, pivot_z: scalars, or (K,) with a pivot per point.
    angles: (n, K) float radians, or (n, 1) for one angle per frame; positive moves points
        in front of the pivot down.

    Returns
    -------
    The rotated ``(y, z)``, each (n, K) in the dtype of ``y``.
    """
    angles = np.asarray(angles, dtype=y.dtype)
    c, s = np.cos(angles), np.sin(angles)
    y = y - pivot_y
    z = z - pivot_z
    return y * c - z * s + pivot_y, y * s + z * c + pivot_z


def axis_angle(rotations: np.ndarray, dtype: type = np.float32) -> tuple[np.ndarray, np.ndarray]:
    """Each rotation's unit axis, as a cross-product matrix, and its angle.

    Parameters
    ----------
    rotations: (n, 3, 3) rotation matrices.
    dtype: the float type of the matrices returned.

    Returns
    -------
    ``cross`` (n, 3, 3) ``dtype``, with ``v @ cross[i]`` the cross product of frame i's unit
    axis with ``v`` (zero where the rotation is none); ``angle`` (n,) float64 radians.
    """
    trace = np.clip((np.trace(rotations, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(trace)
    x, y, z = (rotations[:, 2, 1] - rotations[:, 1, 2], rotations[:, 0, 2] - rotations[:, 2, 0],
               rotations[:, 1, 0] - rotations[:, 0, 1])
    norm = np.sqrt(x * x + y * y + z * z)
    scale = np.divide(1.0, norm, out=np.zeros_like(norm), where=norm > 1e-15)
    x, y, z = x * scale, y * scale, z * scale
    zero = np.zeros_like(x)
    # v @ cross[i] is axis[i] x v
    cross: np.ndarray = np.stack([np.stack([zero, z, -y], -1), np.stack([-z, zero, x], -1),
                                  np.stack([y, -x, zero], -1)], -2).astype(dtype)
    return cross, angle


def rotate_weighted(
    points: np.ndarray, pivot: np.ndarray, rotations: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """Rotate points about ``pivot`` by a fraction ``weights`` of each frame's rotation.

    The fraction scales the rotation angle about the rotation's own axis (Rodrigues' formula),
    so a weight of 1 applies the full rotation and 0 leaves the point still.

    Parameters
    ----------
    points: (n, K, 3) float positions.
    pivot: (3,) float.
    rotations: (n, 3, 3) rotation matrices.
    weights: (K,) float in [0, 1].

    Returns
    -------
    (n, K, 3), the dtype of ``points``.
    """
    cross, angle = axis_angle(rotations, points.dtype.type)
    phi = (angle[:, None] * weights[None, :]).astype(points.dtype)  # (n, K)
    pivot = np.asarray(pivot, dtype=points.dtype)
    v = points - pivot
    kv = v @ cross
    kkv = kv @ cross  # axis x (axis x v)
    kv *= np.sin(phi)[..., None]
    kkv *= (1.0 - np.cos(phi))[..., None]
    v += kv
    v += kkv
    v += pivot
    return v
