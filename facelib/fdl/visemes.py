"""Viseme names a stored viseme script may use: those of ``facelib.visemes`` (one table,
``facelib/data/mpeg4_visemes.csv``), checked with the script's file and line."""

from __future__ import annotations

from facelib.checks import did_you_mean
from facelib.errors import FdlError, ParameterError
from facelib.mpeg4.visemes import viseme_aliases
from facelib.mpeg4.visemes import viseme_id as _viseme_id

__all__ = ["check_viseme", "viseme_id"]


def viseme_id(name: str) -> int | None:
    """MPEG-4 viseme number (0-14) of a thesis name, short name or number; None if unknown."""
    text = str(name).strip()
    try:
        return _viseme_id(int(text) if text.isdigit() else text)
    except ParameterError:
        return None


def check_viseme(name: str, *, path: str, line: int | None) -> int:
    """MPEG-4 viseme number of ``name``; FdlError (with a suggestion) when unknown."""
    number = viseme_id(name)
    if number is None:
        raise FdlError(
            f"unknown viseme {name!r}{did_you_mean(name, viseme_aliases())} (use the thesis "
            "names silence pbm fv th td kg ch sz nl r A e I Q U, the short names sil PP FF TH "
            "DD kk CH SS nn RR aa E ih oh ou, or numbers 0-14)",
            path=path,
            line=line,
        )
    return number
