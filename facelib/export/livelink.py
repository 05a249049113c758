"""ARKit curves as files: Live Link Face's CSV (what the iPhone app records) and JSON.

Live Link Face CSV: a header ``Timecode,BlendShapeCount,EyeBlinkLeft,...,TongueOut,
HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,...,RightEyeRoll`` (the app's order:
:func:`~facelib.export.arkit.live_link_names`) and one row per frame: an SMPTE-style timecode
``HH:MM:SS:FF.mmm`` (frame ``FF`` counted at 60 whatever the row rate, ``.mmm`` thousandths of
a frame), the count 61 (52 blendshapes + 9 angles), the 52 weights in [0, 1] and the 9 angles
in radians. Rows come at 30 or 60 Hz.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
from pathlib import Path

import numpy as np

from facelib.atomic import write_text_atomic
from facelib.checks import check_fps
from facelib.engine import Face
from facelib.errors import ArkitFormatError, ParameterError
from facelib.export.arkit import (
    ANGLE_NAMES,
    ArkitCurves,
    arkit_names,
    from_arkit,
    live_link_names,
    live_link_order,
    to_arkit,
)
from facelib.export.source import Source
from facelib.mpeg4.stream import FapStream

__all__ = ["export_arkit", "import_arkit", "read_arkit_json", "read_live_link_csv",
           "write_arkit_json", "write_live_link_csv"]

_COUNT = 61
_TIMECODE_BASE = 60
"""The frame base of the timecodes facelib writes: the app counts the frame field at 60 whatever
the row rate (30 Hz rows step it by 2)."""
_USUAL_RATES = (24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 120.0)
_COUNT_SPELLINGS = ("blendshapecount",)  # BlendShapeCount, or BlendshapeCount in some captures


def _timecode(seconds: float, base: int = _TIMECODE_BASE) -> str:
    """Seconds -> ``HH:MM:SS:FF.mmm``: frame ``FF`` counted at ``base``, ``.mmm`` thousandths
    of a frame."""
    milli = round(seconds * base * 1000)
    whole, rest = divmod(milli, base * 1000)
    ff, sub = divmod(rest, 1000)
    h, rest_s = divmod(whole, 3600)
    m, s = divmod(rest_s, 60)
    return f"{h:02d}:{m:02d}:{s:02d}:{ff:02d}.{sub:03d}"


def _cell(value: float) -> str:
    """Six decimals; a value that rounds to zero is written ``0.000000``, never ``-0.000000``."""
    text = f"{value:.6f}"
    return "0.000000" if text == "-0.000000" else text


def write_live_link_csv(
    curves: ArkitCurves, path: str | os.PathLike[str], *, start: float = 0.0
) -> Path:
    """Write the Live Link Face app's CSV layout, atomically: its column order (``JawRight``
    before ``JawLeft``, ``MouthRight`` before ``MouthLeft``) and its timecodes (frame field
    counted at 60 whatever ``curves.fps``); ``start``: timecode of frame 0 (s)."""
    order = list(live_link_order())
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["Timecode", "BlendShapeCount", *live_link_names(), *ANGLE_NAMES])
    for i in range(curves.n_frames):
        writer.writerow([_timecode(start + i / curves.fps), _COUNT,
                         *(_cell(v) for v in curves.weights[i, order]),
                         *(_cell(v) for v in curves.angles[i])])
    path = Path(path)
    write_text_atomic(path, out.getvalue())
    return path


def _parse_timecode(text: str, path: Path, line: int) -> tuple[int, float]:
    """``HH:MM:SS:FF.mmm`` -> (whole seconds, frame with its fraction)."""
    try:
        h, m, s, f = text.split(":")
        frame = float(f)
        if not math.isfinite(frame) or frame < 0:
            raise ValueError
        return int(h) * 3600 + int(m) * 60 + int(s), frame
    except ValueError:
        raise ArkitFormatError(f"column 1 (Timecode): bad timecode {text!r}, expected "
                               "HH:MM:SS:FF.mmm", path=path, line=line) from None


def _columns(header: list[str], path: Path) -> np.ndarray:
    """Where each header cell after the first two goes: (len(header) - 2,) int64 indices into
    ``arkit_names() + ANGLE_NAMES`` (names matched case-insensitively, any order)."""
    cells = [c.strip() for c in header]
    if len(cells) < 2 or cells[0].lower() != "timecode" or \
            cells[1].lower() not in _COUNT_SPELLINGS:
        found = ", ".join(repr(c) for c in cells[:2])
        raise ArkitFormatError("not a Live Link Face CSV: columns 1 and 2 must be Timecode and "
                               f"BlendShapeCount, found {found}", path=path, line=1)
    known = {name.lower(): k for k, name in enumerate((*arkit_names(), *ANGLE_NAMES))}
    where: list[int] = []
    for c, name in enumerate(cells[2:], start=3):
        k = known.get(name.lower())
        if k is None:
            raise ArkitFormatError(f"column {c} ({name}) is not a Live Link Face column (the 52 "
                                   "ARKit names and the 9 head and eye angles)", path=path, line=1)
        if k in where:
            raise ArkitFormatError(f"column {c} ({name}) repeats column {where.index(k) + 3}",
                                   path=path, line=1)
        where.append(k)
    missing = [name for k, name in enumerate((*arkit_names(), *ANGLE_NAMES)) if k not in where]
    if missing:
        raise ArkitFormatError(f"not a Live Link Face CSV: missing column(s) {', '.join(missing)}",
                               path=path, line=1)
    return np.array(where, np.int64)


def _read_rows(
    rows: list[list[str]], header: list[str], path: Path
) -> tuple[list[tuple[int, float]], np.ndarray]:
    """Timecodes and the (n, len(header) - 2) float64 cells after them; every cell checked."""
    stamps, values = [], []
    for line, row in enumerate(rows, start=2):
        if not row or (len(row) == 1 and not row[0].strip()):
            continue
        if len(row) != len(header):
            raise ArkitFormatError(f"{len(row)} cells, the header has {len(header)}", path=path,
                                   line=line)
        stamps.append(_parse_timecode(row[0].strip(), path, line))
        try:
            cells = [float(v) for v in row[2:]]
        except ValueError:
            cells = []
        if len(cells) != len(row) - 2 or not all(math.isfinite(v) for v in cells):
            c = next(c for c, v in enumerate(row[2:], start=2) if not _finite(v))
            raise ArkitFormatError(f"column {c + 1} ({header[c].strip()}): {row[c]!r} is not a "
                                   "finite number", path=path, line=line)
        values.append(cells)
    if not stamps:
        raise ArkitFormatError("the file has no frames", path=path)
    return stamps, np.array(values, np.float64)


def _finite(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def read_live_link_csv(
    path: str | os.PathLike[str], *, fps: float | None = None, rate: float | None = None
) -> ArkitCurves:
    """Read a Live Link Face CSV into curves at the capture's row rate.

    Columns are read by name in any order (the app's ``JawRight, JawLeft``, facelib's older
    ``JawLeft, JawRight``); the second may be spelled ``BlendShapeCount`` or
    ``BlendshapeCount``. Every one of the 52 ARKit names and 9 angles must be there, once.

    fps: the frame base of the timecodes' frame field (the app counts it at 60 whatever the
        row rate); default: the smallest usual rate (24, 25, 30, 48, 50, 60, 120) above the
        largest frame number in the file.
    rate: the row rate of the curves returned; default: the median row interval, snapped to
        a usual rate within 5 %. Rows are placed at their timecode and resampled to uniform
        frames (captures drop frames).

    Raises ``ArkitFormatError`` naming the line and column of a missing, extra or repeated
    column, a row of the wrong length, a bad timecode, or a cell that is not a finite number.
    """
    path = Path(path)
    try:
        rows = list(csv.reader(path.read_text(encoding="utf-8-sig").splitlines()))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise ArkitFormatError(f"cannot read the file: {exc}", path=path) from exc
    if not rows:
        raise ArkitFormatError("not a Live Link Face CSV: the file is empty", path=path)
    where = _columns(rows[0], path)
    stamps, cells = _read_rows(rows[1:], rows[0], path)
    base = check_fps(fps) if fps is not None else _guess_base(stamps)
    times = np.array([s + f / base for s, f in stamps])
    times -= times.min()
    table = np.zeros((len(times), 52 + len(ANGLE_NAMES)))
    table[:, where] = cells
    order = np.argsort(times, kind="stable")
    times, table = times[order], table[order]
    keep = np.concatenate([[True], np.diff(times) > 0])  # a repeated timecode: the first row
    times, table = times[keep], table[keep]
    step = check_fps(rate) if rate is not None else _guess_rate(times, base)
    n = round(times[-1] * step) + 1
    grid = np.arange(n) / step
    resampled = np.stack([np.interp(grid, times, col) for col in table.T], 1)
    weights = np.clip(resampled[:, :52], 0.0, 1.0).astype(np.float32)
    angles = resampled[:, 52:].astype(np.float32)
    nan = np.full(n, np.nan, np.float32)
    return ArkitCurves(float(step), weights, angles, nan, nan.copy())


def _guess_base(stamps: list[tuple[int, float]]) -> float:
    """The timecodes' frame base: the smallest usual rate above the largest frame number."""
    largest = max(f for _, f in stamps)
    for base in _USUAL_RATES:
        if largest < base:
            return base
    return float(int(largest) + 1)


