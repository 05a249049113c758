"""The midline profile of a head mesh, and feature points placed on it by its shape.

MediaPipe's face model places the chin where a human's would be, so on a face with a long
chin (a cartoon) the automatic chin points land centimetres too high, and it puts the nose
tip a few millimetres off the most prominent point. The midline profile says where these
points are from the mesh's own shape:

- the profile is the outer surface cut by the midline plane, found by a fan of rays from a
  point behind the mouth (the last hit of each ray: the outside, not the mouth lining),
  resampled evenly along its length, with the direction of its outward normal ``theta``
  (degrees; 0 looking forward, -90 down) from the chord over a few millimetres;
- 9.3 (nose tip): the most prominent profile point above the mouth;
- 2.1 (chin): walking up from straight below the mouth (the underside of the chin), the
  first point whose normal turns as far forward as the source face's does at its 2.1;
- 2.10 (chin boss): walking on up, the first point as far forward as the source's 2.10;
- 8.2 (lower lip): below the mouth line 2.2, past the lower lip's most upward-facing point
  (within a tenth of the lid distance), the first point as far down-facing as the source's.

The source's normal directions at 2.1, 2.10 and 8.2 come from its own profile, made the same
way, so nothing is tuned to a particular head. Lengths scale with the distance between the
upper eyelid points 3.1 and 3.2; the mesh must be upright (+y up) looking along +z.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from facelib.errors import FaceModelError

__all__ = ["PROFILE_NEEDS", "PROFILE_POINTS", "Profile", "midline_profile", "profile_points"]

PROFILE_POINTS = ("9.3", "8.2", "2.1", "2.10")
"""Feature points :func:`profile_points` places from the profile."""
PROFILE_NEEDS = ("3.1", "3.2", "8.1", "8.2")
"""Feature points :func:`profile_points` needs on both faces (the fan's centre and scale)."""
_MIDLINE = ("8.1", "8.2", "2.2", "9.3", "2.1", "2.10")  # the median x of these is the plane
_SOURCE_NEEDED = ("2.1", "2.10")  # the source's points whose normals are matched
_BEHIND = 0.8  # the fan's centre lies this far (x the lid points' distance) behind the mouth
_STEP = 1 / 120  # resampling step (x the same distance): about half a millimetre
_CHORD = 4  # samples each side of the chord that gives the normal (about 2 mm)
_LIP_WINDOW = 0.1  # the lower lip's upper face lies this far below the mouth line (x scale)
_FAN_DEG = (45.0, -120.0)  # the rays' angles, from up-forward past straight down (y-z plane)
_FAN_RAYS = 661  # rays in the fan (a quarter of a degree apart)


@dataclass(frozen=True, eq=False)
class Profile:
    """A midline profile, top (nose) to bottom (under the chin).

    points: (n, 3) float64 evenly spaced along the profile (the mesh's unit). theta: (n,)
    float64 degrees, the outward normal's direction in the y-z plane (0 forward, +90 up).
    below: index of the point straight below the fan's centre (under the chin).
    """

    points: np.ndarray
    theta: np.ndarray
    below: int

    def nearest(self, point: np.ndarray) -> int:
        """Index of the profile point nearest to ``point (3,)``."""
        return int(np.argmin(np.linalg.norm(self.points - point, axis=1)))


def _cuts(vertices: np.ndarray, triangles: np.ndarray, x: float) -> np.ndarray:
    """``(S, 2, 2)`` float64 (y, z) end points of the triangles' cuts by the plane ``x``."""
    corners = np.asarray(vertices, dtype=np.float64)[triangles]
    side = corners[..., 0] - x
    crossing = (side.min(axis=1) < 0) & (side.max(axis=1) > 0)
    corners, side = corners[crossing], side[crossing]
    ends = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        t = side[:, a] / np.where(side[:, a] != side[:, b], side[:, a] - side[:, b], 1.0)
        point = corners[:, a, 1:] + t[:, None] * (corners[:, b, 1:] - corners[:, a, 1:])
        ends.append(np.where(((side[:, a] < 0) != (side[:, b] < 0))[:, None], point, np.nan))
    ends_arr = np.stack(ends, axis=1)  # (S, 3, 2): exactly two edges cross
    order = np.argsort(np.isnan(ends_arr[..., 0]), axis=1, kind="stable")[:, :2]
    return np.take_along_axis(ends_arr, order[..., None], axis=1)


def _fan(cuts: np.ndarray, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The last hit ``(m, 2)`` (y, z) of each fan ray from ``centre (2,)`` on the cut
    segments, and the rays' angles (radians) of those that hit."""
    angles = np.radians(np.linspace(*_FAN_DEG, _FAN_RAYS))
    start, edge = cuts[:, 0] - centre, cuts[:, 1] - cuts[:, 0]
    hits, kept = [], []
    for angle in angles:
        ray = np.array([np.sin(angle), np.cos(angle)])
        den = ray[0] * edge[:, 1] - ray[1] * edge[:, 0]
        safe = np.where(np.abs(den) > 1e-30, den, np.inf)
        t = (start[:, 0] * edge[:, 1] - start[:, 1] * edge[:, 0]) / safe
        s = (start[:, 0] * ray[1] - start[:, 1] * ray[0]) / safe
        ok = (t > 0) & (s >= 0) & (s <= 1)
        if ok.any():
            hits.append(centre + ray * t[ok].max())
            kept.append(angle)
    return np.array(hits).reshape(-1, 2), np.array(kept)


def midline_profile(vertices: np.ndarray, triangles: np.ndarray, *, x: float,
                    centre: np.ndarray, scale: float) -> Profile:
    """The profile of the mesh ``vertices (V, 3)``, ``triangles (F, 3)`` in the plane
    ``x``, seen from ``centre (3,)`` (inside the head, behind the mouth); ``scale``: the
    distance between the upper lid points, which sets the sampling."""
    hits, angles = _fan(_cuts(vertices, triangles, x), np.asarray(centre, np.float64)[1:])
    if len(hits) < 2 * _CHORD + 2:
        raise FaceModelError("the midline of the mesh was not found behind its landmarks")
    length = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(hits, axis=0), axis=1))]
    at = np.arange(0.0, length[-1], _STEP * scale)
    yz = np.stack([np.interp(at, length, hits[:, k]) for k in range(2)], axis=1)
    ahead = yz[np.minimum(np.arange(len(yz)) + _CHORD, len(yz) - 1)]
    behind = yz[np.maximum(np.arange(len(yz)) - _CHORD, 0)]
    chord = ahead - behind  # runs down the face: the outward normal is (dz, -dy)
    theta = np.degrees(np.arctan2(chord[:, 1], -chord[:, 0]))
    ray_angle = np.interp(at, length, angles)
    below = int(np.argmin(np.abs(ray_angle + np.pi / 2)))
    return Profile(np.c_[np.full(len(yz), x), yz], theta, below)


