"""FACS action units as FAP amplitudes, and the expressions made of them.

``facelib/data/expressions/action_units.csv`` gives each action unit's FAP values at full
intensity; ``expressions.csv`` beside it defines each library expression as a list of parts
(an action unit with its intensity, or a FAP with its value); ``intensity.csv`` gives each
expression's intensity curve. This module reads and composes them; the expression library
(:mod:`facelib.expressions.library`) and the MPEG-4 FAP 2 decoder both use it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib import data
from facelib.errors import DataError, FacelibError
from facelib.mpeg4.tables import N_FAPS, fap

__all__ = [
    "ActionUnit", "Recipe", "action_units", "compose", "intensity_exponents", "recipes",
]

_UNITS = "expressions/action_units.csv"
_RECIPES = "expressions/expressions.csv"
_CURVES = "expressions/intensity.csv"


@dataclass(frozen=True, eq=False)
class ActionUnit:
    """One FACS action unit at full intensity.

    code: ``"AU4"``; name: its FACS name (``"brow lowerer"``).
    values: ``(84,) float32`` FAP values in FAP units; mask: ``(84,) bool`` the FAPs it moves.
    """

    code: str
    name: str
    values: np.ndarray
    mask: np.ndarray


@dataclass(frozen=True)
class Recipe:
    """A library expression as parts: ``(action unit code or FAP name, amount)``, where an
    action unit's amount is its intensity and a FAP's is its value in FAP units."""

    name: str
    parts: tuple[tuple[str, float], ...]


def _number(row: Mapping[str, str], key: str, name: str, line: int) -> float:
    try:
        value = float(row[key])
    except ValueError:
        value = float("nan")
    if not np.isfinite(value):
        raise DataError(f"{key} {row[key]!r} is not a number", path=str(data.path(name)),
                        line=line)
    return value


def _column(key: str, name: str, line: int) -> int:
    try:
        column = fap(key).index
    except FacelibError as exc:
        raise DataError(str(exc), path=str(data.path(name)), line=line) from None
    if column < 2:
        raise DataError(f"FAP {key!r} is high level; give low-level FAPs 3-84",
                        path=str(data.path(name)), line=line)
    return column


@cache
def action_units() -> Mapping[str, ActionUnit]:
    """The action units of ``action_units.csv`` by code (``"AU12"``), read once."""
    values: dict[str, np.ndarray] = {}
    names: dict[str, str] = {}
    for line, row in data.csv_rows(_UNITS):
        code = row["au"]
        column = _column(row["fap"], _UNITS, line)
        if code not in values:
            values[code] = np.zeros(N_FAPS, np.float32)
            names[code] = row["name"]
        values[code][column] += _number(row, "value", _UNITS, line)
    out = {}
    for code, v in values.items():
        mask = v != 0
        v.flags.writeable = False
        mask.flags.writeable = False
        out[code] = ActionUnit(code, names[code], v, mask)
    return MappingProxyType(out)


@cache
def recipes() -> Mapping[str, Recipe]:
    """The expressions of ``expressions.csv`` by name, each part checked, read once."""
    parts: dict[str, list[tuple[str, float]]] = {}
    units = action_units()
    for line, row in data.csv_rows(_RECIPES):
        part = row["part"]
        if part.upper().startswith("AU"):
            if part.upper() not in units:
                raise DataError(f"unknown action unit {part!r} (known: {', '.join(units)})",
                                path=str(data.path(_RECIPES)), line=line)
            part = part.upper()
        else:
            _column(part, _RECIPES, line)
        parts.setdefault(row["expression"], []).append(
            (part, _number(row, "amount", _RECIPES, line)))
    return MappingProxyType({n: Recipe(n, tuple(p)) for n, p in parts.items()})


def compose(parts: Sequence[tuple[str, float]]) -> tuple[np.ndarray, np.ndarray]:
    """``(values, mask)`` of a list of parts (see :class:`Recipe`): ``(84,) float64`` FAP
    values, the sum of each part's amount times its unit's values (or the FAP's value),
    and ``(84,) bool`` the FAPs any part moves."""
    values = np.zeros(N_FAPS, np.float64)
    mask = np.zeros(N_FAPS, bool)
    units = action_units()
    for part, amount in parts:
        unit = units.get(part)
        if unit is not None:
            values += amount * unit.values
            mask |= unit.mask
        else:
            column = fap(part).index
            values[column] += amount
            mask[column] = True
    return values, mask


@cache
def intensity_exponents() -> Mapping[str, float]:
    """Expression name -> exponent of its intensity curve (``intensity.csv``)."""
    out = {}
    for line, row in data.csv_rows(_CURVES):
        exponent = _number(row, "exponent", _CURVES, line)
        if not 0.2 <= exponent <= 3.0:
            raise DataError(f"exponent {exponent} is outside 0.2-3",
                            path=str(data.path(_CURVES)), line=line)
        out[row["expression"]] = exponent
    return MappingProxyType(out)
