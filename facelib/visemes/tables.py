"""The viseme rules as data: loaders for the files in ``facelib/data/visemes/``.

- ``phone_to_viseme.csv``: ARPAbet phone -> viseme (thesis annex B), diphthongs as two.
- ``viseme_faps.json``: each viseme's FAP values (FAP units).
- ``coarticulation.json``: dominance-function parameters and timing rules.

Everything is read once, on first use, and returned as read-only data.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from importlib import resources
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib.errors import FacelibError, ParameterError
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
    "lower_lip_per_jaw",
    "phone_viseme",
    "script_name",
    "timing_rules",
    "viseme_aliases",
    "viseme_id",
    "viseme_name",
    "viseme_targets",
]

_DIR = "data/visemes"


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


def _text(name: str) -> tuple[str, str]:
    path = resources.files("facelib").joinpath(f"{_DIR}/{name}")
    return str(path), path.read_text(encoding="utf-8")


def _csv_rows(name: str) -> list[tuple[int, dict[str, str]]]:
    """Rows of a commented CSV as (1-based line number, row dict)."""
    lines = _text(name)[1].splitlines()
    kept = [(i + 1, line) for i, line in enumerate(lines) if line and not line.startswith("#")]
    reader = csv.DictReader(io.StringIO("\n".join(line for _, line in kept)))
    rows = list(reader)
    return [(kept[i + 1][0], row) for i, row in enumerate(rows)]


def _data_error(name: str, line: int | None, message: str) -> FacelibError:
    path, _ = _text(name)
    return FacelibError(message, path=path, line=line)


@cache
def _phone_table() -> Mapping[str, PhoneViseme]:
    table: dict[str, PhoneViseme] = {}
    for line, row in _csv_rows("phone_to_viseme.csv"):
        phone = row["phone"]
        if row["sequence"]:
            visemes = tuple(int(v) for v in row["sequence"].split(">"))
            split = float(row["split"])
        else:
            visemes, split = (int(row["viseme"]),), 1.0
        if not all(0 <= v < N_VISEMES for v in visemes) or not 0 < split <= 1:
            raise _data_error("phone_to_viseme.csv", line, f"bad row for phone {phone!r}")
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
    path, text = _text("viseme_faps.json")
    data = json.loads(text)
    targets = np.zeros((N_VISEMES, N_FAPS), np.float32)
    names = viseme_names()
    if set(data["visemes"]) != set(names):
        raise FacelibError(f"visemes {sorted(data['visemes'])} differ from {names}", path=path)
    for vid, name in enumerate(names):
        for fap_name, value in data["visemes"][name]["faps"].items():
            try:
                targets[vid, fap(fap_name).index] = float(value)
            except ParameterError as exc:
                raise FacelibError(f"viseme {name!r}: {exc.message}", path=path) from exc
    targets.flags.writeable = False
    return targets


@cache
def _coarticulation() -> dict[str, Any]:
    path, text = _text("coarticulation.json")
    data = json.loads(text)
    data["_path"] = path
    return data


@cache
def coarticulation_classes() -> Mapping[str, tuple[int, ...]]:
    """FAP class name -> 0-based FAP columns (jaw, lip_height, lip_shape, tongue). Together
    they are the FAPs the viseme track drives."""
    data = _coarticulation()
    out: dict[str, tuple[int, ...]] = {}
    for cls, members in data["classes"].items():
        try:
            out[cls] = tuple(fap(m).index for m in members)
        except ParameterError as exc:
            raise FacelibError(f"class {cls!r}: {exc.message}", path=data["_path"]) from exc
    return MappingProxyType(out)


@cache
def dominance_table() -> Mapping[tuple[int, str], Dominance]:
    """(viseme id, FAP class) -> :class:`Dominance`, defaults filled in."""
    data = _coarticulation()
    default = data["default"]
    out: dict[tuple[int, str], Dominance] = {}
    for vid, name in enumerate(viseme_names()):
        rules = data["visemes"].get(name, {})
        for cls in data["classes"]:
            params = {**default, **rules.get("*", {}), **rules.get(cls, {})}
            dom = Dominance(
                float(params["alpha"]),
                float(params["theta_before"]),
                float(params["theta_after"]),
            )
            if dom.alpha <= 0 or dom.theta_before <= 0 or dom.theta_after <= 0:
                raise FacelibError(f"non-positive dominance for {name}/{cls}", path=data["_path"])
            out[vid, cls] = dom
    return MappingProxyType(out)


@cache
def lower_lip_per_jaw() -> float:
    """MNS of lower-lip drop per unit of open_jaw (``lower_lip_per_jaw`` of the data file)."""
    return float(_coarticulation().get("lower_lip_per_jaw", 1.0))


@cache
def timing_rules() -> Mapping[str, int]:
    """Timing rules in ms: ``min_visible_ms``, ``merge_silence_below_ms``,
    ``envelope_ramp_ms``, ``release_pause_ms``."""
    timing = _coarticulation()["timing"]
    return MappingProxyType({k: int(v) for k, v in timing.items() if not k.startswith("_")})

