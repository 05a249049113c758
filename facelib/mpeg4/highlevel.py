"""High-level FAPs 1 and 2 decoded into low-level FAP values, as an MPEG-4 decoder does.

FAP 1 (viseme) selects two of the 15 visemes and blends them::

    viseme = (blend * V[select1] + (63 - blend) * V[select2]) / 63

FAP 2 (expression) selects two of the six standard expressions (1 joy, 2 sadness, 3 anger,
4 fear, 5 disgust, 6 surprise; 0 is neutral) with their own intensities::

    expression = intensity1 / 63 * E[select1] + intensity2 / 63 * E[select2]

``V`` and ``E`` are the FAP values of facelib's viseme table
(``facelib/data/visemes/viseme_faps.json``) and expression library (composed from its
action units, :mod:`facelib.mpeg4.action_units`) at full intensity. The viseme and the
expression add up;
a low-level FAP that the frame sets itself keeps its own value (the file's author animated
it explicitly), every other FAP takes the decoded value.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from facelib import data
from facelib.errors import DataError
from facelib.mpeg4.action_units import compose, recipes
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.mpeg4.visemes import N_VISEMES, viseme_names

__all__ = ["EXPRESSION_IDS", "apply_high_level", "expression_table", "viseme_table"]

EXPRESSION_IDS = ("neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise")
"""FAP 2 ``expression_select`` values 0-6 (ISO/IEC 14496-2, table C.3)."""
_SCALE = 63.0  # viseme_blend and expression intensities run 0-63


@cache
def viseme_table() -> np.ndarray:
    """(15, 84) float32: FAP values of each viseme id at full intensity (read-only)."""
    source = data.json_data("visemes/viseme_faps.json")["visemes"]
    out = np.zeros((N_VISEMES, N_FAPS), np.float32)
    for vid, name in enumerate(viseme_names()):
        if name not in source:
            raise DataError(f"viseme {name!r} is missing",
                            path=str(data.path("visemes/viseme_faps.json")))
        for key, value in source[name]["faps"].items():
            out[vid, fap(key).index] = float(value)
    out.flags.writeable = False
    return out


@cache
def expression_table() -> np.ndarray:
    """(7, 84) float32: FAP values of each FAP 2 expression id (row 0 neutral: zeros)."""
    out = np.zeros((len(EXPRESSION_IDS), N_FAPS), np.float32)
    table = recipes()
    for i, name in enumerate(EXPRESSION_IDS[1:], start=1):
        if name not in table:
            raise DataError(f"expression {name!r} is missing",
                            path=str(data.path("expressions/expressions.csv")))
        out[i] = compose(table[name].parts)[0]
    out.flags.writeable = False
    return out


def _selected(table: np.ndarray, select: np.ndarray) -> np.ndarray:
    """Rows of ``table`` for ids ``select`` (n,); ids outside the table give zeros."""
    ok = (select >= 0) & (select < len(table))
    out = np.zeros((len(select), N_FAPS), np.float32)
    out[ok] = table[select[ok]]
    return out


def decode_high_level(stream: FapStream) -> np.ndarray:
    """(n_frames, 84) float32: the low-level values that FAP 1 and 2 of each frame mean.

    Frames without FAP 1/2 (mask columns 0, 1 unset) contribute zeros.
    """
    out = np.zeros((stream.n_frames, N_FAPS), np.float32)
    if stream.viseme is not None:
        v = stream.viseme.astype(np.int64)
        blend = np.clip(v[:, 2], 0, 63)[:, None] / _SCALE
        vis = blend * _selected(viseme_table(), v[:, 0]) + (1 - blend) * _selected(
            viseme_table(), v[:, 1])
        out += np.where(stream.mask[:, :1], vis, 0).astype(np.float32)
    if stream.expression is not None:
        e = stream.expression.astype(np.int64)
        table = expression_table()
        expr = (np.clip(e[:, 1], 0, 63)[:, None] / _SCALE * _selected(table, e[:, 0])
                + np.clip(e[:, 3], 0, 63)[:, None] / _SCALE * _selected(table, e[:, 2]))
        out += np.where(stream.mask[:, 1:2], expr, 0).astype(np.float32)
    return out


def apply_high_level(stream: FapStream) -> FapStream:
    """``stream`` with FAP 1/2 decoded into the low-level FAPs the frames do not set.

    A stream without FAP 1/2 data is returned unchanged (the same object). The result keeps
    the viseme and expression fields; its mask gains the FAPs that the decoding set.
    """
    if not stream.n_frames or not stream.mask[:, :2].any() or (
            stream.viseme is None and stream.expression is None):
        return stream
    decoded = decode_high_level(stream)
    free = ~stream.mask
    free[:, :2] = False
    values = np.where(free, decoded, stream.values)
    mask = stream.mask | (free & (decoded != 0))
    return FapStream(stream.fps, values, mask, stream.viseme, stream.expression)
