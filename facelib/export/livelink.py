"""ARKit curves as files: Live Link Face's CSV (what the iPhone app records) and JSON.

Live Link Face CSV: a header ``Timecode,BlendShapeCount,EyeBlinkLeft,...,TongueOut,
HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,...,RightEyeRoll`` and one row per frame: an SMPTE-style
timecode ``HH:MM:SS:FF.mmm`` (frame ``FF`` at the capture rate, ``.mmm`` the sub-frame), the
count 61 (52 blendshapes + 9 angles), the 52 weights in [0, 1] and the 9 angles in radians.
"""

from __future__ import annotations

import csv
import io
import itertools
import json
import math
import os
from pathlib import Path

import numpy as np

from facelib.atomic import write_text_atomic
from facelib.checks import check_fps
from facelib.engine import Face
from facelib.errors import ArkitFormatError, ParameterError
from facelib.export.arkit import ANGLE_NAMES, ArkitCurves, arkit_names, from_arkit, to_arkit
from facelib.export.source import Source
from facelib.mpeg4.stream import FapStream

__all__ = ["export_arkit", "import_arkit", "read_arkit_json", "read_live_link_csv",
           "write_arkit_json", "write_live_link_csv"]

_COUNT = 61


def _timecode(seconds: float, rate: float) -> str:
    whole = math.floor(seconds + 1e-9)
    frames = (seconds - whole) * rate
    ff = math.floor(frames + 1e-6)
    sub = max(frames - ff, 0.0)
    h, rest = divmod(whole, 3600)
    m, s = divmod(rest, 60)
    return f"{h:02d}:{m:02d}:{s:02d}:{ff:02d}.{round(sub * 1000) % 1000:03d}"


def write_live_link_csv(
    curves: ArkitCurves, path: str | os.PathLike[str], *, start: float = 0.0
) -> Path:
    """Write Live Link Face's CSV layout, atomically; ``start``: timecode of frame 0 (s)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["Timecode", "BlendShapeCount", *arkit_names(), *ANGLE_NAMES])
    for i in range(curves.n_frames):
        writer.writerow([_timecode(start + i / curves.fps, curves.fps), _COUNT,
                         *(f"{v:.6f}" for v in curves.weights[i]),
                         *(f"{v:.6f}" for v in curves.angles[i])])
    path = Path(path)
    write_text_atomic(path, out.getvalue())
    return path


def _parse_timecode(text: str, path: Path, line: int) -> tuple[int, float]:
    """``HH:MM:SS:FF.mmm`` -> (whole seconds, frame with its fraction)."""
    try:
        h, m, s, f = text.split(":")
        return int(h) * 3600 + int(m) * 60 + int(s), float(f)
    except ValueError:
        raise ArkitFormatError(f"bad timecode {text!r}: expected HH:MM:SS:FF.mmm",
                               path=path, line=line) from None


def read_live_link_csv(path: str | os.PathLike[str], *, fps: float | None = None) -> ArkitCurves:
    """Read a Live Link Face CSV into curves at the capture's frame rate.

    fps: the timecode rate of the capture; default: the last frame number before a second
        rolls over, plus one (LLF records 60 fps, or 30 on older phones); files shorter than
        a second take the smallest usual rate above their largest frame number. Rows are
        placed at their timecode and resampled to uniform frames (captures drop frames).
    """
    path = Path(path)
    try:
        rows = list(csv.reader(path.read_text(encoding="utf-8-sig").splitlines()))
    except (OSError, UnicodeDecodeError) as exc:
        raise ArkitFormatError(f"cannot read the file: {exc}", path=path) from exc
    names = arkit_names()
    if not rows or [c.strip() for c in rows[0][2:54]] != list(names) or rows[0][:2] != [
            "Timecode", "BlendShapeCount"]:
        raise ArkitFormatError("not a Live Link Face CSV: the header must be Timecode, "
                               "BlendShapeCount and the 52 ARKit names in order", path=path,
                               line=1)
    angle_cols = [c.strip() for c in rows[0][54:63]]
    stamps, values = [], []
    for line, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) < 54:
            raise ArkitFormatError(f"{len(row)} cells, expected at least 54", path=path,
                                   line=line)
        stamps.append(_parse_timecode(row[0], path, line))
        try:
            values.append([float(v) for v in row[2 : 54 + len(angle_cols)]])
        except ValueError as exc:
            raise ArkitFormatError(f"not a number: {exc}", path=path, line=line) from None
    if not stamps:
        raise ArkitFormatError("the file has no frames", path=path)
    rate = check_fps(fps) if fps is not None else _guess_rate(stamps)
    times = np.array([s + f / rate for s, f in stamps])
    times -= times[0]
    table = np.array(values, np.float64)
    if np.any(np.diff(times) <= 0):
        order = np.argsort(times, kind="stable")
        times, table = times[order], table[order]
    n = round(times[-1] * rate) + 1
    grid = np.arange(n) / rate
    resampled = np.stack([np.interp(grid, times, col) for col in table.T], 1)
    weights = np.clip(resampled[:, :52], 0.0, 1.0).astype(np.float32)
    angles = np.zeros((n, len(ANGLE_NAMES)), np.float32)
    for k, name in enumerate(angle_cols):
        if name in ANGLE_NAMES:
            angles[:, ANGLE_NAMES.index(name)] = resampled[:, 52 + k]
    nan = np.full(n, np.nan, np.float32)
    return ArkitCurves(float(rate), weights, angles, nan, nan.copy())


def _guess_rate(stamps: list[tuple[int, float]]) -> float:
    """The timecode rate: the last frame before a second rolls over, plus one; without a
    rollover, the smallest usual rate above the largest frame number."""
    before = [int(f) for (s, f), (s2, _) in itertools.pairwise(stamps) if s2 > s]
    if before:
        return float(max(before) + 1)
    largest = max(f for _, f in stamps)
    for rate in (24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 120.0):
        if largest < rate:
            return rate
    return float(int(largest) + 1)


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
    path: str | os.PathLike[str], *, fps: float | None = None, face: Face | None = None
) -> FapStream:
    """A FapStream from a Live Link Face CSV (or facelib's ARKit JSON) capture."""
    curves = (read_arkit_json(path) if Path(path).suffix.lower() == ".json"
              else read_live_link_csv(path, fps=fps))
    return from_arkit(curves, face=face)
