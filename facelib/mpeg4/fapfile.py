"""Reading and writing ``.fap`` files, the text format MPEG-4 face players exchange.

A file is a header line ``<version> <name> <fps> <n_frames>`` followed, for every frame, by
a mask line (one 0/1 token per FAP) and a value line (the frame number, then one value per
masked FAP). FAP 1 (viseme) takes 4 tokens and FAP 2 (expression) 6 tokens when masked in.

Dialects the reader accepts (detected per file, reported as ``FapFile.dialect``):

``standard``
    68 mask tokens, integer values, frames ``0..n-1``: what every player reads.
``xface``
    Like standard, but float values, CRLF line ends and trailing spaces are common.
``greta``
    69 mask tokens (Greta's frame has one unused slot after FAP 68), integer values, a
    header name that may contain spaces, FAP 1/2 as single tokens.
``vreng``
    Frame numbers start at 1 (VREng's own 2.0 samples: tab-separated with frames from 0, or
    space-separated with frames from 1). Written with single spaces, as VREng's reader splits
    on ``' '`` only.
``extended``
    84 mask tokens: facelib's extended FAPs 69-84 (annex A, table A.3) follow FAP 68.

Lenient reading (``strict=False``) also takes ``#`` comment lines, frames missing from the
file (the previous frame is held, with a warning) and masks that change between frames.

Files from anywhere are read defensively: only regular files, line by line; the header's
frame count is checked against the file's size before anything is allocated; numbers are
ASCII only; FAP values must fit the format's 32-bit integers and FAP 1/2 fields their
MPEG-4 ranges.
"""

from __future__ import annotations

import math
import os
import re
import stat
import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.atomic import write_text_atomic
from facelib.checks import check_kind
from facelib.errors import FacelibWarning, FapFormatError, ParameterError
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import (
    EXPRESSION_FIELDS,
    EXPRESSION_LIMITS,
    VISEME_FIELDS,
    VISEME_LIMITS,
    FapStream,
)
from facelib.mpeg4.tables import N_FAPS, N_STANDARD_FAPS

__all__ = ["DIALECTS", "FapFile", "format_fap", "read_fap", "read_fap_file", "write_fap"]

DIALECTS: tuple[str, ...] = ("standard", "xface", "greta", "vreng", "extended")
_GRETA_MASK = N_STANDARD_FAPS + 1
_GRETA_FPS = 25  # Greta's Java reader: Constants.FRAME_PER_SECOND (fap_players.md M10)
_GRETA_CPP_FRAMES = 8000  # Greta's C++ reader: fap1[8000][4], fap2[8000][6] (M8)
_GROUP = {0: len(VISEME_FIELDS), 1: len(EXPRESSION_FIELDS)}
_FIELD_LIMITS = {0: VISEME_LIMITS, 1: EXPRESSION_LIMITS}
VALUE_LIMIT = 2**31 - 1
"""Largest magnitude of a FAP value in a ``.fap`` file (a 32-bit integer)."""
_MIN_FRAME_BYTES = 2 * N_STANDARD_FAPS + 2
"""Fewest bytes one frame takes: a 68-token mask line, a newline and a frame number line."""
_HELD_PER_FRAME = 16
"""A lenient file may declare up to this many frames per frame it could hold (the rest are
held): a bound on what a header can make the reader allocate."""
_INTEGER = re.compile(r"[0-9]+")
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")

# One parsed frame: (frame number, values (84,) float32, mask (84,) bool,
# viseme (4,) int16 or None, expression (6,) int16 or None).
_Frame = tuple[int, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]


@dataclass(frozen=True)
class FapFile:
    """A ``.fap`` file as read: the stream plus what the header and layout said."""

    stream: FapStream
    name: str
    version: str
    dialect: str
    missing_frames: tuple[int, ...]
    """Frame numbers absent from the file (held from the previous frame)."""


@dataclass(frozen=True, slots=True)
class _Line:
    number: int
    tokens: list[str]
    raw: str


def _lines(raw_lines: Iterable[bytes]) -> Iterator[_Line]:
    """Non-blank lines with their 1-based numbers (UTF-8, else Latin-1 per line)."""
    for number, data in enumerate(raw_lines, start=1):
        try:
            raw = data.decode("utf-8")
        except UnicodeDecodeError:
            raw = data.decode("latin-1")
        tokens = raw.split()
        if tokens:
            yield _Line(number, tokens, raw.rstrip("\r\n"))


