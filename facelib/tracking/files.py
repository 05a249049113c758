"""Landmark tracks from other trackers' files, and facelib's own landmark CSV.

Read by :func:`read_landmarks` (the format is told by the suffix and the header):

- ``.csv`` with columns ``frame, point, x, y[, z]`` (facelib's, and a generic long table;
  points numbered from 0, or from 1 as in iBUG's figure when no point 0 appears; an
  optional ``# fps: 30`` or ``# fps: 30000/1001`` comment line before the rows gives the
  rate);
- ``.csv`` written by OpenFace 2.x ``FeatureExtraction`` (``frame, face_id, timestamp,
  confidence, success, ..., x_0 ... x_67, y_0 ... y_67[, X_0 ... Z_67]``): the 2-D columns
  of the lowest face id, rows placed by their ``frame`` (a frame without a row, or with
  ``success`` 0, is lost), the rate from the timestamps over the whole track (OpenFace
  rounds them to the millisecond) snapped to a common camera rate within 1 %;
- ``.json``: ``{"fps": 30, "frames": [[[x, y], ...], null, ...]}`` or a bare list of frames
  (dlib/iBUG 68-point lists; null or ``[]`` is a lost frame);
- ``.pts`` (iBUG 300-W), one file per frame, or a folder of them ordered by the last number
  in their names (a missing number is a lost frame), else by name.

Text may start with a UTF-8 byte-order mark (as Excel writes CSV). Coordinates all within
0-1 (normalised, as MediaPipe's Python API gives them) are refused.

Coordinates are image pixels (column, row[, depth]). Frames with missing points, or with a
different point count, are lost frames (NaN, named in a warning); a file with no usable
frame is a TrackingError naming the file and line.
"""

from __future__ import annotations

import csv
import json
import os
import re
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import NoReturn

import numpy as np

from facelib.atomic import atomic_path
from facelib.checks import check_fps
from facelib.errors import ParameterError, TrackingError, TrackingWarning
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


_WRITE_FRAMES = 256
"""Frames formatted at a time by :func:`write_landmarks_csv`."""

MAX_FRAMES_PER_FRAME = 16
"""A track spans at most this many frames for every frame the file holds ..."""
MAX_LOST_VALUES = 2**24
"""... plus lost frames worth this many coordinates (128 MiB of float64: 2 h of 68 2-D
points at 17 fps, 8 min of 478 3-D points at 25 fps): a file's frame numbers and gaps never
size memory beyond what it holds."""


def _shown(value: float) -> str:
    """A frame or point number as the file gave it (a whole number below 2^53 in full)."""
    if np.isfinite(value) and value == round(value) and abs(value) <= 2.0**53:
        return str(int(value))
    return f"{value:g}"


def _bound_track(numbers: np.ndarray, *, start: float | None, values_per_frame: int,
                 locate: Callable[[int], tuple[Path, int | None]]) -> None:
    """Refuse a track whose frame numbers ``(n,) float64`` (one per row of the file; whole
    numbers) would size memory beyond what the file holds: a number at or past 2^53, or a
    span (from ``start``, else the first frame, to the last) longer than
    :data:`MAX_FRAMES_PER_FRAME` per frame held plus :data:`MAX_LOST_VALUES` coordinates
    of ``values_per_frame`` each. ``locate(row)`` gives the file and line to name."""
    big = np.flatnonzero(~(np.abs(numbers) < 2.0**53))
    if big.size:
        where, line = locate(int(big[0]))
        raise TrackingError(f"frame {_shown(float(numbers[big[0]]))} is not a frame number "
                            "(frames are whole numbers below 2^53)", path=where, line=line)
    held = np.unique(numbers)
    first = float(held[0]) if start is None else min(float(start), float(held[0]))
    span = int(held[-1] - first) + 1
    allowance = MAX_LOST_VALUES // max(values_per_frame, 1)
    allowed = MAX_FRAMES_PER_FRAME * len(held) + allowance
    if span <= allowed:
        return
    before = np.concatenate([[first - 1.0], held[:-1]])
    j = int(np.argmax(held - before))
    where, line = locate(int(np.flatnonzero(numbers == held[j])[0]))
    after = f"frame {_shown(float(before[j]))}" if j else f"the track's start (frame {first:g})"
    raise TrackingError(
        f"frame {_shown(float(held[j]))} comes {_shown(float(held[j] - before[j]))} frames "
        f"after {after}: the track would span {span} frames, more than the {allowed} allowed "
        f"for the {len(held)} frames the file holds ({MAX_FRAMES_PER_FRAME} per frame held "
        f"plus {allowance} lost)", path=where, line=line)


