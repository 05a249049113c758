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
    Version ``2.0`` style: frame numbers start at 1 and tokens are tab-separated.
``extended``
    84 mask tokens: facelib's extended FAPs 69-84 (annex A, table A.3) follow FAP 68.

Lenient reading (``strict=False``) also takes ``#`` comment lines, frames missing from the
file (the previous frame is held, with a warning) and masks that change between frames.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.atomic import write_text_atomic
from facelib.errors import FacelibWarning, FapFormatError, ParameterError
from facelib.mpeg4.stream import EXPRESSION_FIELDS, VISEME_FIELDS, FapStream
from facelib.mpeg4.tables import N_FAPS, N_STANDARD_FAPS

__all__ = ["DIALECTS", "FapFile", "read_fap", "read_fap_file", "write_fap"]

DIALECTS: tuple[str, ...] = ("standard", "xface", "greta", "vreng", "extended")
_WRITE_DIALECTS = ("standard", "xface", "greta", "extended")
_GRETA_MASK = N_STANDARD_FAPS + 1
_GROUP = {0: len(VISEME_FIELDS), 1: len(EXPRESSION_FIELDS)}


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


def _lines(text: str) -> Iterator[_Line]:
    for number, raw in enumerate(text.splitlines(), start=1):
        tokens = raw.split()
        if tokens:
            yield _Line(number, tokens, raw)


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
        data = path.read_bytes()
    except OSError as exc:
        raise FapFormatError(f"cannot read the file: {exc.strerror}", path=path) from exc
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return _Parser(path, text, strict=strict).parse()


