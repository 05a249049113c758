"""FAP relationships (first seed, eq. 4.17): untracked FAPs from tracked ones.

``FAP_N = c_RN * FAP_R`` with the coefficients of ``facelib/data/tracking/relations.csv``;
rows labelled with a high-level state (``pucker``) replace the default rows of the same
target in the frames that carry the state.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache

import numpy as np

from facelib.data import csv_rows
from facelib.data import path as data_path
from facelib.errors import DataError, ParameterError
from facelib.mpeg4 import N_FAPS

__all__ = ["Relation", "apply_relations", "relations", "states"]


@dataclass(frozen=True)
class Relation:
    """``FAP target = coefficient * FAP source`` (ids 1-84), in frames with ``state`` ("" =
    the default relation)."""

    target: int
    source: int
    coefficient: float
    state: str


@cache
def relations() -> tuple[Relation, ...]:
    """Every row of ``tracking/relations.csv``."""
    name = "tracking/relations.csv"
    out = []
    for line, row in csv_rows(name):
        try:
            rel = Relation(int(row["target"]), int(row["source"]), float(row["coefficient"]),
                           row["state"])
        except ValueError:
            raise DataError(f"bad relation row {row}", path=str(data_path(name)),
                            line=line) from None
        if not (3 <= rel.target <= N_FAPS and 3 <= rel.source <= N_FAPS):
            raise DataError(f"FAP ids must be 3-{N_FAPS}", path=str(data_path(name)), line=line)
        out.append(rel)
    return tuple(out)


def states() -> tuple[str, ...]:
    """The high-level states the table knows (``("pucker",)``)."""
    return tuple(sorted({r.state for r in relations() if r.state}))


def apply_relations(values: np.ndarray, mask: np.ndarray, *,
                    frame_states: Mapping[str, np.ndarray] | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Fill FAPs by eq. 4.17.

    Parameters
    ----------
    values: ``(n, 84) float`` FAP values; column k-1 is FAP k.
    mask: ``(n, 84) bool``, which FAPs were measured.
    frame_states: state name -> ``(n,) bool``, the frames carrying that label.

    Returns
    -------
    New ``(values, mask)``: default relations fill unmeasured targets whose source is
    measured; state relations overwrite their targets in the labelled frames.
    """
    values = np.array(values, np.float64)
    mask = np.array(mask, bool)
    measured = mask.copy()
    for rel in relations():
        if rel.state:
            continue
        src, dst = rel.source - 1, rel.target - 1
        fill = measured[:, src] & ~measured[:, dst]
        values[fill, dst] = rel.coefficient * values[fill, src]
        mask[:, dst] |= fill
    known = states()
    for state, labelled in (frame_states or {}).items():
        if state not in known:
            raise ParameterError(f"unknown high-level state {state!r}; known: {known}")
        frames = np.asarray(labelled, bool)
        if frames.shape != (len(values),):
            raise ParameterError(f"state {state!r} needs ({len(values)},) bools, got "
                                 f"{frames.shape}")
        for rel in relations():
            if rel.state != state:
                continue
            src, dst = rel.source - 1, rel.target - 1
            sel = frames & measured[:, src]
            values[sel, dst] = rel.coefficient * values[sel, src]
            mask[sel, dst] = True
    return values, mask