def _row_line(path: Path, header_line: int, *, comments: bool) -> Callable[[int], tuple[
        Path, int | None]]:
    """``locate(row)`` for a CSV: the file and the line of its ``row``-th data row (0-based;
    blank lines, rows of empty cells and, with ``comments``, ``#`` lines are no rows)."""
    def locate(row: int) -> tuple[Path, int | None]:
        count = 0
        for line, cells in _data_rows(path, header_line, comments=comments):
            if not any(c.strip() for c in cells):
                continue
            if count == row:
                return path, line
            count += 1
        return path, None
    return locate


def guess_layout(n_points: int) -> str | None:
    """``"ibug68"`` for 68 points, ``"mediapipe"`` for 468 or 478, else None."""
    return {68: "ibug68", 468: "mediapipe", 478: "mediapipe"}.get(n_points)


def _finish(path: Path, frames: list[np.ndarray | None], fps: float | None) -> LandmarkFile:
    """The track of ``frames`` (None: lost), each ``(K, D)``; see :func:`_checked`."""
    sizes = [f.shape for f in frames if f is not None]
    if not sizes:
        raise TrackingError("no frame with landmarks", path=path)
    shape = max(set(sizes), key=sizes.count)
    out = np.full((len(frames), *shape), np.nan)
    for i, f in enumerate(frames):
        if f is not None and f.shape == shape:
            out[i] = f  # another shape stays NaN: a frame with missing points, below
    return _checked(path, out, np.array([f is not None for f in frames], bool), fps)


def _checked(path: Path, out: np.ndarray, seen: np.ndarray, fps: float | None
             ) -> LandmarkFile:
    """The :class:`LandmarkFile` of ``out`` ``(n, K, D)``, in place: the ``seen`` frames
    (the file has them) with a missing point are lost (named in a warning), and a track
    whose coordinates are all within 0-1 is refused."""
    wrong = np.flatnonzero(seen & ~np.isfinite(out).all(axis=(1, 2)))
    if wrong.size:
        warnings.warn(TrackingWarning(
            f"{path.name}: frames {frame_spans(wrong)} have missing points or not "
            f"{out.shape[1]} points; treated as lost"), stacklevel=3)
        out[wrong] = np.nan
    plane = out[..., :2]  # NaN-ignoring extremes, without a copy of the track
    largest = max(np.fmax.reduce(plane, axis=None), -np.fmin.reduce(plane, axis=None))
    if largest <= 1.5:
        raise TrackingError("every coordinate is within 0-1: these look normalised; give "
                            "image pixels (x times the width, y times the height)", path=path)
    return LandmarkFile(path, out, fps, guess_layout(out.shape[1]))


_COMMON_RATES = (24000 / 1001, 24.0, 25.0, 30000 / 1001, 30.0, 48.0, 50.0, 60000 / 1001,
                 60.0, 90.0, 100.0, 120.0, 240.0)
"""Camera and video frame rates a rate measured from rounded timestamps is snapped to."""


def _snapped(rate: float) -> float:
    """``rate`` (frames a second, measured) as the common rate within 1 % of it, if any."""
    near = min(_COMMON_RATES, key=lambda r: abs(r - rate))
    return near if abs(near - rate) <= 0.01 * near else rate


def _fps_comment(path: Path, text: str) -> float | None:
    """The rate of a ``# fps: 30`` (or ``30000/1001``) comment line, if any."""
    match = re.search(r"^[ \t]*#[ \t]*fps[ \t]*[:=][ \t]*(\S+)", text, re.MULTILINE)
    if match is None:
        return None
    try:
        top, _, bottom = match.group(1).partition("/")
        return check_fps(float(top) / (float(bottom) if bottom else 1.0))
    except (ValueError, ZeroDivisionError, ParameterError):
        raise TrackingError(f"bad frame rate {match.group(1)!r}", path=path,
                            line=text.count("\n", 0, match.start()) + 1) from None