class _Parser:
    def __init__(self, path: Path, text: str, *, strict: bool):
        self.path = path
        self.text = text
        self.strict = strict
        self.float_values = False

    def error(self, line: _Line | int | None, message: str) -> FapFormatError:
        number = line.number if isinstance(line, _Line) else line
        return FapFormatError(message, path=self.path, line=number)

    def parse(self) -> FapFile:
        lines = list(_lines(self.text))
        comments = [ln for ln in lines if ln.tokens[0].startswith("#")]
        if comments and self.strict:
            raise self.error(comments[0], "comment lines are not allowed in strict mode")
        lines = [ln for ln in lines if not ln.tokens[0].startswith("#")]
        if not lines:
            raise self.error(None, "the file is empty: expected a header line "
                             "'<version> <name> <fps> <n_frames>'")
        version, name, fps, n_frames = self.header(lines[0])
        body = lines[1:]
        if len(body) % 2:
            raise self.error(body[-1], "truncated frame: a mask line without its value line")
        if not body:
            if n_frames:
                raise self.error(lines[0], f"the header declares {n_frames} frames but "
                                 "the file has none")
            return FapFile(FapStream.zeros(0, fps=fps), name, version, "standard", ())
        width = len(body[0].tokens)
        dialect = self.dialect(body[0], width, version)
        frames = [self.frame(body[i], body[i + 1], width, dialect) for i in range(0, len(body), 2)]
        one_based = frames[0][0] == 1 and max(f[0] for f in frames) == n_frames
        if one_based:
            if self.strict:
                raise self.error(body[1], "frame numbers must start at 0 in strict mode")
            if dialect == "standard":
                dialect = "vreng"
            frames = [(number - 1, *rest) for number, *rest in frames]
        if self.float_values and dialect == "standard":
            dialect = "xface"
        return self.assemble(frames, body, fps=fps, n_frames=n_frames, name=name, version=version,
                             dialect=dialect)

    def header(self, line: _Line) -> tuple[str, str, float, int]:
        expected = "expected '<version> <name> <fps> <n_frames>'"
        tokens = line.tokens
        if len(tokens) < 4:
            raise self.error(line, f"bad header {line.raw.strip()!r}: {expected}")
        version, fps_text, count_text = tokens[0], tokens[-2], tokens[-1]
        name = " ".join(tokens[1:-2])
        if not _is_number(version):
            raise self.error(line, f"bad header version {version!r}: {expected}")
        if not _is_number(fps_text) or not 0 < float(fps_text) < math.inf:
            raise self.error(line, f"bad frame rate {fps_text!r} in the header: {expected}")
        if not count_text.isdigit():
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
    ) -> tuple[int, np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
        if len(mask_line.tokens) != width:
            raise self.error(mask_line, f"mask line has {len(mask_line.tokens)} tokens, "
                             f"expected {width} like the first mask line")
        if any(t not in ("0", "1") for t in mask_line.tokens):
            bad = next(t for t in mask_line.tokens if t not in ("0", "1"))
            raise self.error(mask_line, f"mask token {bad!r} is not 0 or 1")
        flags = np.array([t == "1" for t in mask_line.tokens])
        number_text, *tokens = value_line.tokens
        if not number_text.isdigit():
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
        for slot in np.flatnonzero(flags):
            if slot in groups:
                count = groups[slot]
                field = [self.number(value_line, t, integer=True) for t in
                         tokens[position : position + count]]
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

    def number(self, line: _Line, token: str, *, integer: bool) -> float:
        try:
            value = float(token)
        except ValueError:
            raise self.error(line, f"value {token!r} is not a number") from None
        if not math.isfinite(value):
            raise self.error(line, f"value {token!r} is not finite")
        if not value.is_integer() or not token.lstrip("+-").isdigit():
            if integer or self.strict:
                raise self.error(line, f"value {token!r} is not an integer")
            self.float_values = True
        return value

    def assemble(
        self, frames: list, body: list[_Line], *, fps: float, n_frames: int, name: str,
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
            line = body[2 * index + 1]
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
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


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
        The FAP stream; its fps must be a whole number (resample it otherwise).
    path:
        The file to write.
    dialect:
        ``"standard"`` (68 mask tokens, integer values: the recommended choice, read
        correctly by Xface, Greta (Java and C++) and VREng), ``"xface"`` (standard plus
        the FAP 1/2 token groups; warns when it writes them: Greta's Java reader and VREng
        shift every later value), ``"greta"`` (69 mask tokens, the 69th always 0, as Greta
        writes) or ``"extended"`` (84 mask tokens with facelib's FAPs 69-84, plus FAP 1/2;
        only facelib reads it). Every dialect but ``extended`` warns, naming them, when it
        drops extended FAPs 69-84 that carry values.
    name:
        The header's name; default: the file's stem. Spaces become underscores.

    Returns the path written.
    """
    if dialect not in _WRITE_DIALECTS:
        raise ParameterError(f"unknown .fap dialect {dialect!r}; choose one of {_WRITE_DIALECTS}")
    if not float(stream.fps).is_integer():
        raise ParameterError(f"a .fap file needs a whole frame rate, the stream has "
                             f"{stream.fps:g} fps: resample it first (stream.resample(25))")
    path = Path(path)
    label = "_".join((name if name is not None else path.stem).split()) or "facelib"
    width = {"standard": N_STANDARD_FAPS, "xface": N_STANDARD_FAPS,
             "greta": _GRETA_MASK, "extended": N_FAPS}[dialect]
    high_level = dialect in ("xface", "extended")
    _warn_dropped(stream, path, dialect)
    values = np.rint(stream.values).astype(np.int64)
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
        out.append(" ".join("1" if m else "0" for m in mask[i]))
        tokens = [str(i)]
        for slot in np.flatnonzero(mask[i]):
            if slot == 0:
                tokens += [str(int(v)) for v in stream.viseme[i]]  # type: ignore[index]
            elif slot == 1:
                tokens += [str(int(v)) for v in stream.expression[i]]  # type: ignore[index]
            else:
                tokens.append(str(values[i, slot]))
        out.append(" ".join(tokens))
    write_text_atomic(path, "\n".join(out) + "\n")
    return path


def _warn_dropped(stream: FapStream, path: Path, dialect: str) -> None:
    """Warn about what a dialect cannot carry: extended FAPs 69-84 outside ``extended``, and
    the FAP 1/2 token groups of ``xface`` that Greta's Java reader and VREng misread."""
    if dialect != "extended":
        used = (stream.mask[:, N_STANDARD_FAPS:] & (stream.values[:, N_STANDARD_FAPS:] != 0))
        dropped = [int(i) + N_STANDARD_FAPS + 1 for i in np.flatnonzero(used.any(axis=0))]
        if dropped:
            warnings.warn(
                f"{path}: the {dialect} dialect has no extended FAPs; dropping FAP "
                f"{', '.join(map(str, dropped))} (write dialect='extended' to keep them; "
                "only facelib reads that dialect)", FacelibWarning, stacklevel=3)
    if dialect == "xface" and stream.mask[:, :2].any() and (
            stream.viseme is not None or stream.expression is not None):
        warnings.warn(
            f"{path}: the xface dialect writes FAP 1/2 as 4- and 6-token groups, which Greta's "
            "Java reader and VREng read as one token each, shifting every later value of "
            "the frame; dialect='standard' is read correctly by every player",
            FacelibWarning, stacklevel=3)
