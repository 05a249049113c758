"""How strongly speech is articulated: jaw and lip levels per span (JALI's two axes).

A speech's ``style`` (``"mumble"``, ``"normal"``, ``"emphatic"`` or a number) gives a jaw
level and a lip level; reduced vowels (schwa) take a share of them; the viseme blend
multiplies each span's targets by its levels (:func:`facelib.visemes.coarticulation.blend`),
and :func:`bound` keeps the result within the face's anatomical range. Rules in
``facelib/data/visemes/articulation.json``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import cache
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib import data
from facelib.checks import did_you_mean
from facelib.errors import DataError, ParameterError
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.visemes.timeline import VisemeSpan

__all__ = ["Style", "bound", "is_reduced", "limits", "span_levels", "style_levels",
           "style_names"]

Style = str | float
"""A style name of the data file or a number (both levels set to it)."""

_FILE = "visemes/articulation.json"


@cache
def _rules() -> dict[str, Any]:
    doc: dict[str, Any] = data.json_data(_FILE)
    return doc


@cache
def _styles() -> Mapping[str, tuple[float, float]]:
    raw = _rules()["styles"]
    out = {name: (float(row["jaw"]), float(row["lip"]))
           for name, row in raw.items() if not name.startswith("_")}
    if any(not 0 < v <= 2 for pair in out.values() for v in pair):
        raise DataError(f"style levels must lie in (0, 2]: {out}", path=str(data.path(_FILE)))
    return MappingProxyType(out)


def style_names() -> tuple[str, ...]:
    """The named styles a speech may take (``mumble``, ``normal``, ``emphatic``, ...)."""
    return tuple(_styles())


def style_levels(style: Style) -> tuple[float, float]:
    """``(jaw, lip)`` levels of ``style``: a name of the data file, or a number within the
    file's ``number_range`` for both. ParameterError otherwise, with the choices."""
    if isinstance(style, bool):
        raise ParameterError(f"style must be a name or a number, got {style!r}")
    if isinstance(style, int | float):
        low, high = (float(v) for v in _rules()["number_range"])
        if not low <= float(style) <= high:
            raise ParameterError(f"style must be a number from {low:g} to {high:g} or one of "
                                 f"{', '.join(style_names())}; got {style!r}")
        return float(style), float(style)
    if not isinstance(style, str):
        raise ParameterError(f"style must be a name or a number, got {style!r}")
    styles = _styles()
    if style not in styles:
        raise ParameterError(f"unknown speech style {style!r} (one of "
                             f"{', '.join(styles)}, or a number){did_you_mean(style, styles)}")
    return styles[style]


@cache
def _reduced() -> tuple[frozenset[str], float]:
    raw = _rules()["reduced_vowels"]
    return frozenset(str(p) for p in raw["phones"]), float(raw["level"])


def is_reduced(span: VisemeSpan) -> bool:
    """Whether ``span`` shows only reduced vowels (schwa and kin: ``reduced_vowels``)."""
    reduced = _reduced()[0]
    return bool(span.phones) and all(p in reduced for p in span.phones)


def span_levels(visemes: Sequence[VisemeSpan], *, style: Style = "normal") -> np.ndarray:
    """``(len(visemes), 2) float64``: each span's jaw and lip levels, the style's, times the
    reduced-vowel level for a span whose phones are all reduced vowels."""
    out = np.empty((len(visemes), 2))
    out[:] = style_levels(style)
    out[[is_reduced(s) for s in visemes]] *= _reduced()[1]
    return out


@cache
def limits() -> tuple[np.ndarray, np.ndarray]:
    """``(low, high)``, each ``(84,) float32``: the range each FAP may reach in speech
    (``-inf``/``inf`` where the data file sets no bound)."""
    low = np.full(N_FAPS, -np.inf, np.float32)
    high = np.full(N_FAPS, np.inf, np.float32)
    for name, value in _rules()["bounds"].items():
        if name.startswith("_"):
            continue
        try:
            k = fap(name).index
            low[k], high[k] = (float(v) for v in value)
        except (ParameterError, TypeError, ValueError) as exc:
            raise DataError(f"bounds: {name}: expected a FAP name and [low, high], got "
                            f"{value!r}", path=str(data.path(_FILE))) from exc
        if not low[k] < 0 < high[k]:
            raise DataError(f"bounds: {name}: {value!r} must contain 0", path=str(data.path(_FILE)))
    low.flags.writeable = high.flags.writeable = False
    return low, high


def bound(values: np.ndarray) -> np.ndarray:
    """``values`` ``(n, 84)`` FAP units clipped to the anatomical bounds, in place; returned."""
    np.clip(values, *limits(), out=values)
    return values
