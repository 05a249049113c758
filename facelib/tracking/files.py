"""Landmark tracks from other trackers' files, and facelib's own landmark CSV.

Read by :func:`read_landmarks` (the format is told by the suffix and the header):

- ``.csv`` with columns ``frame, point, x, y[, z]`` (facelib's, and a generic long table;
  an optional ``# fps: 30`` comment line gives the rate);
- ``.csv`` written by OpenFace 2.x ``FeatureExtraction`` (``frame, face_id, timestamp,
  confidence, success, ..., x_0 ... x_67, y_0 ... y_67[, X_0 ... Z_67]``): the 2-D columns,
  rows with ``success`` 0 as lost frames, the rate from the timestamps, the first face id;
- ``.json``: ``{"fps": 30, "frames": [[[x, y], ...], null, ...]}`` or a bare list of frames
  (dlib/iBUG 68-point lists; null is a lost frame);
- ``.pts`` (iBUG 300-W), one file per frame, or a folder of them in name order.

Coordinates are image pixels (column, row[, depth]). Frames with missing points, or with a
different point count, are lost frames (NaN, named in a warning); a file with no usable
frame is a TrackingError naming the file and line.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.atomic import write_text_atomic
from facelib.checks import check_fps
from facelib.errors import TrackingError, TrackingWarning
from facelib.tracking.faps import frame_spans

__all__ = ["LandmarkFile", "guess_layout", "read_landmarks", "write_landmarks_csv"]


@dataclass(frozen=True)
class LandmarkFile:
    """A landmark track read from a file.

    Attributes
    ----------
    path: where it came from.
    landmarks: ``(n_frames, K, D) float64`` pixels, NaN in lost frames.
    fps: the frame rate the file states, or None.
    layout: the packaged layout its point count suggests (``"ibug68"``, ``"mediapipe"``)
        or None.
    """

    path: Path
    landmarks: np.ndarray
    fps: float | None
    layout: str | None


def guess_layout(n_points: int) -> str | None:
    """``"ibug68"`` for 68 points, ``"mediapipe"`` for 468 or 478, else None."""
    return {68: "ibug68", 468: "mediapipe", 478: "mediapipe"}.get(n_points)


def _finish(path: Path, frames: list[np.ndarray | None], fps: float | None) -> LandmarkFile:
    sizes = [f.shape for f in frames if f is not None]
    if not sizes:
        raise TrackingError("no frame with landmarks", path=path)
    shape = max(set(sizes), key=sizes.count)
    bad = [i for i, f in enumerate(frames) if f is None or f.shape != shape
           or not np.isfinite(f).all()]
    wrong = [i for i in bad if frames[i] is not None]
    if wrong:
        warnings.warn(TrackingWarning(
            f"{path.name}: frames {frame_spans(np.array(wrong))} have missing points or not "
            f"{shape[0]} points; treated as lost"), stacklevel=3)
    out = np.full((len(frames), *shape), np.nan)
    for i, f in enumerate(frames):
        if i not in bad and f is not None:
            out[i] = f
    return LandmarkFile(path, out, fps, guess_layout(shape[0]))


def _fps_comment(text: str) -> float | None:
    match = re.search(r"^#\s*fps\s*[:=]\s*([0-9.eE+-]+)", text, re.MULTILINE)
    return check_fps(float(match.group(1))) if match else None


def _read_long_csv(path: Path, text: str) -> LandmarkFile:
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines())
             if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(ln for _, ln in lines))))
    header = [h.strip().lower() for h in rows[0]]
    dim = 3 if "z" in header else 2
    cols = [header.index(c) for c in ("frame", "point", "x", "y", "z")[: 2 + dim]]
    table: dict[int, dict[int, list[float]]] = {}
    for (line, _), cells in zip(lines[1:], rows[1:], strict=True):
        try:
            frame, point = int(cells[cols[0]]), int(cells[cols[1]])
            xyz = [float(cells[c]) for c in cols[2:]]
        except (ValueError, IndexError):
            raise TrackingError(f"bad landmark row {cells}", path=path, line=line) from None
        if frame < 0 or point < 0:
            raise TrackingError("frame and point must be >= 0", path=path, line=line)
        table.setdefault(frame, {})[point] = xyz
    n_points = 1 + max(p for pts in table.values() for p in pts)
    frames: list[np.ndarray | None] = []
    for frame in range(1 + max(table)):
        pts = table.get(frame)
        if pts is None:
            frames.append(None)
            continue
        arr = np.full((n_points, dim), np.nan)
        for p, xyz in pts.items():
            arr[p] = xyz
        frames.append(arr)
    return _finish(path, frames, _fps_comment(text))


def _read_openface(path: Path, text: str) -> LandmarkFile:
    reader = csv.reader(io.StringIO(text))
    header = [h.strip() for h in next(reader)]
    xs = sorted((int(h[2:]), i) for i, h in enumerate(header) if re.fullmatch(r"x_\d+", h))
    ys = sorted((int(h[2:]), i) for i, h in enumerate(header) if re.fullmatch(r"y_\d+", h))
    if len(xs) != len(ys) or not xs:
        raise TrackingError("OpenFace CSV without matching x_i / y_i columns", path=path, line=1)
    col = {name: header.index(name) for name in ("timestamp", "success", "face_id")
           if name in header}
    frames: list[np.ndarray | None] = []
    times: list[float] = []
    for line, cells in enumerate(reader, start=2):
        try:
            if "face_id" in col and int(float(cells[col["face_id"]])) != 0:
                continue
            ok = "success" not in col or float(cells[col["success"]]) > 0
            pts = np.array([[float(cells[i]) for _, i in xs], [float(cells[i]) for _, i in ys]]).T
            if "timestamp" in col:
                times.append(float(cells[col["timestamp"]]))
        except (ValueError, IndexError):
            raise TrackingError("bad OpenFace row", path=path, line=line) from None
        frames.append(pts if ok else None)
    steps = np.diff(times)
    fps = float(1 / np.median(steps)) if len(steps) and np.median(steps) > 0 else None
    return _finish(path, frames, fps)


def _read_json(path: Path, text: str) -> LandmarkFile:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise TrackingError(f"invalid JSON: {exc.msg}", path=path, line=exc.lineno) from exc
    fps = None
    if isinstance(doc, dict):
        fps = None if doc.get("fps") is None else check_fps(doc["fps"])
        doc = doc.get("frames")
    if not isinstance(doc, list):
        raise TrackingError("expected a list of frames (or {'fps', 'frames'})", path=path)
    frames: list[np.ndarray | None] = []
    for i, frame in enumerate(doc):
        if frame is None:
            frames.append(None)
            continue
        try:
            arr = np.array(frame, np.float64)
        except (ValueError, TypeError):
            raise TrackingError(f"frame {i} is not a list of points", path=path) from None
        if arr.ndim != 2 or arr.shape[1] not in (2, 3):
            raise TrackingError(f"frame {i} has shape {arr.shape}, not (K, 2 or 3)", path=path)
        frames.append(arr)
    return _finish(path, frames, fps)


def _read_pts_file(path: Path) -> np.ndarray:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise TrackingError(f"cannot read it: {exc}", path=path) from exc
    match = re.search(r"\{(.*)\}", text, re.DOTALL)
    count = re.search(r"n_points\s*:\s*(\d+)", text)
    if match is None or count is None:
        raise TrackingError("not an iBUG .pts file (no n_points or braces)", path=path)
    try:
        pts = np.array([[float(v) for v in ln.split()] for ln in match.group(1).splitlines()
                        if ln.strip()])
    except ValueError:
        raise TrackingError("non-numeric point in .pts", path=path) from None
    if pts.shape != (int(count.group(1)), 2):
        raise TrackingError(f"{len(pts)} points where n_points says {count.group(1)}", path=path)
    return pts - 1.0  # .pts coordinates are 1-based (Matlab convention of 300-W)


def read_landmarks(path: str | os.PathLike[str]) -> LandmarkFile:
    """Read a landmark track (formats in the module docstring)."""
    path = Path(path)
    if path.is_dir():
        files = sorted(path.glob("*.pts"))
        if not files:
            raise TrackingError("folder holds no .pts files", path=path)
        return _finish(path, [_read_pts_file(f) for f in files], None)
    if not path.is_file():
        raise TrackingError(f"landmark file {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".pts":
        return _finish(path, [_read_pts_file(path)], None)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise TrackingError(f"cannot read it: {exc}", path=path) from exc
    if suffix == ".json":
        return _read_json(path, text)
    if suffix != ".csv":
        raise TrackingError("landmark files are .csv, .json, .pts or a folder of .pts",
                            path=path)
    first = next((ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")), "")
    names = {h.strip().lower() for h in first.split(",")}
    if {"frame", "point", "x", "y"} <= names:
        return _read_long_csv(path, text)
    if "x_0" in names and "y_0" in names:
        return _read_openface(path, text)
    raise TrackingError("CSV header is neither 'frame,point,x,y[,z]' nor OpenFace's",
                        path=path, line=1)


def write_landmarks_csv(path: str | os.PathLike[str], landmarks: np.ndarray, *,
                        fps: float) -> Path:
    """Write ``(n_frames, K, 2 or 3)`` landmarks as ``frame,point,x,y[,z]`` (lost frames,
    NaN, are left out) with a ``# fps:`` comment; atomically. Returns the path."""
    data = np.asarray(landmarks, np.float64)
    if data.ndim != 3 or data.shape[2] not in (2, 3):
        raise TrackingError(f"landmarks must be (n_frames, K, 2 or 3), got {data.shape}")
    rate = check_fps(fps)
    axes = "x,y,z" if data.shape[2] == 3 else "x,y"
    out = [f"# facelib landmarks, image pixels (column, row[, depth])\n# fps: {rate:g}\n",
           f"frame,point,{axes}\n"]
    k = data.shape[1]
    points = np.arange(k)
    for i, frame in enumerate(data):
        if not np.isfinite(frame).all():
            continue
        block = np.column_stack([np.full(k, i), points, frame])
        out.append("\n".join(
            f"{int(r[0])},{int(r[1])}," + ",".join(f"{v:.3f}" for v in r[2:]) for r in block))
        out.append("\n")
    write_text_atomic(path, "".join(out))
    return Path(path)
