"""Landmark layouts: which tracker point (or mean of points) is which MPEG-4 feature point.

A layout turns a tracker's ``(n_frames, K, D)`` landmark array into feature-point positions
``(n_frames, P, D)`` and names the points the rigid head fit uses. The tables are package
data under ``facelib/data/tracking/`` (one row per point with its reason).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache, cached_property

import numpy as np

from facelib.data import csv_rows, json_data
from facelib.data import path as data_path
from facelib.errors import DataError, ParameterError, TrackingError
from facelib.mpeg4 import feature_point_table

__all__ = ["LandmarkLayout", "feature_point_layout", "landmark_layout", "layout_names"]


@dataclass(frozen=True)
class LandmarkLayout:
    """How one tracker's landmarks map to MPEG-4 feature points.

    Attributes
    ----------
    name: ``"mediapipe"``, ``"ibug68"``, or ``"feature_points"`` for tracks that already are
        feature points.
    n_points: K, the tracker's landmark count.
    feature_points: feature point ids (``"8.3"``) in output order, P of them.
    weights: ``(P, K) float64``; row p averages the landmarks of feature point p.
    stable: ``(S,) int64`` landmark indices for the rigid head fit (may be empty).
    anchors: ``(A,) int64`` landmark indices the rig fit measures motion against (may be
        empty).
    """

    name: str
    n_points: int
    feature_points: tuple[str, ...]
    weights: np.ndarray
    stable: np.ndarray
    anchors: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    def feature_point_positions(self, landmarks: np.ndarray) -> np.ndarray:
        """``(n_frames, K, D)`` landmarks -> ``(n_frames, P, D) float64`` feature points."""
        landmarks = np.asarray(landmarks, np.float64)
        if landmarks.ndim != 3 or landmarks.shape[1] != self.n_points:
            raise TrackingError(
                f"layout {self.name!r} needs landmarks of shape (n_frames, {self.n_points}, 2 "
                f"or 3), got {landmarks.shape}"
            )
        index, weight = self._terms
        points = (landmarks[:, index] * weight[:, :, None]).sum(axis=2)
        # as the product with all of weights: a non-finite coordinate makes that axis NaN
        return np.where(np.isfinite(landmarks).all(axis=1)[:, None, :], points, np.nan)

    @cached_property
    def _terms(self) -> tuple[np.ndarray, np.ndarray]:
        """``(P, m) int64`` the landmarks each feature point averages, in order, and
        ``(P, m) float64`` their weights (rows with fewer padded with weight 0): the product
        with :attr:`weights`, mostly zeros, on a few terms a point."""
        m = max(int(np.count_nonzero(self.weights, axis=1).max(initial=0)), 1)
        index = np.argsort(self.weights == 0, axis=1, kind="stable")[:, :m]
        return index, np.take_along_axis(self.weights, index, axis=1)

    def index(self, fp: str) -> int:
        """Row of feature point ``fp`` in :attr:`feature_points`; KeyError if unmapped."""
        return self.feature_points.index(fp)


def layout_names() -> tuple[str, ...]:
    """Names of the packaged layouts (``"mediapipe"``, ``"ibug68"``)."""
    return tuple(json_data("tracking/layouts.json"))


def _indices(text: str, n_points: int, where: str, line: int) -> list[int] | None:
    try:
        ids = [int(part) for part in text.split(";") if part.strip()]
    except ValueError:
        raise DataError(f"landmarks {text!r} are not integers", path=where, line=line) from None
    if not ids or min(ids) < 0:
        raise DataError(f"bad landmark list {text!r}", path=where, line=line)
    return None if max(ids) >= n_points else ids


@cache
def landmark_layout(name: str, n_points: int | None = None) -> LandmarkLayout:
    """The packaged layout ``name``; ``n_points`` picks a smaller variant listed under
    ``also`` (MediaPipe without iris refinement has 468 points: the pupils are dropped)."""
    spec = json_data("tracking/layouts.json").get(name)
    if spec is None:
        raise ParameterError(f"unknown landmark layout {name!r}; known: {layout_names()}")
    count = int(spec["n_points"]) if n_points is None else int(n_points)
    if count != spec["n_points"] and count not in spec["also"]:
        raise TrackingError(f"layout {name!r} has {spec['n_points']} points, not {count}")
    table = f"tracking/{spec['table']}"
    where = str(data_path(table))
    known = feature_point_table()
    fps: list[str] = []
    rows: list[list[int]] = []
    stable: list[int] = []
    anchors: list[int] = []
    for line, row in csv_rows(table):
        ids = _indices(row["landmarks"], count, where, line)
        if ids is None:
            continue
        if row["role"] == "stable":
            stable += ids
        elif row["role"] == "anchor":
            anchors += ids
        elif row["role"] == "feature_point":
            if row["name"] not in known or row["name"] in fps:
                raise DataError(f"unknown or repeated feature point {row['name']!r}",
                                path=where, line=line)
            fps.append(row["name"])
            rows.append(ids)
        else:
            raise DataError(f"role must be feature_point, stable or anchor, got {row['role']!r}",
                            path=where, line=line)
    weights = np.zeros((len(fps), count))
    for p, ids in enumerate(rows):
        weights[p, ids] = 1.0 / len(ids)
    weights.flags.writeable = False
    stable_arr = np.array(sorted(set(stable)), np.int64)
    stable_arr.flags.writeable = False
    anchor_arr = np.array(sorted(set(anchors)), np.int64)
    anchor_arr.flags.writeable = False
    return LandmarkLayout(name, count, tuple(fps), weights, stable_arr, anchor_arr)


def feature_point_layout(feature_points: tuple[str, ...],
                         stable: tuple[str, ...] = ()) -> LandmarkLayout:
    """A layout for tracks whose K points already are the given feature points (in order);
    ``stable`` names those the rigid head fit may use."""
    known = feature_point_table()
    bad = [fp for fp in feature_points if fp not in known]
    if bad or len(set(feature_points)) != len(feature_points):
        raise ParameterError(f"unknown or repeated feature points: {bad or feature_points}")
    weights = np.eye(len(feature_points))
    weights.flags.writeable = False
    index = np.array([feature_points.index(fp) for fp in stable], np.int64)
    index.flags.writeable = False
    return LandmarkLayout("feature_points", len(feature_points), tuple(feature_points),
                          weights, index)
