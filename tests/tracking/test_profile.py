"""The midline profile places 9.3, 8.2, 2.1 and 2.10 from a head mesh's own shape."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.engine.setup import read_landmarks
from facelib.engine.setup.headmesh import load_head_mesh
from facelib.errors import FaceModelError
from facelib.tracking.profile import PROFILE_POINTS, midline_profile, profile_points

HEADS = Path(__file__).resolve().parents[2] / "examples" / "heads"


@pytest.fixture(scope="module")
def source():  # type: ignore[no-untyped-def]
    face = default_face()
    points = {k: face.vertices[v].astype(np.float64) for k, v in face.feature_points.items()}
    return face.vertices.astype(np.float64), face.parts["skin"].triangles, points


def test_the_source_finds_its_own_points(source) -> None:  # type: ignore[no-untyped-def]
    vertices, triangles, points = source
    placed = profile_points(vertices, triangles, points, source=source)
    assert set(placed) == set(PROFILE_POINTS)
    for fp, at in placed.items():  # half-millimetre samples, 2 mm chords
        assert np.linalg.norm(at - points[fp]) <= 1e-3, fp


def test_the_cartoons_long_chin(source) -> None:  # type: ignore[no-untyped-def]
    mesh = load_head_mesh(HEADS / "cartoon_head.obj")
    truth = {k: np.asarray(v) for k, v in read_landmarks(
        HEADS / "cartoon_landmarks.json").items()}
    placed = profile_points(mesh.vertices, mesh.triangles, truth, source=source)
    err = {k: float(np.linalg.norm(placed[k] - truth[k])) for k in placed}
    assert err["2.1"] <= 2e-3 and err["9.3"] <= 2e-3 and err["8.2"] <= 2e-3
    # the chin boss: the cartoon's truth is the default head's point moved by the
    # long-chin target, which is not where the chin faces as far forward (measured 6.7 mm)
    assert err["2.10"] <= 8e-3
    assert placed["2.1"][1] < placed["2.10"][1] < placed["8.2"][1] < placed["9.3"][1]


def test_the_profile_runs_down_the_face(source) -> None:  # type: ignore[no-untyped-def]
    vertices, triangles, points = source
    scale = float(np.linalg.norm(points["3.1"] - points["3.2"]))
    centre = np.array([1e-7, points["8.1"][1], points["8.1"][2] - 0.8 * scale])
    profile = midline_profile(vertices, triangles, x=1e-7, centre=centre, scale=scale)
    gaps = np.linalg.norm(np.diff(profile.points, axis=0), axis=1)
    # even steps along the polyline: a chord across one of its corners is a little shorter
    assert np.median(gaps) == pytest.approx(scale / 120, rel=1e-6)
    assert gaps.max() <= scale / 120 * (1 + 1e-6)
    assert profile.points[0, 1] > points["9.3"][1] > profile.points[profile.below, 1]
    assert abs(profile.theta[profile.nearest(points["9.3"])]) < 30  # the tip looks forward
    with pytest.raises(FaceModelError, match=r"needs feature points 8\.1"):
        profile_points(vertices, triangles, {k: v for k, v in points.items() if k != "8.1"},
                       source=source)


def test_missing_points_are_named(source) -> None:  # type: ignore[no-untyped-def]
    vertices, triangles, points = source
    without_lid = {k: v for k, v in points.items() if k != "3.1"}
    with pytest.raises(FaceModelError, match=r"needs feature points 3\.1"):
        profile_points(vertices, triangles, without_lid, source=source)
    src_vertices, src_triangles, src_points = source
    no_boss = {k: v for k, v in src_points.items() if k != "2.10"}
    with pytest.raises(FaceModelError, match=r"source face .* 2\.10"):
        profile_points(vertices, triangles, points, source=(src_vertices, src_triangles, no_boss))