def _read_long_csv(path: Path, head: str) -> LandmarkFile:
    """A ``frame, point, x, y[, z]`` table from the file (``head``: its first lines, with
    the header and any ``# fps`` comment), parsed by numpy: a long recording's CSV holds
    millions of rows; a bad row is found again line by line to name it."""
    at, first = _header(head)
    header = [h.strip().lower() for h in first.split(",")]
    dim = 3 if "z" in header else 2
    cols = [header.index(c) for c in ("frame", "point", "x", "y", "z")[: 2 + dim]]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # no rows: said below
            table = np.loadtxt(path, delimiter=",", comments="#", ndmin=2, skiprows=at,
                               usecols=cols, encoding="utf-8-sig")
    except ValueError:
        _raise_bad_row(path, at, cols)
    if not len(table):
        raise TrackingError("no landmark rows after the header", path=path)
    ids = table[:, :2]
    if (ids != np.round(ids)).any() or (ids < 0).any():
        _raise_bad_row(path, at, cols)
    locate = _row_line(path, at, comments=True)
    widest = int(np.argmax(ids[:, 1]))
    if not ids[widest, 1] < len(table):  # a frame of K points needs K rows
        where, line = locate(widest)
        raise TrackingError(f"point {_shown(float(ids[widest, 1]))} is more points than the "
                            f"file's {len(table)} rows hold", path=where, line=line)
    _bound_track(ids[:, 0], start=0.0, values_per_frame=int(ids[:, 1].max() + 1) * dim,
                 locate=locate)
    frame, point = ids.astype(np.int64).T
    if not (point == 0).any():  # numbered from 1, as iBUG's figure
        point = point - 1
    out = np.full((frame.max() + 1, point.max() + 1, dim), np.nan)
    out[frame, point] = table[:, 2:]
    del table
    seen = np.zeros(len(out), bool)
    seen[frame] = True
    return _checked(path, out, seen, _fps_comment(path, head))


def _numbered_lines(text: str) -> Iterator[tuple[int, str]]:
    """``(line number from 1, line)`` of ``text``, one at a time (no copy of the text)."""
    start, number = 0, 1
    while start < len(text):
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        yield number, text[start:end]
        start, number = end + 1, number + 1


def _data_rows(path: Path, header_line: int, *, comments: bool
               ) -> Iterator[tuple[int, list[str]]]:
    """``(line number, cells)`` of each line of the file after the header that is not blank
    (nor, with ``comments``, a ``#`` comment): the slow path that names a bad row."""
    for line, text in _numbered_lines(path.read_text(encoding="utf-8-sig")):
        if line > header_line and text.strip() and not (
                comments and text.lstrip().startswith("#")):
            yield line, next(csv.reader([text]))


def _raise_bad_row(path: Path, header_line: int, cols: list[int]) -> NoReturn:
    """TrackingError naming the first row after the header whose columns ``cols``
    (frame, point, x, y[, z]) are not a frame and point >= 0 and numbers."""
    for line, cells in _data_rows(path, header_line, comments=True):
        try:
            frame, point = (int(cells[c]) for c in cols[:2])
            [float(cells[c]) for c in cols[2:]]
        except (ValueError, IndexError):
            raise TrackingError(f"bad landmark row {cells}", path=path, line=line) from None
        if frame < 0 or point < 0:
            raise TrackingError("frame and point must be >= 0", path=path, line=line)
    raise TrackingError("unreadable landmark table", path=path)


def _header(head: str) -> tuple[int, str]:
    """The line number (from 1) and text of the header: the first line of ``head`` that is
    neither blank nor a comment."""
    return next((i, ln) for i, ln in _numbered_lines(head)
                if ln.strip() and not ln.lstrip().startswith("#"))


