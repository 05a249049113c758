"""facelib's package data and the one reader for it.

Rules live in data files here (CSV with ``#`` comments, JSON); every module reads them
through :func:`csv_rows`, :func:`json_data` or :func:`text`, so a broken file raises one
:class:`~facelib.errors.DataError` naming the file and line.
"""

from __future__ import annotations

import csv
import io
import json
from importlib import resources
from importlib.resources.abc import Traversable
from typing import Any

from facelib.errors import DataError

__all__ = ["csv_rows", "json_data", "path", "text"]


def path(name: str) -> Traversable:
    """The package data file ``name``, relative to ``facelib/data/`` (``"gaze/model.json"``)."""
    return resources.files("facelib").joinpath("data", *name.split("/"))


def text(name: str) -> str:
    """The UTF-8 text of data file ``name``; DataError if it is missing or unreadable."""
    try:
        return path(name).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read package data: {exc}", path=str(path(name))) from exc


def csv_rows(name: str) -> list[tuple[int, dict[str, str]]]:
    """Rows of the commented CSV ``name`` as ``(1-based line number, row)``.

    Lines starting with ``#`` and blank lines are skipped; the first other line is the header.
    A row with more or fewer cells than the header raises DataError with its line.
    """
    kept = [(i + 1, line) for i, line in enumerate(text(name).splitlines())
            if line.strip() and not line.lstrip().startswith("#")]
    if not kept:
        raise DataError("no header row", path=str(path(name)))
    reader = csv.reader(io.StringIO("\n".join(line for _, line in kept)))
    rows = list(reader)
    header = [h.strip() for h in rows[0]]
    out = []
    for (line, _), cells in zip(kept[1:], rows[1:], strict=True):
        if len(cells) != len(header):
            raise DataError(f"{len(cells)} cells where the header has {len(header)}",
                            path=str(path(name)), line=line)
        out.append((line, dict(zip(header, (c.strip() for c in cells), strict=True))))
    return out


def json_data(name: str) -> Any:
    """The parsed JSON data file ``name``, with keys starting ``_`` (comments) dropped from
    the top-level object."""
    try:
        doc = json.loads(text(name))
    except json.JSONDecodeError as exc:
        raise DataError(f"invalid JSON: {exc.msg}", path=str(path(name)), line=exc.lineno) from exc
    if isinstance(doc, dict):
        return {k: v for k, v in doc.items() if not k.startswith("_")}
    return doc