def read_fap(path: str | os.PathLike[str], *, strict: bool = False) -> FapStream:
    """Read a ``.fap`` file into a :class:`FapStream`.

    Parameters
    ----------
    path:
        The file to read.
    strict:
        If True, accept only the standard profile (what :func:`write_fap` writes with
        ``dialect="standard"`` or ``"extended"``): no comments, integer fps and values,
        68 or 84 mask tokens, frames ``0..n-1`` all present.

    Raises
    ------
    FapFormatError
        naming the file, the line and what was expected.
    """
    return read_fap_file(path, strict=strict).stream


def read_fap_file(path: str | os.PathLike[str], *, strict: bool = False) -> FapFile:
    """Read a ``.fap`` file with its header name, version and detected dialect."""
    path = Path(path)
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise FapFormatError("not a regular file (a folder, device or pipe?)", path=path)
        with path.open("rb") as f:
            return _Parser(path, info.st_size, strict=strict).parse(_lines(f))
    except OSError as exc:
        raise FapFormatError(f"cannot read the file: {exc.strerror}", path=path) from exc


class _Parser:
    def __init__(self, path: Path, size: int, *, strict: bool):
        self.path = path
        self.size = size
        self.strict = strict
        self.float_values = False

    def error(self, line: _Line | int | None, message: str) -> FapFormatError:
        number = line.number if isinstance(line, _Line) else line
        return FapFormatError(message, path=self.path, line=number)

    def content(self, lines: Iterator[_Line]) -> Iterator[_Line]:
        for line in lines:
            if not line.tokens[0].startswith("#"):
                yield line
            elif self.strict:
                raise self.error(line, "comment lines are not allowed in strict mode")

    def parse(self, lines: Iterator[_Line]) -> FapFile:
        body = self.content(lines)
        first = next(body, None)
        if first is None:
            raise self.error(None, "the file is empty: expected a header line "
                             "'<version> <name> <fps> <n_frames>'")
        version, name, fps, n_frames = self.header(first)
        most = _HELD_PER_FRAME * (self.size // _MIN_FRAME_BYTES + 1)
        if n_frames > most:
            raise self.error(first, f"the header declares {n_frames} frames, but a file of "
                             f"{self.size} bytes cannot describe more than {most}")
        frames, value_lines, dialect = self.frames(body, n_frames, version)
        if not frames:
            if n_frames:
                raise self.error(first, f"the header declares {n_frames} frames but "
                                 "the file has none")
            return FapFile(FapStream.zeros(0, fps=fps), name, version, "standard", ())
        one_based = frames[0][0] == 1 and max(f[0] for f in frames) == n_frames
        if one_based:
            if self.strict:
                raise self.error(value_lines[0], "frame numbers must start at 0 in strict mode")
            if dialect == "standard":
                dialect = "vreng"
            frames = [(f[0] - 1, *f[1:]) for f in frames]
        if self.float_values and dialect == "standard":
            dialect = "xface"
        return self.assemble(frames, value_lines, fps=fps, n_frames=n_frames, name=name,
                             version=version, dialect=dialect)

    def frames(self, body: Iterator[_Line], n_frames: int, version: str
               ) -> tuple[list[_Frame], list[_Line], str]:
        """Every (mask line, value line) pair parsed, their value lines and the dialect."""
        frames: list[_Frame] = []
        value_lines: list[_Line] = []
        width, dialect = 0, "standard"
        for mask_line in body:
            value_line = next(body, None)
            if value_line is None:
                raise self.error(mask_line, "truncated frame: a mask line without its value line")
            if not frames:
                width = len(mask_line.tokens)
                dialect = self.dialect(mask_line, width, version)
            frames.append(self.frame(mask_line, value_line, width, dialect))
            value_lines.append(value_line)
            if len(frames) > n_frames + 1:
                raise self.error(value_line, f"more frames than the {n_frames} the header "
                                 "declares")
        return frames, value_lines, dialect

    def header(self, line: _Line) -> tuple[str, str, float, int]:
        expected = "expected '<version> <name> <fps> <n_frames>'"
        tokens = line.tokens
        if len(tokens) < 4:
            raise self.error(line, f"bad header {line.raw.strip()!r}: {expected}")
        version, fps_text, count_text = tokens[0], tokens[-2], tokens[-1]
        name = " ".join(tokens[1:-2])
        if not _is_number(version):
            raise self.error(line, f"bad header version {version!r}: {expected}")
        if not _is_number(fps_text) or not 0 < float(fps_text) <= 1000:
            raise self.error(line, f"bad frame rate {fps_text!r} in the header: {expected}")
        if not _INTEGER.fullmatch(count_text):
            raise self.error(line, f"bad frame count {count_text!r} in the header: {expected}")
        if self.strict:
            if len(tokens) != 4:
                raise self.error(line, f"header name {name!r} contains spaces (strict mode)")
            if not fps_text.isdigit():
                raise self.error(line, f"frame rate {fps_text!r} is not an integer (strict mode)")
        return version, name, float(fps_text), int(count_text)

    def dialect(self, mask_line: _Line, width: int, version: str) -> str:
        if width == N_STANDARD_FAPS:
            return "standard"
        if width == N_FAPS:
            return "extended"
        if width == _GRETA_MASK and not self.strict:
            return "greta"
        allowed = "68 or 84" if self.strict else "68, 69 (Greta) or 84"
        raise self.error(mask_line, f"mask line has {width} tokens, expected {allowed}")

    def frame(
        self, mask_line: _Line, value_line: _Line, width: int, dialect: str
    ) -> _Frame:
        if len(mask_line.tokens) != width:
            raise self.error(mask_line, f"mask line has {len(mask_line.tokens)} tokens, "
                             f"expected {width} like the first mask line")
        if any(t not in ("0", "1") for t in mask_line.tokens):
            bad = next(t for t in mask_line.tokens if t not in ("0", "1"))
            raise self.error(mask_line, f"mask token {bad!r} is not 0 or 1")
        flags = np.array([t == "1" for t in mask_line.tokens])
        number_text, *tokens = value_line.tokens
        if not _INTEGER.fullmatch(number_text):
            raise self.error(value_line, f"frame number {number_text!r} is not a "
                             "non-negative integer (is a mask or value line missing?)")
        groups = self.group_widths(flags, len(tokens), dialect)
        expected = int(flags[2:].sum()) + sum(groups.values())
        if len(tokens) != expected:
            raise self.error(value_line, f"value line has {len(tokens)} values, the mask "
                             f"line above sets {expected}")
        values = np.zeros(N_FAPS, np.float32)
        mask = np.zeros(N_FAPS, bool)
        viseme = expression = None
        position = 0
        for slot in (int(s) for s in np.flatnonzero(flags)):
            if slot in groups:
                count = groups[slot]
                field = [self.number(value_line, t, integer=True) for t in
                         tokens[position : position + count]]
                self.check_fields(value_line, slot, field)
                full = np.zeros(_GROUP[slot], np.int16)
                full[:count] = field
                viseme, expression = (full, expression) if slot == 0 else (viseme, full)
                mask[slot] = True
            else:
                value = self.number(value_line, tokens[position], integer=False)
                if slot < N_FAPS and not (dialect == "greta" and slot == N_STANDARD_FAPS):
                    values[slot] = value
                    mask[slot] = True
                elif value:
                    warnings.warn(f"{self.path}:{value_line.number}: ignoring Greta's unused "
                                  f"69th slot (value {value:g})", FacelibWarning, stacklevel=4)
                count = 1
            position += count
        return int(number_text), values, mask, viseme, expression

    def group_widths(self, flags: np.ndarray, available: int, dialect: str) -> dict[int, int]:
        """Token counts of FAP 1 and 2 in this frame: 4 and 6 (standard), or 1 each as
        Greta writes them."""
        present = [slot for slot in (0, 1) if flags[slot]]
        full = {slot: _GROUP[slot] for slot in present}
        if self.strict or not present:
            return full
        single = dict.fromkeys(present, 1)
        low = int(flags[2:].sum())
        if dialect == "greta" or available == low + len(present):
            return single
        return full

    def check_fields(self, line: _Line, slot: int, field: list[float]) -> None:
        names = VISEME_FIELDS if slot == 0 else EXPRESSION_FIELDS
        for name, value, high in zip(names, field, _FIELD_LIMITS[slot], strict=False):
            if not 0 <= value <= high:
                raise self.error(line, f"FAP {slot + 1} field {name} is {value:g}, outside "
                                 f"0-{high}")

    def number(self, line: _Line, token: str, *, integer: bool) -> float:
        if not _NUMBER.fullmatch(token):
            raise self.error(line, f"value {_short(token)!r} is not a number")
        value = float(token)
        if not abs(value) <= VALUE_LIMIT:
            raise self.error(line, f"value {_short(token)!r} is outside the format's range "
                             f"(+-{VALUE_LIMIT})")
        if not value.is_integer() or not token.lstrip("+-").isdigit():
            if integer or self.strict:
                raise self.error(line, f"value {token!r} is not an integer")
            self.float_values = True
        return value

    def assemble(
        self, frames: list[_Frame], value_lines: list[_Line], *, fps: float, n_frames: int,
        name: str,
        version: str, dialect: str,
    ) -> FapFile:
        values = np.zeros((n_frames, N_FAPS), np.float32)
        mask = np.zeros((n_frames, N_FAPS), bool)
        viseme = np.zeros((n_frames, len(VISEME_FIELDS)), np.int16)
        expression = np.zeros((n_frames, len(EXPRESSION_FIELDS)), np.int16)
        seen = np.zeros(n_frames, bool)
        any_viseme = any_expression = False
        previous = -1
        for index, (number, v, m, vis, expr) in enumerate(frames):
            line = value_lines[index]
            if number >= n_frames:
                raise self.error(line, f"frame number {number} is outside the "
                                 f"{n_frames} frames the header declares")
            if number <= previous:
                raise self.error(line, f"frame number {number} does not follow frame "
                                 f"{previous}: frames must be in increasing order")
            previous = number
            values[number], mask[number], seen[number] = v, m, True
            if vis is not None:
                viseme[number], any_viseme = vis, True
            if expr is not None:
                expression[number], any_expression = expr, True
        missing = tuple(int(i) for i in np.flatnonzero(~seen))
        if missing:
            if self.strict:
                raise self.error(None, f"frames {_spans(missing)} are missing (strict mode)")
            held = np.maximum.accumulate(np.where(seen, np.arange(n_frames), -1))
            fill = held >= 0
            for array in (values, mask, viseme, expression):
                array[fill] = array[held[fill]]
            warnings.warn(f"{self.path}: frames {_spans(missing)} are missing; "
                          "holding the previous frame", FacelibWarning, stacklevel=4)
        stream = FapStream(fps, values, mask, viseme if any_viseme else None,
                           expression if any_expression else None)
        return FapFile(stream, name, version, dialect, missing)


def _is_number(text: str) -> bool:
    return bool(_NUMBER.fullmatch(text)) and math.isfinite(float(text))


def _short(text: str, limit: int = 40) -> str:
    return text if len(text) <= limit else text[:limit] + "..."


def _spans(numbers: tuple[int, ...]) -> str:
    """``(3, 4, 5, 9)`` -> ``'3-5, 9'`` (at most 5 spans, then '...')."""
    spans: list[list[int]] = []
    for n in numbers:
        if spans and n == spans[-1][1] + 1:
            spans[-1][1] = n
        else:
            spans.append([n, n])
    text = [f"{a}" if a == b else f"{a}-{b}" for a, b in spans[:5]]
    return ", ".join(text) + (", ..." if len(spans) > 5 else "")


def _check_range(stream: FapStream) -> None:
    """ParameterError naming the first frame and FAP whose value a ``.fap`` cannot hold."""
    too_big = np.argwhere(np.abs(stream.values) > VALUE_LIMIT)
    if too_big.size:
        frame, column = (int(i) for i in too_big[0])
        raise ParameterError(f"frame {frame} FAP {column + 1} is {stream.values[frame, column]:g},"
                             f" beyond the .fap format's range (+-{VALUE_LIMIT})")


def write_fap(
    stream: FapStream,
    path: str | os.PathLike[str],
    *,
    dialect: str = "standard",
    name: str | None = None,
) -> Path:
    """Write ``stream`` to a ``.fap`` file, atomically (temp file, then rename).

    Parameters
    ----------
    stream:
        The FAP stream; its fps must be a whole number (resample it otherwise:
        ``stream.at_whole_rate()`` takes the nearest).
    path:
        The file to write.
    dialect:
        Any of :data:`DIALECTS`, each read back as that dialect: ``"standard"`` (68 mask
        tokens, integer values: the recommended choice, read correctly by Xface, Greta (Java
        and C++) and VREng), ``"xface"`` (68 mask tokens, values with decimals, plus the
        FAP 1/2 token groups: only Xface reads it right, and it warns), ``"greta"`` (69 mask
        tokens, the 69th always 0, as Greta writes), ``"vreng"`` (standard with frames
        numbered from 1, space-separated, as VREng's reader splits) or ``"extended"`` (84
        mask tokens with facelib's FAPs 69-84, plus FAP 1/2; only facelib reads it). Every
        dialect but ``extended`` warns, naming them, when it drops extended FAPs 69-84 that
        carry values, and ``standard``, ``greta`` and ``vreng`` when they drop FAP 1/2
        (viseme, expression: decode them first, or see :func:`write_fap_complete`); ``greta``
        warns unless the stream has 25 fps (Greta plays every file at 25), ``xface`` and
        ``extended`` when over 8000 frames carry FAP 1/2 (Greta's C++ reader crashes).
    name:
        The header's name; default: the file's stem. Spaces become underscores.

    Returns the path written.
    """
    path = Path(path)
    text = format_fap(stream, dialect=dialect, name=name if name is not None else path.stem)
    write_text_atomic(path, text)
    return path


def format_fap(stream: FapStream, *, dialect: str = "standard", name: str = "facelib") -> str:
    """The text of a ``.fap`` file holding ``stream`` (see :func:`write_fap` for
    ``dialect``); ``name`` goes into the header, spaces becoming underscores."""
    stream = check_kind("stream", stream, FapStream)
    if dialect not in DIALECTS:
        raise ParameterError(f"unknown .fap dialect {dialect!r}; choose one of {DIALECTS}")
    if not float(stream.fps).is_integer():
        raise ParameterError(f"a .fap file needs a whole frame rate, the stream has "
                             f"{stream.fps:g} fps: resample it first (stream.resample(25), or "
                             "stream.at_whole_rate() for the nearest)")
    _check_range(stream)
    label = "_".join(name.split()) or "facelib"
    _warn_dropped(stream, label, dialect)
    width = {"greta": _GRETA_MASK, "extended": N_FAPS}.get(dialect, N_STANDARD_FAPS)
    high_level = dialect in ("xface", "extended")
    values = [_decimal(v) for v in stream.values.ravel()] if dialect == "xface" else [
        str(v) for v in np.rint(stream.values).astype(np.int64).ravel()]
    first, sep = (1 if dialect == "vreng" else 0), " "  # VREng splits on ' ' only
    mask = np.zeros((stream.n_frames, width), bool)
    # Greta's 69th slot is unused: FAP 69 (an extended FAP) must never land there
    kept = min(width, N_FAPS if dialect == "extended" else N_STANDARD_FAPS)
    mask[:, :kept] = stream.mask[:, :kept]
    if not high_level:
        mask[:, :2] = False
    else:
        mask[:, 0] &= stream.viseme is not None
        mask[:, 1] &= stream.expression is not None
    out = [f"2.1 {label} {int(stream.fps)} {stream.n_frames}"]
    for i in range(stream.n_frames):
        out.append(sep.join("1" if m else "0" for m in mask[i]))
        tokens = [str(i + first)]
        for slot in np.flatnonzero(mask[i]):
            if slot == 0:
                tokens += [str(int(v)) for v in stream.viseme[i]]  # type: ignore[index]
            elif slot == 1:
                tokens += [str(int(v)) for v in stream.expression[i]]  # type: ignore[index]
            else:
                tokens.append(values[i * N_FAPS + slot])
        out.append(sep.join(tokens))
    return "\n".join(out) + "\n"


def write_fap_complete(
    stream: FapStream, path: str | os.PathLike[str], *, name: str | None = None
) -> tuple[Path, ...]:
    """Write ``stream`` so that every FAP its frames show is kept, without a warning.

    ``path`` gets the ``standard`` dialect, which every player reads, with FAP 1/2 decoded
    into the FAPs 3-68 the frames do not set (:func:`~facelib.mpeg4.highlevel.apply_high_level`,
    so players without FAP 1/2 show the same mouth). When the stream also carries extended
    FAPs 69-84 or FAP 1/2, a second file ``<stem>.extended.fap`` beside it holds all of them
    in the ``extended`` dialect (only facelib reads it).

    Returns the paths written: ``(path,)`` or ``(path, <stem>.extended.fap)``.
    """
    path = Path(path)
    name = name if name is not None else path.stem
    decoded = apply_high_level(stream)
    mask = np.array(decoded.mask)
    high = (stream.viseme is not None and bool(stream.mask[:, 0].any())) or (
        stream.expression is not None and bool(stream.mask[:, 1].any()))
    extended = bool((mask[:, N_STANDARD_FAPS:] & (decoded.values[:, N_STANDARD_FAPS:] != 0))
                    .any())
    mask[:, :2] = False
    mask[:, N_STANDARD_FAPS:] = False
    write_fap(FapStream(decoded.fps, decoded.values, mask), path, name=name)
    if not (high or extended):
        return (path,)
    beside = path.with_name(f"{path.stem}.extended{path.suffix}")
    write_fap(stream, beside, dialect="extended", name=name)
    return path, beside


def _decimal(value: float) -> str:
    """``value`` with up to 3 decimals and at least one (``100.0``, ``-12.5``)."""
    text = f"{value:.3f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def _warn_dropped(stream: FapStream, label: str, dialect: str) -> None:
    """Warn (naming the file's header ``label``) about what a dialect's players cannot read
    (shared/reference/fap_players.md): extended FAPs 69-84 outside ``extended``, Greta's
    fixed 25 fps, Greta C++'s 8000-frame limit with FAP 1/2, and ``xface`` in any reader but
    Xface's."""
    if dialect != "extended":
        used = stream.mask[:, N_STANDARD_FAPS:] & (stream.values[:, N_STANDARD_FAPS:] != 0)
        dropped = [int(i) + N_STANDARD_FAPS + 1 for i in np.flatnonzero(used.any(axis=0))]
        if dropped:
            warnings.warn(
                f"{label}: the {dialect} dialect has no extended FAPs; dropping FAP "
                f"{', '.join(map(str, dropped))} (write dialect='extended' to keep them; "
                "only facelib reads that dialect)", FacelibWarning, stacklevel=4)
    if dialect not in ("xface", "extended"):
        for slot, what, field in ((0, "viseme", stream.viseme), (1, "expression",
                                                                  stream.expression)):
            frames = int(stream.mask[:, slot].sum()) if field is not None else 0
            if frames:
                warnings.warn(
                    f"{label}: the {dialect} dialect has no FAP {slot + 1} ({what}); dropping it "
                    f"in {frames} frames (decode it into FAPs 3-68 first with "
                    "facelib.mpeg4.apply_high_level, or write_fap_complete, which does)",
                    FacelibWarning, stacklevel=4)
    if dialect == "greta" and stream.fps != _GRETA_FPS:
        warnings.warn(
            f"{label}: Greta's Java reader ignores the header's frame rate and plays "
            f"{_GRETA_FPS} fps; this stream has {stream.fps:g} fps (resample it: "
            f"stream.resample({_GRETA_FPS}))", FacelibWarning, stacklevel=4)
    high_level = bool(stream.mask[:, :2].any()) and (
        stream.viseme is not None or stream.expression is not None)
    if high_level and dialect in ("xface", "extended") and stream.n_frames > _GRETA_CPP_FRAMES:
        warnings.warn(
            f"{label}: {stream.n_frames} frames with FAP 1/2: Greta's C++ reader keeps them in "
            f"arrays of {_GRETA_CPP_FRAMES} frames and crashes on longer files",
            FacelibWarning, stacklevel=4)
    if dialect == "xface":
        groups = ("; its FAP 1/2 token groups shift every later value of the frame in Greta "
                  "Java and VREng" if high_level else "")
        warnings.warn(
            f"{label}: only Xface reads the xface dialect right: Greta's Java reader loses "
            "every frame on its decimal values and Greta's C++ reader every value after the "
            f"first decimal{groups}; dialect='standard' is read correctly by every player",
            FacelibWarning, stacklevel=4)
