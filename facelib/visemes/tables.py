"""The viseme rules as data: loaders for the files in ``facelib/data/visemes/``.

- ``visemes.csv``: the 15 MPEG-4 visemes and the names viseme scripts use for them.
- ``phone_to_viseme.csv``: ARPAbet phone -> viseme (thesis annex B), diphthongs as two.
- ``viseme_faps.json``: each viseme's FAP values (FAP units).
- ``coarticulation.json``: dominance-function parameters and timing rules.
- ``phone_durations.csv``: the text-only duration model.
- ``letter_to_sound.csv``: pronunciations for words missing from the dictionary.

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

__all__ = [
    "N_VISEMES",
    "Dominance",
    "PhoneViseme",
    "coarticulation_classes",
    "dominance_table",
    "letter_to_sound_rules",
    "phone_durations",
    "phone_viseme",
    "script_name",
    "timing_rules",
    "viseme_aliases",
    "viseme_id",
    "viseme_name",
    "viseme_targets",
]

N_VISEMES = 15
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
def _viseme_names() -> tuple[
    tuple[str, ...], Mapping[str, int], Mapping[str, int], tuple[str, ...]
]:
    """(MPEG-4 names, exact alias -> id, unambiguous lower-case alias -> id, script names)."""
    names: list[str] = []
    script: list[str] = []
    exact: dict[str, int] = {}
    folded: dict[str, set[int]] = {}
    for line, row in _csv_rows("visemes.csv"):
        vid = int(row["id"])
        if vid != len(names):
            raise _data_error("visemes.csv", line, f"viseme ids must run 0-14, got {vid}")
        names.append(row["name"])
        script.append(row["thesis_names"].split()[0])
        for alias in (row["name"], str(vid), *row["thesis_names"].split()):
            exact.setdefault(alias, vid)
            folded.setdefault(alias.lower(), set()).add(vid)
    unique = {k: next(iter(v)) for k, v in folded.items() if len(v) == 1}
    return tuple(names), MappingProxyType(exact), MappingProxyType(unique), tuple(script)


def script_name(viseme: int) -> str:
    """The name thesis ``Sentence`` scripts use for viseme id 0-14 (``"silence"``,
    ``"pbm"``, ... ``"A"``, ``"U"``)."""
    viseme_name(viseme)
    return _viseme_names()[3][int(viseme)]


def viseme_name(viseme: int) -> str:
    """The MPEG-4 name (``"sil"``, ``"PP"``, ... ``"ou"``) of viseme id 0-14."""
    names = _viseme_names()[0]
    if not (isinstance(viseme, (int, np.integer)) and 0 <= viseme < N_VISEMES):
        raise ParameterError(f"viseme id must be an integer 0-14, got {viseme!r}")
    return names[int(viseme)]


def viseme_aliases() -> Mapping[str, int]:
    """Every name a script may give a viseme (MPEG-4 and thesis names) -> its id 0-14."""
    return _viseme_names()[1]


def viseme_id(name: str | int) -> int:
    """The viseme id 0-14 of ``name``: an MPEG-4 name (``"aa"``), a thesis script name
    (``"A"``, ``"kg"``, ``"silence"``), or the id itself. Case-sensitive first, then any
    case where that is unambiguous (``"td"`` is 4 but ``"TD"`` is 3)."""
    if isinstance(name, (int, np.integer)) and not isinstance(name, bool):
        viseme_name(int(name))
        return int(name)
    _, exact, folded, _ = _viseme_names()
    key = str(name).strip()
    if key in exact:
        return exact[key]
    if key.lower() in folded:
        return folded[key.lower()]
    raise ParameterError(
        f"unknown viseme {name!r}; use an MPEG-4 name ({', '.join(_viseme_names()[0])}) "
        "or a thesis script name (silence, pbm, fv, TD, td, kg, tSdZS, sz, nl, r, A, e, I, Q, U)"
    )


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
    names = _viseme_names()[0]
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
    for vid, name in enumerate(_viseme_names()[0]):
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
def timing_rules() -> Mapping[str, int]:
    """Timing rules in ms: ``min_visible_ms``, ``merge_silence_below_ms``,
    ``envelope_ramp_ms``, ``release_pause_ms``."""
    timing = _coarticulation()["timing"]
    return MappingProxyType({k: int(v) for k, v in timing.items() if not k.startswith("_")})


@cache
def phone_durations() -> Mapping[str, tuple[int, int]]:
    """ARPAbet phone -> (mean_ms, min_ms) at speaking rate 1.0."""
    return MappingProxyType(
        {row["phone"]: (int(row["mean_ms"]), int(row["min_ms"])) for _, row in
         _csv_rows("phone_durations.csv")}
    )


@cache
def letter_to_sound_rules() -> tuple[tuple[str, tuple[str, ...]], ...]:
    """(letter group, phones) rules, longest groups first (ties keep file order)."""
    rules = [
        (row["graphemes"], () if row["phones"] == "-" else tuple(row["phones"].split()))
        for _, row in _csv_rows("letter_to_sound.csv")
    ]
    return tuple(sorted(rules, key=lambda r: -len(r[0])))
