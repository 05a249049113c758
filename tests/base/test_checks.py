"""The base layer's shared helpers: argument checks and the one "did you mean"."""

import numpy as np
import pytest

from facelib.checks import check_count, check_fps, check_number, check_seed, did_you_mean
from facelib.errors import ParameterError


@pytest.mark.parametrize("fps", [25, 25.0, np.float32(25), np.int64(25), np.float64(29.97)])
def test_check_fps_accepts_python_and_numpy_numbers(fps):
    assert check_fps(fps) == pytest.approx(float(fps))
    assert type(check_fps(fps)) is float


@pytest.mark.parametrize("fps", [0, -1, float("nan"), float("inf"), True, "25", None])
def test_check_fps_refuses(fps):
    with pytest.raises(ParameterError, match="fps must be a positive number"):
        check_fps(fps)


def test_check_number_bounds_and_open_low():
    assert check_number("x", 0.25, low=0.25, high=4) == 0.25
    with pytest.raises(ParameterError, match=r"x must be a finite number in \(0, 1\]"):
        check_number("x", 0, low=0, high=1, low_open=True)


@pytest.mark.parametrize(("value", "ok"), [(0, True), (np.int32(7), True), (2**63 - 1, True),
                                           (-1, False), (2**63, False), (1.0, False),
                                           (False, False)])
def test_check_seed(value, ok):
    if ok:
        assert check_seed(value) == int(value)
    else:
        with pytest.raises(ParameterError, match="seed must be an integer"):
            check_seed(value)


def test_check_count():
    assert check_count("n", np.int64(3)) == 3
    with pytest.raises(ParameterError):
        check_count("n", 3.0)


@pytest.mark.parametrize(("word", "choices", "hint"), [
    ("joyy", ["joy", "sadness", "inlove"], "; did you mean 'joy'?"),
    ("nope", ["joy", "sadness", "inlove"], ""),  # the old library hint suggested 'inlove'
    ("speaksound", ["speakSound", "speakText"], "; did you mean 'speakSound'?"),
    ("fps", ["fps", "seed"], ""),  # a word never suggests itself
])
def test_did_you_mean(word, choices, hint):
    assert did_you_mean(word, choices) == hint


def test_did_you_mean_is_the_only_one():
    """No module keeps its own difflib-based suggestion."""
    from pathlib import Path

    package = Path(__file__).parents[2] / "facelib"
    users = [p.relative_to(package).as_posix() for p in package.rglob("*.py")
             if "difflib" in p.read_text(encoding="utf-8")]
    assert users == ["checks.py"]


def test_check_kind_and_items():
    from facelib.checks import check_items, check_kind

    assert check_kind("x", 3, int) == 3
    with pytest.raises(ParameterError, match="x must be a str, got int 3"):
        check_kind("x", 3, str)
    assert check_items("xs", (1, 2), int) == [1, 2]
    with pytest.raises(ParameterError, match=r"xs\[1\] must be a int, got str"):
        check_items("xs", [1, "a"], int)
    with pytest.raises(ParameterError, match="xs must be a sequence of int, got str"):
        check_items("xs", "12", int)
