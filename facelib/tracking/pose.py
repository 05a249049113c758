"""Rigid head pose from stable landmarks: a similarity fit per frame (Umeyama 1991).

Each frame's stable points ``Y`` are fitted as ``Y ≈ s R X + t`` to the neutral points ``X``
(least squares, ``det R = +1``); undoing the fit puts every landmark back in the neutral
head's frame, so head turns, distance to the camera and translation no longer change the
other FAPs (the seed's method only corrects translation, section 4.3.2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.errors import TrackingError

__all__ = ["HeadPose", "euler_angles", "fit_pose", "unpose"]


@dataclass(frozen=True)
class HeadPose:
    """Per-frame similarity transforms from the neutral head to each frame.

    Attributes
    ----------
    scale: ``(n,) float64``.
    rotation: ``(n, D, D) float64``, proper rotations.
    translation: ``(n, D) float64``, in the points' unit.
    """

    scale: np.ndarray
    rotation: np.ndarray
    translation: np.ndarray


def fit_pose(neutral: np.ndarray, frames: np.ndarray) -> HeadPose:
    """Fit ``frames[i] ≈ s_i R_i neutral + t_i``.

    Parameters
    ----------
    neutral: ``(S, D)`` stable points of the neutral head, D = 2 or 3, S > D.
    frames: ``(n, S, D)`` the same points in each frame.
    """
    neutral = np.asarray(neutral, np.float64)
    frames = np.asarray(frames, np.float64)
    s_count, dim = neutral.shape
    if s_count <= dim:
        raise TrackingError(f"a rigid fit in {dim}-D needs more than {dim} stable points, "
                            f"got {s_count}")
    mu_x = neutral.mean(axis=0)
    mu_y = frames.mean(axis=1)
    x = neutral - mu_x
    y = frames - mu_y[:, None, :]
    var_x = float((x**2).sum()) / s_count
    cov = np.einsum("nsi,sj->nij", y, x) / s_count
    u, sig, vt = np.linalg.svd(cov)
    sign = np.ones((len(frames), dim))
    sign[:, -1] = np.sign(np.linalg.det(u) * np.linalg.det(vt))
    sign[sign == 0] = 1.0
    rotation = np.einsum("nij,nj,njk->nik", u, sign, vt)
    scale = (sig * sign).sum(axis=1) / var_x
    translation = mu_y - scale[:, None] * np.einsum("nij,j->ni", rotation, mu_x)
    return HeadPose(scale, rotation, translation)


def unpose(points: np.ndarray, pose: HeadPose) -> np.ndarray:
    """``(n, P, D)`` points -> the neutral head's frame: ``R^T (p - t) / s``."""
    moved = np.asarray(points, np.float64) - pose.translation[:, None, :]
    return np.einsum("npi,nij->npj", moved, pose.rotation) / pose.scale[:, None, None]


def euler_angles(rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(pitch, yaw, roll)`` radians, each ``(n,)``, with ``R = R_y(yaw) R_x(pitch) R_z(roll)``
    (the engine's convention, :func:`facelib.engine.rigid.rotation_matrices`).

    ``(n, 2, 2)`` rotations (2-D tracks) give only roll; pitch and yaw are 0.
    """
    rotation = np.asarray(rotation, np.float64)
    if rotation.shape[1:] == (2, 2):
        roll = np.arctan2(rotation[:, 1, 0], rotation[:, 0, 0])
        zero = np.zeros(len(rotation))
        return zero, zero.copy(), roll
    pitch = np.arcsin(np.clip(-rotation[:, 1, 2], -1.0, 1.0))
    yaw = np.arctan2(rotation[:, 0, 2], rotation[:, 2, 2])
    roll = np.arctan2(rotation[:, 1, 0], rotation[:, 1, 1])
    return pitch, yaw, roll
