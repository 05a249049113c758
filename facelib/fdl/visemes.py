"""Viseme names a stored viseme script may use (``facelib/data/fdl/viseme_names.csv``)."""

from __future__ import annotations

import csv
import io
from functools import cache
from importlib import resources

from facelib.errors import FdlError
from facelib.fdl.suggest import did_you_mean

__all__ = ["check_viseme", "viseme_id"]


@cache
def _names() -> dict[str, int]:
    text = resources.files("facelib.data").joinpath("fdl/viseme_names.csv").read_text("utf-8")
    rows = csv.DictReader(
        io.StringIO("".join(r for r in text.splitlines(keepends=True) if not r.startswith("#")))
    )
    names: dict[str, int] = {}
    for row in rows:
        number = int(row["id"])
        for key in (row["id"], row["mpeg4"], row["thesis"]):
            names[key] = number
    return names


def viseme_id(name: str) -> int | None:
    """MPEG-4 viseme number (0-14) of a thesis name, short name or number; None if unknown."""
    return _names().get(str(name))


def check_viseme(name: str, *, path: str, line: int | None) -> int:
    """MPEG-4 viseme number of ``name``; FdlError (with a suggestion) when unknown."""
    number = viseme_id(name)
    if number is None:
        raise FdlError(
            f"unknown viseme {name!r}{did_you_mean(name, _names())} (use the thesis names "
            "silence pbm fv th td kg ch sz nl r A e I Q U, the short names sil PP FF TH DD kk "
            "CH SS nn RR aa E ih oh ou, or numbers 0-14)",
            path=path,
            line=line,
        )
    return number