def _profile_of(vertices: np.ndarray, triangles: np.ndarray,
                points: Mapping[str, np.ndarray], *, whose: str = "") -> Profile:
    """The profile of a mesh in its midline plane: the median ``x`` of its midline feature
    points ``points`` (each ``(3,)``), nudged off a mirrored mesh's midline vertices by a
    millionth of the lid points' distance. FaceModelError naming ``whose`` points are
    missing."""
    missing = [k for k in PROFILE_NEEDS if k not in points]
    if missing:
        raise FaceModelError(f"the midline profile{whose} needs feature points "
                             f"{', '.join(missing)}")
    scale = float(np.linalg.norm(np.asarray(points["3.1"]) - np.asarray(points["3.2"])))
    x = float(np.median([points[k][0] for k in _MIDLINE if k in points])) + 1e-6 * scale
    mouth = (np.asarray(points["8.1"]) + np.asarray(points["8.2"])) / 2
    centre = np.array([x, mouth[1], mouth[2] - _BEHIND * scale])
    return midline_profile(vertices, triangles, x=x, centre=centre, scale=scale)


def _chin(profile: Profile, theta_21: float, theta_210: float) -> tuple[int, int]:
    """Indices of 2.1 and 2.10: up from under the chin to the first points whose normal
    turns as far forward as ``theta_21``, then ``theta_210`` (degrees)."""
    i = profile.below
    while i > 0 and profile.theta[i] < theta_21:
        i -= 1
    j = i
    while j > 0 and profile.theta[j] < theta_210:
        j -= 1
    return i, j


def profile_points(vertices: np.ndarray, triangles: np.ndarray,
                   points: Mapping[str, np.ndarray], *,
                   source: tuple[np.ndarray, np.ndarray, Mapping[str, np.ndarray]]
                   ) -> dict[str, np.ndarray]:
    """9.3, 2.1, 2.10 and (where both faces have 2.2) 8.2 placed on the midline profile of
    ``vertices (V, 3)``, ``triangles (F, 3)`` (see the module docstring).

    points: feature point -> (3,) positions found so far (3.1, 3.2, 8.1 and 8.2 are
        needed; the midline is the median ``x`` of the midline points among them).
    source: the source face's vertices, triangles and feature point positions (the same
        four needed, and 2.1 and 2.10), whose own profile, made the same way, gives the
        normal directions at 2.1, 2.10 and 8.2.
    Returns point -> ``(3,)`` position (the mesh's unit). FaceModelError naming the missing
    feature points.
    """
    src_vertices, src_triangles, src_points = source
    missing = [k for k in _SOURCE_NEEDED if k not in src_points]
    if missing:
        raise FaceModelError(f"profile_points: the source face needs feature points "
                             f"{', '.join(missing)}")
    ref = _profile_of(src_vertices, src_triangles, src_points, whose=" of the source face")
    theta_21 = float(ref.theta[ref.nearest(np.asarray(src_points["2.1"]))])
    theta_210 = float(ref.theta[ref.nearest(np.asarray(src_points["2.10"]))])
    profile = _profile_of(vertices, triangles, points)
    chin, boss = _chin(profile, theta_21, theta_210)
    upper = np.flatnonzero(profile.points[:, 1] > points["8.1"][1])
    tip = upper[np.argmax(profile.points[upper, 2])] if upper.size else boss
    out = {"9.3": profile.points[tip], "2.1": profile.points[chin],
           "2.10": profile.points[boss]}
    if "2.2" in points and "2.2" in src_points:
        theta_82 = float(ref.theta[ref.nearest(np.asarray(src_points["8.2"]))])
        out["8.2"] = profile.points[_lower_lip(profile, profile.nearest(points["2.2"]),
                                               theta_82)]
    return out


def _lower_lip(profile: Profile, mouth: int, theta_82: float) -> int:
    """Index of 8.2: from the mouth line (index ``mouth``) past the lower lip's most
    upward-facing point, the first whose normal turns down to ``theta_82`` (degrees)."""
    window = round(_LIP_WINDOW / _STEP)
    j = mouth + int(np.argmax(profile.theta[mouth : mouth + window]))
    while j < len(profile.theta) - 1 and profile.theta[j] > theta_82:
        j += 1
    return j
