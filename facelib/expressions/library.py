"""The expression library: named sets of FAP values at full intensity.

The default library is built from FACS action units: ``facelib/data/expressions/`` holds
the units' FAP amplitudes (``action_units.csv``), each expression as a combination of units
(``expressions.csv``, with a note on every part) and each expression's intensity curve
(``intensity.csv``); :mod:`facelib.mpeg4.action_units` composes them. Storyboards add or
override expressions with ``Storyboard.expression_defs``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib.checks import did_you_mean
from facelib.cues import Origin
from facelib.errors import FdlError, ParameterError
from facelib.mpeg4.action_units import compose, intensity_exponents, recipes
from facelib.mpeg4.tables import N_FAPS, fap

__all__ = ["Expression", "ExpressionLibrary", "default_library"]

# FAP values at full intensity by FAP name or 1-based id, in FAP units.
FapValues = Mapping[str, float] | Mapping[int, float] | Mapping[str | int, float]


@dataclass(frozen=True, eq=False)
class Expression:
    """One expression at full intensity.

    values: ``(84,) float32`` FAP values in FAP units (0 where the expression is silent).
    mask: ``(84,) bool``, the FAPs the expression drives.
    exponent: its intensity curve, ``share = intensity ** exponent`` (1: linear).
    parts: the action units (``("AU4", 1.0)``) and FAPs it is made of; empty for an
        expression given as FAP values.
    """

    name: str
    values: np.ndarray
    mask: np.ndarray
    exponent: float = 1.0
    parts: tuple[tuple[str, float], ...] = ()

    def share(self, intensity: float) -> float:
        """The share of the full FAP values shown at cue ``intensity``: its intensity curve,
        mirrored for negative intensities (0.6 ** 0.6 = 0.74 with an exponent of 0.6)."""
        return float(np.sign(intensity) * abs(intensity) ** self.exponent)

    @classmethod
    def from_faps(cls, name: str, faps: FapValues) -> Expression:
        """Build from ``{FAP name or id: value}``; unknown FAPs raise ``ParameterError``."""
        values = np.zeros(N_FAPS, np.float32)
        mask = np.zeros(N_FAPS, bool)
        for key, value in faps.items():
            column = fap(key).index
            if column < 2:
                raise ParameterError(f"expression {name!r}: FAP {key!r} is high level; "
                                     "give low-level FAPs 3-84")
            if not np.isfinite(float(value)):
                raise ParameterError(f"expression {name!r}: FAP {key!r} value {value!r} "
                                     "is not finite")
            values[column] = float(value)
            mask[column] = True
        values.flags.writeable = False
        mask.flags.writeable = False
        return cls(name, values, mask)


@dataclass(frozen=True)
class ExpressionLibrary:
    """Expressions by lower-case name."""

    expressions: Mapping[str, Expression]

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name.lower() in self.expressions

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.expressions)

    def get(self, name: str, *, origin: Origin | None = None) -> Expression:
        """The expression called ``name`` (case-insensitive).

        An unknown name raises ``FdlError`` at ``origin`` (the script line that asked for
        it), suggesting the closest known name.
        """
        found = self.expressions.get(name.lower())
        if found is not None:
            return found
        hint = did_you_mean(name, self.names)
        path, line = origin if origin is not None else (None, None)
        raise FdlError(f"unknown expression {name!r}{hint} (known: {', '.join(self.names)})",
                       path=path, line=line)

    def with_defs(
        self,
        defs: Mapping[str, FapValues],
        *,
        mixes: Mapping[str, Mapping[str, float]] | None = None,
    ) -> ExpressionLibrary:
        """A library with storyboard definitions added or replacing entries.

        defs: name -> {FAP: value at full intensity}.
        mixes: name -> {library expression: weight}; the mix is the weighted sum of those
            expressions, with the FAPs of ``defs[name]`` (if any) set on top.
        """
        if not defs and not mixes:
            return self
        merged = dict(self.expressions)
        for name, parts in (mixes or {}).items():
            values = np.zeros(N_FAPS, np.float64)
            mask = np.zeros(N_FAPS, bool)
            for part, weight in parts.items():
                expression = self.get(part)
                values += float(weight) * expression.values
                mask |= expression.mask
            faps: dict[str | int, float] = {
                int(i) + 1: float(values[i]) for i in np.flatnonzero(mask)
            }
            faps.update(defs.get(name, {}).items())
            merged[name.lower()] = Expression.from_faps(name.lower(), faps)
        for name, own in defs.items():
            if name not in (mixes or {}):
                merged[name.lower()] = Expression.from_faps(name.lower(), own)
        return ExpressionLibrary(MappingProxyType(merged))


@cache
def default_library() -> ExpressionLibrary:
    """The expressions shipped with facelib, composed from their action units (read once)."""
    exponents = intensity_exponents()
    out = {}
    for name, recipe in recipes().items():
        values, mask = compose(recipe.parts)
        values32 = values.astype(np.float32)
        values32.flags.writeable = False
        mask.flags.writeable = False
        out[name] = Expression(name, values32, mask, exponents.get(name, 1.0), recipe.parts)
    return ExpressionLibrary(MappingProxyType(out))