def _guess_rate(times: np.ndarray, base: float) -> float:
    """The row rate: 1 / the median interval, snapped to a usual rate within 5 %."""
    steps = np.diff(times)
    if not steps.size:
        return base
    found = 1.0 / float(np.median(steps))
    near = min(_USUAL_RATES, key=lambda r: abs(r - found))
    return near if abs(near - found) < 0.05 * near else round(found, 3)


def write_arkit_json(curves: ArkitCurves, path: str | os.PathLike[str]) -> Path:
    """Write the curves as JSON: names, fps, per-frame weights and angles, the residuals."""
    doc = {
        "format": "facelib-arkit", "version": 1, "fps": curves.fps,
        "names": list(arkit_names()), "angle_names": list(ANGLE_NAMES), "angle_unit": "radian",
        "weights": np.round(curves.weights, 6).tolist(),
        "angles": np.round(curves.angles, 6).tolist(),
        "residual_m": [None if math.isnan(v) else round(float(v), 7) for v in curves.residual],
        "relative_residual": [None if math.isnan(v) else round(float(v), 5)
                              for v in curves.relative],
    }
    path = Path(path)
    write_text_atomic(path, json.dumps(doc, separators=(",", ":")) + "\n")
    return path


def read_arkit_json(path: str | os.PathLike[str]) -> ArkitCurves:
    """Read what :func:`write_arkit_json` writes."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if doc.get("format") != "facelib-arkit" or doc["names"] != list(arkit_names()):
            raise ArkitFormatError("not a facelib ARKit JSON file (format, names)", path=path)
        weights = np.array(doc["weights"], np.float32).reshape(-1, 52)
        angles = np.array(doc["angles"], np.float32).reshape(-1, len(ANGLE_NAMES))
        residual = np.array([np.nan if v is None else v for v in doc["residual_m"]], np.float32)
        relative = np.array([np.nan if v is None else v for v in doc["relative_residual"]],
                            np.float32)
        return ArkitCurves(check_fps(doc["fps"]), weights, angles, residual, relative)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ArkitFormatError(f"cannot read ARKit JSON: {exc}", path=path) from exc


def export_arkit(
    source: Source, out: str | os.PathLike[str], *, face: Face | None = None
) -> ArkitCurves:
    """Solve ARKit curves of ``source`` and write them: ``.csv`` (Live Link Face) or ``.json``.

    Returns the :class:`ArkitCurves` (with the per-frame fit residual).
    """
    suffix = Path(out).suffix.lower()
    if suffix not in (".csv", ".json"):
        raise ParameterError(f"ARKit curves go to a .csv (Live Link Face) or .json file, not {out}")
    curves = to_arkit(source, face=face)
    if suffix == ".csv":
        write_live_link_csv(curves, out)
    else:
        write_arkit_json(curves, out)
    return curves


def import_arkit(
    path: str | os.PathLike[str], *, fps: float | None = None, rate: float | None = None,
    face: Face | None = None,
) -> FapStream:
    """A FapStream from a Live Link Face CSV (or facelib's ARKit JSON) capture, at the
    capture's row rate; ``fps`` and ``rate`` as in :func:`read_live_link_csv`."""
    curves = (read_arkit_json(path) if Path(path).suffix.lower() == ".json"
              else read_live_link_csv(path, fps=fps, rate=rate))
    return from_arkit(curves, face=face)