def _read_openface(path: Path, head: str) -> LandmarkFile:
    """An OpenFace 2.x CSV (``head``: its first lines, with the header), its columns read by
    numpy from the file; row by row only to name a bad row (or skip a blank one)."""
    at, first = _header(head)
    header = [h.strip() for h in first.split(",")]
    xs = [i for _, i in sorted((int(h[2:]), i) for i, h in enumerate(header)
                               if re.fullmatch(r"x_\d+", h))]
    ys = [i for _, i in sorted((int(h[2:]), i) for i, h in enumerate(header)
                               if re.fullmatch(r"y_\d+", h))]
    if len(xs) != len(ys) or not xs:
        raise TrackingError("OpenFace CSV without matching x_i / y_i columns", path=path,
                            line=at)
    named: list[str] = [n for n in ("frame", "timestamp", "success", "face_id") if n in header]
    cols = [header.index(n) for n in named] + xs + ys
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # no rows: said below
            table = np.loadtxt(path, delimiter=",", comments=None, ndmin=2, skiprows=at,
                               usecols=cols, encoding="utf-8-sig")
    except ValueError:
        table = _openface_rows(path, at, cols, named)
    if not len(table):
        raise TrackingError("no landmark rows after the header", path=path)
    if not _whole_numbers(table, named):
        _openface_rows(path, at, cols, named)  # raises, naming the row
    rows = np.arange(len(table))
    if "face_id" in named:  # the first face id
        first_face = table[:, named.index("face_id")] == table[:, named.index("face_id")].min()
        table, rows = table[first_face], rows[first_face]
    column = {n: table[:, k] for k, n in enumerate(named)}
    if "frame" in column:
        locate = _row_line(path, at, comments=False)
        _bound_track(column["frame"], start=None, values_per_frame=2 * len(xs),
                     locate=lambda row: locate(int(rows[row])))
    frame = column["frame"].astype(np.int64) if "frame" in column else np.arange(len(table))
    ok = column["success"] > 0 if "success" in column else np.ones(len(table), bool)
    points = np.stack([table[:, len(named):len(named) + len(xs)],
                       table[:, len(named) + len(xs):]], axis=2)
    frames: list[np.ndarray | None] = [None] * (int(np.ptp(frame)) + 1)
    for f, good, pts in zip(frame - frame.min(), ok, points, strict=True):
        frames[f] = pts if good else None  # a repeated frame: its last row
    return _finish(path, frames, _openface_rate(frame, column.get("timestamp")))


def _whole_numbers(table: np.ndarray, named: list[str]) -> bool:
    """Whether the ``frame`` and ``face_id`` columns of ``table`` (among its first
    ``named``) are finite numbers that make exact integers."""
    ids = [named.index(n) for n in ("frame", "face_id") if n in named]
    return bool((np.abs(table[:, ids]) < 2.0**53).all())


def _openface_rows(path: Path, header_line: int, cols: list[int], named: list[str]
                   ) -> np.ndarray:
    """``(rows, len(cols))`` the ``cols`` of every row after the header that is not blank;
    TrackingError naming the first row that is not numbers there, or whose frame or face id
    (``named``: the names of the first columns) is not a whole number."""
    rows = []
    for line, cells in _data_rows(path, header_line, comments=False):
        if not any(c.strip() for c in cells):  # a row of empty cells
            continue
        try:
            row = [float(cells[c]) for c in cols]
        except (ValueError, IndexError):
            raise TrackingError("bad OpenFace row", path=path, line=line) from None
        if not _whole_numbers(np.array([row]), named):
            raise TrackingError("bad OpenFace row: its frame or face_id is not a whole number",
                                path=path, line=line)
        rows.append(row)
    return np.array(rows, np.float64).reshape(-1, len(cols))


def _openface_rate(frame: np.ndarray, times: np.ndarray | None) -> float | None:
    """Frames a second from the ``(n,)`` frame numbers and their timestamps (seconds, None
    without them) over the whole track, snapped to a common rate; None if they do not
    give one."""
    if times is None or not np.isfinite(times).all():
        return None
    order = np.argsort(frame, kind="stable")  # a repeated frame: its last row, as read
    low = order[np.searchsorted(frame[order], frame[order[0]], side="right") - 1]
    span, took = frame[order[-1]] - frame[low], times[order[-1]] - times[low]
    return _snapped(span / took) if span and took > 0 else None


def _read_json(path: Path, text: str) -> LandmarkFile:
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise TrackingError(f"invalid JSON: {exc.msg}", path=path, line=exc.lineno) from exc
    except RecursionError:
        raise TrackingError("the JSON is nested too deeply to be a landmark track (frames of "
                            "points are 3 lists deep)", path=path) from None
    fps = None
    if isinstance(doc, dict):
        fps = None if doc.get("fps") is None else check_fps(doc["fps"])
        doc = doc.get("frames")
    if not isinstance(doc, list):
        raise TrackingError("expected a list of frames (or {'fps', 'frames'})", path=path)
    frames: list[np.ndarray | None] = []
    for i, frame in enumerate(doc):
        if frame is None or frame == []:  # no face
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
        text = path.read_text(encoding="utf-8-sig")
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


