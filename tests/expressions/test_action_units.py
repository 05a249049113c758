"""Expressions built on FACS action units (issue 32, item 1), measured on the default head."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from facelib import DataError, engine
from facelib.cues import ExpressionCue
from facelib.expressions import animate, default_library
from facelib.mpeg4.action_units import action_units, compose, recipes
from facelib.mpeg4.highlevel import EXPRESSION_IDS, expression_table


@pytest.fixture(scope="module")
def face():
    return engine.default_face()


def _moved(face, values) -> dict[str, np.ndarray]:
    """Feature point -> displacement (mm) of the skin under FAP ``values``, in the head's
    own frame (head rotations, FAP 48-50, left out)."""
    values = np.array(values, np.float32)
    values[47:50] = 0.0
    d = (face.deform_frame(values) - face.vertices) * 1000.0
    return {k: d[i] for k, i in face.feature_points.items()}


def _gap(face, values, a: str, b: str) -> float:
    """Change (mm) of the vertical distance between feature points ``a`` and ``b``."""
    m = _moved(face, values)
    return float(m[a][1] - m[b][1])


# Each check: (what it measures, function of (face, FAP values) -> mm, least mm at full).
# x is the face's left (+x on the left side points), y up, z forward.
REGIONS = {
    "inner brow up": (lambda f, v: _moved(f, v)["4.1"][1], 2.0),
    "outer brow up": (lambda f, v: _moved(f, v)["4.5"][1], 2.0),
    "inner brow down": (lambda f, v: -_moved(f, v)["4.1"][1], 2.0),
    "brows together": (lambda f, v: -_moved(f, v)["4.1"][0], 1.0),
    "upper lid up": (lambda f, v: _moved(f, v)["3.1"][1], 0.3),
    "upper lid down": (lambda f, v: -_moved(f, v)["3.1"][1], 0.5),
    "lower lid up": (lambda f, v: _moved(f, v)["3.3"][1], 0.8),
    "cheek up": (lambda f, v: _moved(f, v)["5.3"][1], 2.0),
    "nose up": (lambda f, v: _moved(f, v)["9.3"][1], 0.8),
    "upper lip up": (lambda f, v: _moved(f, v)["8.1"][1], 1.5),
    "corners up": (lambda f, v: _moved(f, v)["2.4"][1], 1.5),
    "corners down": (lambda f, v: -_moved(f, v)["2.4"][1], 1.5),
    "corners out": (lambda f, v: _moved(f, v)["2.4"][0], 1.5),
    "lower lip down": (lambda f, v: -_moved(f, v)["8.2"][1], 1.5),
    "chin up": (lambda f, v: _moved(f, v)["2.10"][1], 0.5),
    "lips thinner": (lambda f, v: -_gap(f, v, "8.1", "8.2"), 1.0),
    "lips part": (lambda f, v: _gap(f, v, "2.2", "2.3"), 1.0),
    "jaw down": (lambda f, v: -_moved(f, v)["2.1"][1], 1.5),
}

# What each action unit must do on its own at full intensity (FACS descriptions).
UNIT_REGIONS = {
    "AU1": ("inner brow up",), "AU2": ("outer brow up",),
    "AU4": ("inner brow down", "brows together"), "AU5": ("upper lid up",),
    "AU6": ("cheek up", "lower lid up"), "AU7": ("lower lid up", "upper lid down"),
    "AU9": ("nose up", "upper lip up", "inner brow down"), "AU10": ("upper lip up",),
    "AU12": ("corners up",), "AU14": ("corners up",),
    "AU15": ("corners down",), "AU16": ("lower lip down",), "AU17": ("chin up",),
    "AU20": ("corners out",), "AU23": ("lips thinner",), "AU24": ("lips thinner",),
    "AU25": ("lips part",), "AU26": ("jaw down", "lips part"), "AU43": ("upper lid down",),
}

# The regions that define each library expression (issue 32's list and EMFACS).
DEFINING = {
    "joy": ("corners up", "cheek up", "lower lid up"),
    "sadness": ("inner brow up", "brows together", "corners down", "chin up"),
    "anger": ("inner brow down", "brows together", "upper lid up", "lower lid up",
              "lips thinner"),
    "fear": ("inner brow up", "brows together", "upper lid up", "corners out", "jaw down"),
    "surprise": ("inner brow up", "outer brow up", "upper lid up", "jaw down"),
    "disgust": ("nose up", "upper lip up", "inner brow down", "lower lid up"),
    "worry": ("inner brow up", "brows together", "upper lid up", "lips thinner"),
    "trust": ("corners up", "inner brow up"),
    "inlove": ("corners up", "cheek up", "upper lid down"),
    "sleepy": ("upper lid down",),
    "tongueout": ("jaw down", "lower lip down"),
}


def test_every_unit_moves_its_regions(face):
    assert set(UNIT_REGIONS) == set(action_units())
    for code, regions in UNIT_REGIONS.items():
        for region in regions:
            measure, least = REGIONS[region]
            got = measure(face, action_units()[code].values)
            assert got >= least, (code, region, round(got, 2))


def test_every_expression_is_its_units_and_moves_its_defining_regions(face):
    library = default_library()
    assert set(DEFINING) == set(library.names) == set(recipes())
    for name, regions in DEFINING.items():
        expression = library.get(name)
        values, mask = compose(expression.parts)
        np.testing.assert_allclose(expression.values, values, atol=1e-3)
        assert np.array_equal(expression.mask, mask)
        for region in regions:
            measure, least = REGIONS[region]
            got = measure(face, expression.values)
            assert got >= least, (name, region, round(got, 2))


def test_the_universal_expressions_use_their_emfacs_units():
    emfacs = {"joy": {"AU6", "AU12"}, "sadness": {"AU1", "AU4", "AU15"},
              "anger": {"AU4", "AU5", "AU7", "AU23", "AU24"},
              "fear": {"AU1", "AU2", "AU4", "AU5", "AU20", "AU26"},
              "surprise": {"AU1", "AU2", "AU5", "AU26"}, "disgust": {"AU9", "AU10", "AU15"}}
    for name, units in emfacs.items():
        used = {part for part, amount in recipes()[name].parts if amount > 0}
        assert units <= used, (name, units - used)
    # what tells the neighbours apart: surprise neither knits the brows nor stretches
    # the lips; sadness pouts and droops the lids where worry widens the eyes
    assert not {"AU4", "AU20"} & {p for p, _ in recipes()["surprise"].parts}
    assert {"AU17", "AU43"} <= {p for p, _ in recipes()["sadness"].parts}
    assert "AU5" in {p for p, _ in recipes()["worry"].parts}


def _held(face, name: str, intensity: float) -> np.ndarray:
    """FAP values a cue of ``name`` at ``intensity`` holds (through the expression track)."""
    cue = ExpressionCue(name, 0, 2000, intensity=intensity, ramp_in_ms=0, ramp_out_ms=0)
    return animate([cue], fps=25, n_frames=50).values[25]


@pytest.mark.parametrize("name", sorted(DEFINING))
def test_intensity_0_6_moves_each_defining_region_at_least_half_of_1_0(face, name):
    full, conversational = _held(face, name, 1.0), _held(face, name, 0.6)
    for region in DEFINING[name]:
        measure = REGIONS[region][0]
        assert measure(face, conversational) >= 0.5 * measure(face, full), (name, region)
    # and the curve keeps 1.0 as defined
    np.testing.assert_allclose(full, default_library().get(name).values, atol=1e-3)


def test_expressions_at_0_6_differ_from_neutral_and_from_each_other(face):
    """Every pair of expressions at 0.6 differs by over 1.5 mm at some feature point (or by
    over 2 degrees of head posture), and each moves some point by over 2 mm."""
    lib = default_library()
    moved = {n: np.array(list(_moved(face, _held(face, n, 0.6)).values())) for n in lib.names}
    head = {n: _held(face, n, 0.6)[47:50] * 1e-5 for n in lib.names}  # radians
    for name, m in moved.items():
        assert np.linalg.norm(m, axis=1).max() > 2.0, name
    for a, b in itertools.combinations(lib.names, 2):
        skin = np.linalg.norm(moved[a] - moved[b], axis=1).max()
        posture = np.degrees(np.abs(head[a] - head[b]).max())
        assert skin > 1.5 or posture > 2.0, (a, b, round(float(skin), 2))


def test_fap_2_decodes_the_composed_expressions():
    table = expression_table()
    for i, name in enumerate(EXPRESSION_IDS[1:], start=1):
        np.testing.assert_allclose(table[i], default_library().get(name).values, atol=1e-3)


def test_a_bad_unit_row_names_its_file_and_line(tmp_path, monkeypatch):
    from facelib import data
    from facelib.mpeg4 import action_units as module

    bad = "au,name,fap,value,note\nAU1,inner,raise_l_i_eyebrow,140,\nAU2,outer,raise_l_brow,9,\n"
    monkeypatch.setattr(data, "text", lambda name: bad)
    module.action_units.cache_clear()
    try:
        with pytest.raises(DataError, match=r"action_units.csv:3.*raise_l_brow"):
            module.action_units()
    finally:
        monkeypatch.undo()
        module.action_units.cache_clear()
