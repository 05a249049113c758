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

__all__ = ["HEAD_FAP_IDS", "HeadPose", "euler_angles", "fit_pose", "join_poses",
           "refine_pose_2d", "unpose", "unpose_2d"]

HEAD_FAP_IDS = (48, 49, 50)
"""FAP ids (1-based; column = id - 1) of head pitch, yaw and roll, the order of
:func:`euler_angles`. Not :data:`facelib.sync.combine.HEAD_FAPS`, which holds columns."""


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


def _skew(v: np.ndarray) -> np.ndarray:
    """``(S, 3)`` vectors -> ``(S, 3, 3)`` cross-product matrices ``[v]x``."""
    out = np.zeros((*v.shape, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def refine_pose_2d(neutral: np.ndarray, frames: np.ndarray, pose: HeadPose, *,
                   iterations: int = 6) -> HeadPose:
    """Refine a 3-D pose against the image coordinates only (weak perspective).

    A tracker's per-frame depth is much noisier than its ``x, y`` (MediaPipe's ``z`` moves
    with expressions), so the neutral shape's depth is trusted and each frame's depth
    ignored: Gauss-Newton on ``min Σ |(s R X + t)_xy - Y_xy|^2`` over rotation, scale and
    ``x, y`` translation, for all frames at once. The depth of the translation is kept.

    Parameters
    ----------
    neutral: ``(S, 3)`` neutral stable points; frames: ``(n, S, 3)`` (``z`` unused).
    pose: the starting fit (:func:`fit_pose`).
    """
    x = np.asarray(neutral, np.float64)
    y = np.asarray(frames, np.float64)[..., :2]
    rot, scale, trans = pose.rotation.copy(), pose.scale.copy(), pose.translation.copy()
    skew = _skew(x)
    for _ in range(iterations):
        rx = np.einsum("nij,sj->nsi", rot, x)
        resid = (scale[:, None, None] * rx[..., :2] + trans[:, None, :2]) - y
        d_rot = -scale[:, None, None, None] * np.einsum("nij,sjk->nsik", rot, skew)[..., :2, :]
        jac = np.concatenate([d_rot, rx[..., :2, None], np.broadcast_to(
            np.eye(2), (*rx.shape[:2], 2, 2))], axis=3)  # (n, S, 2, 6)
        jac = jac.reshape(len(y), -1, 6)
        step = np.linalg.solve(np.einsum("nki,nkj->nij", jac, jac) + 1e-9 * np.eye(6),
                               -np.einsum("nki,nk->ni", jac, resid.reshape(len(y), -1))[..., None]
                               )[..., 0]
        w = step[:, :3]
        angle = np.linalg.norm(w, axis=1)
        axis = w / np.where(angle > 0, angle, 1.0)[:, None]
        k = _skew(axis)
        exp = (np.eye(3) + np.sin(angle)[:, None, None] * k
               + (1 - np.cos(angle))[:, None, None] * (k @ k))
        rot = rot @ exp
        scale = scale + step[:, 3]
        trans[:, :2] += step[:, 4:]
    return HeadPose(scale, rot, trans)


def join_poses(poses: list[HeadPose]) -> HeadPose:
    """The fits of consecutive stretches of a track (at least one) as one."""
    return HeadPose(np.concatenate([p.scale for p in poses]),
                    np.concatenate([p.rotation for p in poses]),
                    np.concatenate([p.translation for p in poses]))


def unpose(points: np.ndarray, pose: HeadPose) -> np.ndarray:
    """``(n, P, D)`` points -> the neutral head's frame: ``R^T (p - t) / s``."""
    moved = np.asarray(points, np.float64) - pose.translation[:, None, :]
    return moved @ pose.rotation / pose.scale[:, None, None]


def unpose_2d(points: np.ndarray, rest: np.ndarray, pose: HeadPose) -> np.ndarray:
    """``(n, K, 3)`` points -> the neutral head's frame from their image ``x, y`` only.

    Each point is taken to sit at its neutral position ``rest`` ``(K, 3)`` plus a motion in
    the face's x-y plane, seen through the weak-perspective pose: the image offset from
    where the neutral point would appear, ``p - (s R X + t)``, divided by ``s R[:2, :2]``.
    The tracker's per-frame depth is never used (see :func:`refine_pose_2d`).
    """
    rest = np.asarray(rest, np.float64)
    predicted = (pose.scale[:, None, None] * (rest @ pose.rotation.transpose(0, 2, 1))
                 + pose.translation[:, None, :])  # matmul: a fifth of einsum's time here
    offset = np.asarray(points, np.float64)[..., :2] - predicted[..., :2]
    block = pose.scale[:, None, None] * pose.rotation[:, :2, :2]
    local = np.broadcast_to(rest, np.shape(points)).copy()
    local[..., :2] += offset @ np.linalg.inv(block).transpose(0, 2, 1)
    return local


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