def _read_pts_folder(path: Path) -> LandmarkFile:
    """A folder of ``.pts`` files, one per frame: in the order of the last number in their
    names (``frame_9`` before ``frame_10``), a missing number a lost frame; in name order
    when some name has no number."""
    files = sorted(f for f in path.iterdir() if f.suffix.lower() == ".pts")
    if not files:
        raise TrackingError("folder holds no .pts files", path=path)
    numbers = [re.findall(r"\d+", f.stem) for f in files]
    if not all(numbers):
        return _finish(path, [_read_pts_file(f) for f in files], None)
    order = {int(n[-1]): f for n, f in zip(numbers, files, strict=True)}
    if len(order) != len(files):
        raise TrackingError("two .pts files have the same frame number", path=path)
    held = sorted(order)
    points = {i: _read_pts_file(order[i]) for i in held}
    for i in held:
        if i >= 2**53:  # as a float it would read as another number
            raise TrackingError(f"frame {i} is not a frame number (frames are whole numbers "
                                "below 2^53)", path=order[i])
    _bound_track(np.array(held, np.float64), start=None,
                 values_per_frame=points[held[0]].size,
                 locate=lambda row: (order[held[row]], None))
    return _finish(path, [points.get(i) for i in range(held[0], held[-1] + 1)], None)


_HEAD = 1 << 16
"""Characters read first: enough for a CSV's header and comments."""


def read_landmarks(path: str | os.PathLike[str]) -> LandmarkFile:
    """Read a landmark track (formats in the module docstring)."""
    path = Path(path)
    if path.is_dir():
        return _read_pts_folder(path)
    if not path.is_file():
        raise TrackingError(f"landmark file {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".pts":
        return _finish(path, [_read_pts_file(path)], None)
    if suffix not in (".json", ".csv"):
        raise TrackingError("landmark files are .csv, .json, .pts or a folder of .pts",
                            path=path)
    try:
        with path.open(encoding="utf-8-sig") as stream:  # as Excel writes it, with a BOM
            head = stream.read(_HEAD)
            first = next((ln for ln in head.splitlines()
                          if ln.strip() and not ln.startswith("#")), "")
            names = {h.strip().lower() for h in first.split(",")}
            if suffix == ".csv" and {"frame", "point", "x", "y"} <= names:
                return _read_long_csv(path, head)  # numpy reads the rows from the file
            if suffix == ".csv" and {"x_0", "y_0"} <= names:
                return _read_openface(path, head)  # likewise
            text = head + stream.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise TrackingError(f"cannot read it: {exc}", path=path) from exc
    if suffix == ".json":
        return _read_json(path, text)
    raise TrackingError("CSV header is neither 'frame,point,x,y[,z]' nor OpenFace's",
                        path=path, line=1)


def write_landmarks_csv(path: str | os.PathLike[str], landmarks: np.ndarray, *,
                        fps: float) -> Path:
    """Write ``(n_frames, K, 2 or 3)`` landmarks as ``frame,point,x,y[,z]`` (lost frames,
    NaN, are left out) with a ``# fps:`` comment; atomically, a few hundred frames at a
    time (a long recording's table is never held whole as text). Returns the path."""
    data = np.asarray(landmarks)
    if data.ndim != 3 or data.shape[2] not in (2, 3):
        raise TrackingError(f"landmarks must be (n_frames, K, 2 or 3), got {data.shape}")
    rate = check_fps(fps)
    n, k, dim = data.shape
    axes = "x,y,z" if dim == 3 else "x,y"
    row = "%d,%d," + ",".join(["%.3f"] * dim) + "\n"
    points = np.arange(k, dtype=np.float64)[:, None]
    with atomic_path(path) as temp, temp.open("w", encoding="utf-8", newline="\n") as out:
        out.write(f"# facelib landmarks, image pixels (column, row[, depth])\n# fps: {rate:g}\n"
                  f"frame,point,{axes}\n")
        for start in range(0, n, _WRITE_FRAMES):
            chunk = np.asarray(data[start:start + _WRITE_FRAMES], np.float64)
            frames = np.flatnonzero(np.isfinite(chunk).all(axis=(1, 2)))
            if not len(frames):  # a stretch with no face
                continue
            table = np.concatenate([np.broadcast_to((start + frames)[:, None, None],
                                                    (len(frames), k, 1)),
                                    np.broadcast_to(points, (len(frames), k, 1)),
                                    chunk[frames]], axis=2)
            out.write("".join((row * k) % tuple(values)
                              for values in table.reshape(len(frames), -1).tolist()))
    return Path(path)
