"""The MPEG-4 facial animation vocabulary: FAPs, feature points and FAPU.

The tables are package data (``facelib/data/mpeg4_faps.csv`` and
``facelib/data/mpeg4_feature_points.csv``) copied from the project's reference tables, which
cite their sources. They are read once, on first use.

Coordinate frame: right-handed, +x is the face's own left, +y up, +z out of the face.
FAP values are in FAP units: a translation FAP of 1 moves its feature point by 1/1024 of
its FAPU distance; a rotation FAP of 1 is 1e-5 rad (``ANGLE_UNIT``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType
from typing import Literal

import numpy as np

from facelib import data
from facelib.checks import did_you_mean
from facelib.errors import DataError, ParameterError

__all__ = [
    "ANGLE_UNIT",
    "EXTENDED_FAPS",
    "FAPU_NAMES",
    "FAPU_SCALE",
    "N_FAPS",
    "N_STANDARD_FAPS",
    "Fap",
    "FeaturePoint",
    "fap",
    "fap_groups",
    "fap_table",
    "feature_point",
    "feature_point_table",
]

N_FAPS = 84
"""FAPs 1-68 of the standard plus the thesis's extended FAPs 69-84 (annex A, table A.3)."""
N_STANDARD_FAPS = 68
EXTENDED_FAPS = range(69, 85)
ANGLE_UNIT = 1e-5
"""The angle unit AU in radians."""
FAPU_SCALE = 1024.0
"""A distance FAPU is its neutral-face distance divided by this (e.g. MNS = MNS0 / 1024)."""
FAPU_NAMES = ("IRISD", "ES", "ENS", "MNS", "MW", "AU")
"""The five distance units of the standard and the angle unit."""

Kind = Literal["special", "translation", "rotation"]


@dataclass(frozen=True, slots=True)
class Fap:
    """One facial animation parameter.

    Attributes
    ----------
    id: 1-84; the FAP's column in a stream is ``id - 1``.
    name: lower-case name (``open_jaw``, ``stretch_t_lip_lm``).
    group: 1-10 for the standard FAPs, 11 for the extended ones.
    feature_points: ids of the feature points it moves (``("2.1",)``; empty for 1-2).
    kind: ``"translation"``, ``"rotation"`` or ``"special"`` (high level, pupils, tongue roll).
    axis: ``"x"``, ``"y"``, ``"z"`` or ``""`` (displacement axis, or rotation axis).
    positive_direction: the motion of a positive value in words (``"down"``, ``"left"``).
    direction: (3,) float64, the direction a positive value moves its point, in the face frame.
    fapu: one of ``FAPU_NAMES``, or ``"none"`` for FAP 1-2.
    bidirectional: True (B), False (U), or None where the source does not say.
    min, max: plausible value range in FAP units, or None where no source gives one.
    """

    id: int
    name: str
    group: int
    feature_points: tuple[str, ...]
    kind: Kind
    axis: str
    positive_direction: str
    direction: tuple[float, float, float]
    fapu: str
    bidirectional: bool | None
    min: float | None
    max: float | None

    @property
    def index(self) -> int:
        """The FAP's column in ``FapStream.values`` (``id - 1``)."""
        return self.id - 1

    @property
    def extended(self) -> bool:
        """True for the thesis's extended FAPs 69-84, which are not in the standard."""
        return self.id > N_STANDARD_FAPS


@dataclass(frozen=True, slots=True)
class FeaturePoint:
    """One MPEG-4 feature point (``"2.1"`` ... ``"11.6"``).

    Attributes
    ----------
    id: ``"<group>.<index>"``.
    group: 2-11.
    region: ``"jaw"``, ``"inner lip"``, ``"eye"``, ...
    side: ``"left"``, ``"right"`` or ``"center"`` (the face's own sides).
    description: where the point lies on the face.
    fapu_uses: the neutral distances it helps define (``("MNS0",)``), empty if none.
    faps: ids of the FAPs that move it.
    """

    id: str
    group: int
    region: str
    side: str
    description: str
    fapu_uses: tuple[str, ...]
    faps: tuple[int, ...]


def _split(text: str) -> tuple[str, ...]:
    return tuple(part for part in text.split(";") if part)


def _number(text: str) -> float | None:
    return float(text) if text else None


@cache
def fap_table() -> tuple[Fap, ...]:
    """All 84 FAPs in id order (element ``k`` is FAP ``k + 1``)."""
    rows = _read_csv("mpeg4_faps.csv")
    faps = tuple(
        Fap(
            id=int(row["id"]),
            name=row["name"].lower(),
            group=int(row["group"]),
            feature_points=_split(row["feature_point"]),
            kind=row["kind"],  # type: ignore[arg-type]
            axis=row["axis"],
            positive_direction=row["positive_direction"],
            direction=tuple(float(v) for v in row["direction_vector"].split()),  # type: ignore[arg-type]
            fapu=row["fapu"],
            bidirectional={"B": True, "U": False}.get(row["bidirectional"]),
            min=_number(row["min"]),
            max=_number(row["max"]),
        )
        for row in rows
    )
    if [f.id for f in faps] != list(range(1, N_FAPS + 1)):  # pragma: no cover - data check
        raise DataError("must list FAPs 1-84 in order", path=str(data.path("mpeg4_faps.csv")))
    return faps


@cache
def fap_groups() -> Mapping[int, str]:
    """FAP group number -> its name in the standard (``mpeg4_fap_groups.csv``); every
    :attr:`Fap.group` is one of them."""
    return MappingProxyType(
        {int(row["group"]): row["name"] for _, row in data.csv_rows("mpeg4_fap_groups.csv")}
    )


@cache
def feature_point_table() -> dict[str, FeaturePoint]:
    """All feature points by id (``"2.1"`` ... ``"11.6"``), in table order."""
    return {
        row["id"]: FeaturePoint(
            id=row["id"],
            group=int(row["group"]),
            region=row["region"],
            side=row["side"],
            description=row["description"],
            fapu_uses=_split(row["fapu_use"]),
            faps=tuple(int(v) for v in _split(row["faps"])),
        )
        for row in _read_csv("mpeg4_feature_points.csv")
    }


@cache
def _fap_by_name() -> dict[str, Fap]:
    return {f.name: f for f in fap_table()}


def fap(key: int | str) -> Fap:
    """Look up a FAP by id (1-84, or its digits as a string) or by name, case-insensitive.

    >>> fap("OPEN_JAW").id
    3
    >>> fap(69).name
    'stretch_t_lip_lm'
    """
    if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
        if 1 <= key <= N_FAPS:
            return fap_table()[int(key) - 1]
        raise ParameterError(f"FAP id {key!r} is outside 1-{N_FAPS}")
    if isinstance(key, str):
        text = key.strip()
        if text.isdigit():
            return fap(int(text))
        found = _fap_by_name().get(text.lower())
        if found is not None:
            return found
        hint = did_you_mean(text.lower(), _fap_by_name())
        raise ParameterError(f"unknown FAP name {key!r}{hint}")
    raise ParameterError(f"a FAP is named by id or name, not {key!r}")


def feature_point(key: str) -> FeaturePoint:
    """Look up a feature point by id (``"3.5"``)."""
    found = feature_point_table().get(str(key).strip())
    if found is None:
        raise ParameterError(
            f"unknown feature point {key!r}{did_you_mean(str(key), feature_point_table())}"
        )
    return found


def _read_csv(name: str) -> list[dict[str, str]]:
    return [row for _, row in data.csv_rows(name)]
