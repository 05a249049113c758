"""The expression library against the head's own ARKit target mixes (issue 14, items 1-3)."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pytest

from facelib import engine
from facelib.engine.quality import mean_roughness
from facelib.expressions import default_library
from facelib.mpeg4.tables import fap

POINTS = {
    "mouth corners": ("2.4", "2.5", "8.3", "8.4"),
    "cheeks": ("5.1", "5.2", "5.3", "5.4"),
    "chin": ("2.1", "2.10"),
}


@pytest.fixture(scope="module")
def face():
    return engine.default_face()


def _mix(name: str) -> np.ndarray:
    path = resources.files("facelib.data").joinpath("head", "default_head.npz")
    with np.load(str(path)) as data:
        return data[f"mix_{name}"]


@pytest.mark.parametrize("name", ["joy", "surprise"])
def test_expression_moves_like_its_target_mix(face, name):
    """At the mouth corners, cheeks and chin the library expression moves the skin within
    30 % of the textbook ARKit mix (where the mix moves a point by over a millimetre).
    Fear left this test in issue 32: rebuilt on its action units it parts the lips (AU25)
    and drops the jaw (AU26) more than the mix's jawOpen 0.2; tests/expressions/
    test_action_units.py checks its regions instead."""
    mix = _mix(name)
    moved = face.deform_frame(default_library().get(name).values) - face.vertices
    checked = 0
    for where, ids in POINTS.items():
        for key in ids:
            i = face.feature_points[key]
            want, got = mix[i].astype(np.float64), moved[i].astype(np.float64)
            if np.linalg.norm(want) > 1e-3:
                checked += 1
                assert np.linalg.norm(got - want) <= 0.3 * np.linalg.norm(want), (where, key)
            else:
                assert np.linalg.norm(got - want) < 1e-3, (where, key)
    assert checked >= 4


def test_smile_pulls_the_corners_back_and_lifts_the_cheeks(face):
    moved = face.deform_frame(default_library().get("joy").values) - face.vertices
    for key in ("2.4", "2.5"):
        assert moved[face.feature_points[key], 2] < -0.004  # back by over 4 mm
    for key in ("5.3", "5.4"):
        assert moved[face.feature_points[key], 1] > 0.008  # cheeks up (not inward)


def test_fear_differs_from_surprise(face):
    """Fear draws the brows together and stretches the lips; surprise does neither."""
    lib = default_library()
    fear, surprise = lib.get("fear").values, lib.get("surprise").values
    assert fear[fap("squeeze_l_eyebrow").index] > 10 >= surprise[fap("squeeze_l_eyebrow").index]
    fear_corner = (face.deform_frame(fear) - face.vertices)[face.feature_points["2.4"], 0]
    surprise_corner = (face.deform_frame(surprise) - face.vertices)[face.feature_points["2.4"], 0]
    assert fear_corner > 0.003 and surprise_corner < 0.001  # fear widens the mouth


def test_no_expression_is_rougher_than_one_and_a_half_times_neutral(face):
    skin = face.parts["skin"].triangles
    neutral = mean_roughness(face.vertices, skin)
    for name, expression in default_library().expressions.items():
        rough = mean_roughness(face.deform_frame(expression.values), skin)
        assert rough <= 1.5 * neutral, name


def test_painted_brows_ride_on_the_brow_faps(face):
    colours = np.asarray(face.vertex_colors)
    skin = face.parts["skin"].vertex_ids
    brow = skin[(colours[skin].sum(1) < 1.6) & (face.vertices[skin, 1] > 0.04)]
    left = brow[face.vertices[brow, 0] > 0]
    assert left.size > 10
    values = np.zeros(84, np.float32)
    values[fap("raise_l_i_eyebrow").index] = 150
    values[fap("raise_l_o_eyebrow").index] = 150
    moved = face.deform_frame(values)
    rise = moved[left, 1] - face.vertices[left, 1]
    assert np.median(rise) > 0.5 * 150 * face.fapu["ENS"]
    right = brow[face.vertices[brow, 0] < 0]
    assert np.abs(moved[right] - face.vertices[right]).max() < 1e-4
