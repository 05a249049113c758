"""facelib.facelib_warnings: facelib's warnings collected, every other one dropped."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import facelib
from facelib.errors import FdlWarning, facelib_warnings


def _warn_twice_from_one_place() -> None:
    for n in (1, 2):
        warnings.warn(f"a global that looks misspelt ({n})", FdlWarning, stacklevel=1)


def test_each_facelib_warning_is_kept_in_order_and_the_others_are_dropped(recwarn):
    with facelib_warnings() as caught:
        _warn_twice_from_one_place()  # twice from one line: both kept, not once
        with np.errstate(divide="warn"):
            np.log(np.zeros(1))  # numpy's RuntimeWarning
        warnings.warn("a third party's deprecation", DeprecationWarning, stacklevel=1)
        warnings.warn("frames missing", facelib.FacelibWarning, stacklevel=1)
        assert caught == []  # filled when the block ends
    assert [str(w.message) for w in caught] == [
        "a global that looks misspelt (1)", "a global that looks misspelt (2)", "frames missing"]
    assert [w.category for w in caught] == [FdlWarning, FdlWarning, facelib.FacelibWarning]
    assert len(recwarn) == 0  # nothing shown outside the block either


def test_warnings_before_an_exception_are_kept_and_error_filters_still_apply():
    def warn_then_fail() -> None:
        warnings.warn("first", facelib.FacelibWarning, stacklevel=1)
        raise ValueError("later")

    with pytest.raises(ValueError, match="later"), facelib_warnings() as caught:
        warn_then_fail()
    assert [str(w.message) for w in caught] == ["first"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(RuntimeWarning), facelib_warnings():
            warnings.warn("turned into an error", RuntimeWarning, stacklevel=1)
