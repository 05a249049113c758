"""The 15 MPEG-4 visemes (FAP 1 ``viseme_select`` values 0-14) and every name a script may
give them: the standard's names (``sil``, ``PP``, ... ``ou``) and the thesis's script names
(``silence``, ``pbm``, ... ``U``), from ``facelib/data/mpeg4_visemes.csv``."""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib import data
from facelib.errors import DataError, ParameterError

__all__ = [
    "N_VISEMES", "script_name", "viseme_aliases", "viseme_id", "viseme_name", "viseme_names",
]

N_VISEMES = 15


@cache
def _viseme_names() -> tuple[
    tuple[str, ...], Mapping[str, int], Mapping[str, int], tuple[str, ...]
]:
    """(MPEG-4 names, exact alias -> id, unambiguous lower-case alias -> id, script names)."""
    names: list[str] = []
    script: list[str] = []
    exact: dict[str, int] = {}
    folded: dict[str, set[int]] = {}
    for line, row in data.csv_rows("mpeg4_visemes.csv"):
        vid = int(row["id"])
        if vid != len(names):
            raise DataError(f"viseme ids must run 0-14, got {vid}",
                            path=str(data.path("mpeg4_visemes.csv")), line=line)
        names.append(row["name"])
        script.append(row["thesis_names"].split()[0])
        for alias in (row["name"], str(vid), *row["thesis_names"].split()):
            exact.setdefault(alias, vid)
            folded.setdefault(alias.lower(), set()).add(vid)
    unique = {k: next(iter(v)) for k, v in folded.items() if len(v) == 1}
    return tuple(names), MappingProxyType(exact), MappingProxyType(unique), tuple(script)


def viseme_names() -> tuple[str, ...]:
    """The 15 MPEG-4 viseme names in id order."""
    return _viseme_names()[0]


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
