"""Upper eyelids refitted to close over a transferred face's eye (engine.setup.eyelids)."""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.engine.setup import read_landmarks, setup_face
from facelib.engine.setup.eyelids import close_upper_lid, eye_opening

HEADS = Path(__file__).resolve().parents[2] / "examples" / "heads"
CLOSED = np.zeros(84, np.float32)
CLOSED[[18, 19]] = 1024  # FAP 19/20: both upper lids down by one IRISD


@pytest.fixture(scope="module")
def source():  # type: ignore[no-untyped-def]
    return default_face()


def _eye(face, side: str) -> tuple[np.ndarray, float]:  # type: ignore[no-untyped-def]
    centre = face.pivots[f"eye_{side}"].astype(np.float64)
    ids = face.parts[f"eye_{side}"].vertex_ids
    return centre, float(np.linalg.norm(face.vertices[ids] - centre, axis=1).max())


def _shows(face, vertices, side: str) -> bool:  # type: ignore[no-untyped-def]
    centre, radius = _eye(face, side)
    return eye_opening(vertices, face.parts["skin"].triangles, centre, radius).shows


def test_the_default_heads_opening_and_closed_lids(source) -> None:  # type: ignore[no-untyped-def]
    centre, radius = _eye(source, "l")
    opening = eye_opening(source.vertices, source.parts["skin"].triangles, centre, radius)
    at = int(np.nanargmin(np.abs(opening.x - source.vertices[source.feature_points["3.1"], 0])))
    height = opening.high[at] - opening.low[at]
    iris = 1024 * source.fapu["IRISD"]  # the lid points' distance (3.1 to 3.3)
    assert 0.8 * iris <= height <= 1.2 * iris
    closed = source.deform_frame(CLOSED)
    assert not _shows(source, closed, "l") and not _shows(source, closed, "r")


def test_a_lid_that_closes_is_left_alone_and_a_weak_one_is_raised(source) -> None:  # type: ignore[no-untyped-def]
    lid = next(r for r in source.regions if r.name == "upper_lid_l")
    centre, radius = _eye(source, "l")
    from facelib.engine import rigid

    full = float(rigid.hinge_angle(source.vertices[source.feature_points["3.1"]], centre,
                                   np.array([-1024 * source.fapu["IRISD"]]))[0])
    fit = functools.partial(close_upper_lid, vertices=source.vertices,
                            triangles=source.parts["skin"].triangles, centre=centre,
                            radius=radius, full_angle=full)
    assert fit(lid) is lid
    weak = dataclasses.replace(lid, weights=(lid.weights * 0.6).astype(np.float32))
    fixed = fit(weak)
    assert np.all(fixed.weights >= weak.weights)
    assert fixed.weights.max() > weak.weights.max()
    closed = source.vertices.astype(np.float64).copy()
    members = fixed.vertices
    y, z = rigid.rotate_about_x(closed[members, 1][None], closed[members, 2][None],
                                centre[1], centre[2], (fixed.weights * full)[None])
    closed[members, 1], closed[members, 2] = y[0], z[0]
    assert not _shows(source, closed, "l")


def test_the_cartoons_bigger_eyes_close(source) -> None:  # type: ignore[no-untyped-def]
    face = setup_face(HEADS / "cartoon_head.obj",
                      landmarks=read_landmarks(HEADS / "cartoon_landmarks.json"), source=source)
    assert _shows(face, face.vertices, "l") and _shows(face, face.vertices, "r")
    closed = face.deform_frame(CLOSED)
    assert not _shows(face, closed, "l") and not _shows(face, closed, "r")
