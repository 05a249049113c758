"""OptionalModule dependencies: the one way facelib imports a package behind an extra.

Which module each use imports, the package that ships it and the extra that installs it
are data (``facelib/data/optional.csv``); :func:`require` imports the module and, when it is
missing, raises :class:`~facelib.errors.MissingExtraError` naming the feature, the package
and ``pip install 'facelib[extra]'``.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType, ModuleType

from facelib import data
from facelib.errors import DataError, MissingExtraError

__all__ = ["OptionalModule", "missing_extra", "optional_uses", "require"]


@dataclass(frozen=True)
class OptionalModule:
    """One row of ``optional.csv``: ``use`` imports ``module``, shipped by ``package`` in
    ``extra``, for ``feature``."""

    use: str
    module: str
    package: str
    extra: str
    feature: str


@cache
def optional_uses() -> Mapping[str, OptionalModule]:
    """use -> :class:`OptionalModule`, from ``facelib/data/optional.csv``."""
    table: dict[str, OptionalModule] = {}
    for line, row in data.csv_rows("optional.csv"):
        if row["use"] in table:
            raise DataError(f"use {row['use']!r} repeats", path="optional.csv", line=line)
        table[row["use"]] = OptionalModule(**row)
    return MappingProxyType(table)


def missing_extra(use: str) -> MissingExtraError:
    """The error to raise when the module of ``use`` cannot be imported."""
    row = optional_uses()[use]
    return MissingExtraError(row.feature, row.extra, row.package)


def require(use: str) -> ModuleType:
    """The module of ``use`` (a row of ``optional.csv``), imported.

    Raises MissingExtraError (an ImportError) when it is not installed; a ``use`` not in the
    table is a KeyError (a mistake in facelib, not in the caller's installation).
    """
    row = optional_uses()[use]
    try:
        return importlib.import_module(row.module)
    except ImportError as exc:
        raise missing_extra(use) from exc
