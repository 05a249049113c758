"""The viseme rules as data: loaders for the files in ``facelib/data/visemes/``.

- ``phone_to_viseme.csv``: ARPAbet phone -> viseme (thesis annex B), diphthongs as two.
- ``viseme_faps.json``: each viseme's FAP values (FAP units).
- ``coarticulation.json``: dominance-function parameters and timing rules.

Everything is read once, on first use, and returned as read-only data.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib import data
from facelib.errors import DataError, ParameterError
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.mpeg4.visemes import (
    N_VISEMES,
    script_name,
    viseme_aliases,
    viseme_id,
    viseme_name,
    viseme_names,
)

__all__ = [
    "N_VISEMES",
    "Dominance",
    "PhoneViseme",
    "coarticulation_classes",
    "dominance_table",
    "loudness_rules",
    "lower_lip_per_jaw",
    "peak_hold",
    "phone_viseme",
    "script_name",
    "timing_rules",
    "viseme_aliases",
    "viseme_id",
    "viseme_name",
    "viseme_targets",
]

_DIR = "visemes"


@dataclass(frozen=True, slots=True)
class PhoneViseme:
    """How one phone is shown: ``visemes`` (one, or two for a diphthong) and ``split``, the
    share of the phone's duration given to the first of two visemes."""

    phone: str
    visemes: tuple[int, ...]
    split: float


@dataclass(frozen=True, slots=True)
class Dominance:
    """Dominance-function parameters of one viseme for one FAP class (coarticulation.json):
    magnitude ``alpha`` and fall-off rates ``theta_before`` / ``theta_after`` in 1/s."""

    alpha: float
    theta_before: float
    theta_after: float


def _where(name: str) -> str:
    return str(data.path(f"{_DIR}/{name}"))


@cache
def _phone_table() -> Mapping[str, PhoneViseme]:
    table: dict[str, PhoneViseme] = {}
    for line, row in data.csv_rows(f"{_DIR}/phone_to_viseme.csv"):
        phone = row["phone"]
        try:
            if row["sequence"]:
                visemes = tuple(int(v) for v in row["sequence"].split(">"))
                split = float(row["split"])
            else:
                visemes, split = (int(row["viseme"]),), 1.0
        except ValueError:
            visemes, split = (), 0.0
        if not visemes or not all(0 <= v < N_VISEMES for v in visemes) or not 0 < split <= 1:
            raise DataError(f"bad row for phone {phone!r}: {row}",
                            path=_where("phone_to_viseme.csv"), line=line)
        table[phone] = PhoneViseme(phone, visemes, split)
    return MappingProxyType(table)


def phone_viseme(phone: str) -> PhoneViseme:
    """How ARPAbet ``phone`` (stress digits allowed, ``"AY1"``) is shown."""
    key = phone.strip().upper().rstrip("012")
    table = _phone_table()
    if key not in table:
        raise ParameterError(
            f"unknown phone {phone!r}; expected ARPAbet (pocketsphinx en-us set) or SIL"
        )
    return table[key]


@cache
def viseme_targets() -> np.ndarray:
    """``(15, 84) float32`` FAP values of each viseme at full intensity, in FAP units."""
    path = _where("viseme_faps.json")
    doc = data.json_data(f"{_DIR}/viseme_faps.json")
    targets = np.zeros((N_VISEMES, N_FAPS), np.float32)
    names = viseme_names()
    if set(doc["visemes"]) != set(names):
        raise DataError(f"visemes {sorted(doc['visemes'])} differ from {names}", path=path)
    for vid, name in enumerate(names):
        for fap_name, value in doc["visemes"][name]["faps"].items():
            try:
                targets[vid, fap(fap_name).index] = float(value)
            except ParameterError as exc:
                raise DataError(f"viseme {name!r}: {exc.message}", path=path) from exc
    targets.flags.writeable = False
    return targets


@cache
def _coarticulation() -> dict[str, Any]:
    doc: dict[str, Any] = data.json_data(f"{_DIR}/coarticulation.json")
    return doc


@cache
def coarticulation_classes() -> Mapping[str, tuple[int, ...]]:
    """FAP class name -> 0-based FAP columns (jaw, lip_height, lip_shape, tongue). Together
    they are the FAPs the viseme track drives."""
    doc = _coarticulation()
    path = _where("coarticulation.json")
    out: dict[str, tuple[int, ...]] = {}
    for cls, members in doc["classes"].items():
        try:
            out[cls] = tuple(fap(m).index for m in members)
        except ParameterError as exc:
            raise DataError(f"class {cls!r}: {exc.message}", path=path) from exc
    return MappingProxyType(out)


@cache
def dominance_table() -> Mapping[tuple[int, str], Dominance]:
    """(viseme id, FAP class) -> :class:`Dominance`, defaults filled in."""
    doc = _coarticulation()
    path = _where("coarticulation.json")
    default = doc["default"]
    out: dict[tuple[int, str], Dominance] = {}
    for vid, name in enumerate(viseme_names()):
        rules = doc["visemes"].get(name, {})
        for cls in doc["classes"]:
            params = {**default, **rules.get("*", {}), **rules.get(cls, {})}
            dom = Dominance(
                float(params["alpha"]),
                float(params["theta_before"]),
                float(params["theta_after"]),
            )
            if dom.alpha <= 0 or dom.theta_before <= 0 or dom.theta_after <= 0:
                raise DataError(f"non-positive dominance for {name}/{cls}", path=path)
            out[vid, cls] = dom
    return MappingProxyType(out)


@cache
def loudness_rules() -> Mapping[str, float]:
    """The ``loudness`` rules of the data file (see :mod:`facelib.visemes.loudness`)."""
    raw = _coarticulation()["loudness"]
    return MappingProxyType({k: float(v) for k, v in raw.items() if not k.startswith("_")})


@cache
def lower_lip_per_jaw() -> float:
    """MNS of lower-lip drop per unit of open_jaw (``lower_lip_per_jaw`` of the data file)."""
    return float(_coarticulation().get("lower_lip_per_jaw", 1.0))


@cache
def peak_hold() -> np.ndarray:
    """``(15,) float64`` 1/s: how fast each viseme's dominance grows with the depth into its
    own span (``peak_hold`` of the data file; 0 for visemes it does not hold; see
    :func:`facelib.visemes.coarticulation.blend`)."""
    raw = _coarticulation().get("peak_hold", {"rate": 0.0, "visemes": []})
    path = _where("coarticulation.json")
    rate = float(raw["rate"])
    if not rate >= 0:
        raise DataError(f"peak_hold rate must be >= 0, got {rate}", path=path)
    out = np.zeros(N_VISEMES)
    try:
        out[[viseme_id(name) for name in raw["visemes"]]] = rate
    except ParameterError as exc:
        raise DataError(f"peak_hold: {exc.message}", path=path) from exc
    out.flags.writeable = False
    return out


@cache
def timing_rules() -> Mapping[str, int]:
    """Timing rules in ms: ``min_visible_ms``, ``merge_silence_below_ms``,
    ``envelope_ramp_ms``, ``release_pause_ms``."""
    timing = _coarticulation()["timing"]
    return MappingProxyType({k: int(v) for k, v in timing.items() if not k.startswith("_")})

