"""``FapStream``: a sequence of FAP frames at a fixed frame rate."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from facelib.checks import check_fps, check_number
from facelib.errors import ParameterError
from facelib.mpeg4.tables import N_FAPS

__all__ = ["EXPRESSION_FIELDS", "VISEME_FIELDS", "FapStream", "check_fps"]

VISEME_FIELDS = ("select1", "select2", "blend", "def")
"""Columns of ``FapStream.viseme`` (FAP 1): two viseme ids 0-14, blend 0-63, def flag."""
EXPRESSION_FIELDS = ("select1", "intensity1", "select2", "intensity2", "init_face", "def")
VISEME_LIMITS = (14, 14, 63, 1)
"""Largest value of each of ``VISEME_FIELDS`` (ISO/IEC 14496-2: 15 visemes, 6-bit blend)."""
EXPRESSION_LIMITS = (6, 63, 6, 63, 1, 1)
"""Largest value of each of ``EXPRESSION_FIELDS`` (7 expressions, 6-bit intensities)."""
"""Columns of ``FapStream.expression`` (FAP 2): two expression ids 0-6 with intensities
0-63, init_face and def flags."""


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, copy=True)
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class FapStream:
    """FAP values over time.

    Attributes
    ----------
    fps:
        Frames per second, > 0. Frame ``i`` is shown at ``i / fps`` seconds.
    values:
        ``(n_frames, 84) float32`` in FAP units (FAPU-relative; angles in 1e-5 rad);
        column ``k - 1`` holds FAP ``k``. Values where ``mask`` is False are 0.
    mask:
        ``(n_frames, 84) bool``: which FAPs each frame sets. Columns 0 and 1 (FAP 1, 2)
        say whether the frame carries viseme / expression data. None (the default) sets
        the FAPs whose values are non-zero in some frame, in every frame.
    viseme:
        ``(n_frames, 4) int16`` with columns ``VISEME_FIELDS``, or None.
    expression:
        ``(n_frames, 6) int16`` with columns ``EXPRESSION_FIELDS``, or None.

    The arrays are copied on construction and read-only. Streams compare equal when the
    frame rate and every array are equal.
    """

    fps: float
    values: np.ndarray
    mask: np.ndarray = field(default=None)  # type: ignore[arg-type]  # None: filled in
    viseme: np.ndarray | None = None
    expression: np.ndarray | None = None

    def __post_init__(self) -> None:
        fps = check_fps(self.fps)
        values = np.asarray(self.values)
        if values.ndim != 2 or values.shape[1] != N_FAPS:
            raise ParameterError(f"values must have shape (n_frames, {N_FAPS}), got {values.shape}")
        if not (np.issubdtype(values.dtype, np.number) and not np.iscomplexobj(values)):
            raise ParameterError(f"values must be real numbers, got dtype {values.dtype}")
        values = values.astype(np.float32)
        bad = np.argwhere(~np.isfinite(values))
        if bad.size:
            frame, col = bad[0]
            raise ParameterError(
                f"values must be finite, frame {frame} FAP {col + 1} is {values[frame, col]}"
            )
        if self.mask is None:  # the FAPs the values use: a column of zeros sets nothing
            mask = np.broadcast_to(values.any(axis=0), values.shape).copy()
            mask[:, :2] = False
        else:
            mask = np.asarray(self.mask)
            if mask.shape != values.shape:
                raise ParameterError(f"mask shape {mask.shape} differs from values {values.shape}")
            if mask.dtype != bool:
                raise ParameterError(f"mask must be bool, got dtype {mask.dtype}")
        values = np.where(mask, values, np.float32(0))
        object.__setattr__(self, "fps", fps)
        object.__setattr__(self, "values", _frozen(values))
        object.__setattr__(self, "mask", _frozen(mask))
        for name, limits in (("viseme", VISEME_LIMITS), ("expression", EXPRESSION_LIMITS)):
            width = len(limits)
            data = getattr(self, name)
            if data is None:
                continue
            data = np.asarray(data)
            if data.shape != (len(values), width):
                raise ParameterError(
                    f"{name} must have shape ({len(values)}, {width}), got {data.shape}"
                )
            if not np.issubdtype(data.dtype, np.integer) and not np.array_equal(
                data, np.round(data)
            ):
                raise ParameterError(f"{name} fields must be integers")
            outside = np.argwhere((data < 0) | (data > np.asarray(limits)))
            if outside.size:
                frame, column = (int(i) for i in outside[0])
                raise ParameterError(f"{name} field {column} of frame {frame} is "
                                     f"{data[frame, column]}, outside 0-{limits[column]}")
            object.__setattr__(self, name, _frozen(data.astype(np.int16)))

    # -- construction -----------------------------------------------------------------

    @classmethod
    def zeros(cls, n_frames: int, *, fps: float, masked: bool = False) -> FapStream:
        """A neutral stream of ``n_frames``; ``masked=True`` sets FAPs 3-84 in every frame."""
        mask = np.zeros((n_frames, N_FAPS), dtype=bool)
        if masked:
            mask[:, 2:] = True
        return cls(fps, np.zeros((n_frames, N_FAPS), np.float32), mask)

    # -- size and time ----------------------------------------------------------------

    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    def __len__(self) -> int:
        return self.n_frames

    @property
    def duration(self) -> float:
        """Length in seconds: ``n_frames / fps``."""
        return self.n_frames / self.fps

    @property
    def times(self) -> np.ndarray:
        """``(n_frames,) float64`` seconds at which each frame is shown."""
        return np.arange(self.n_frames) / self.fps

    def active_faps(self) -> tuple[int, ...]:
        """Ids of the FAPs set in at least one frame."""
        return tuple(int(i) + 1 for i in np.flatnonzero(self.mask.any(axis=0)))

    # -- slicing, joining, resampling --------------------------------------------------

    def __getitem__(self, frames: slice) -> FapStream:
        """Frames ``start:stop`` (a slice with step 1 or 2, 3, ... keeps every n-th frame
        at ``fps / step``)."""
        if not isinstance(frames, slice):
            raise ParameterError(f"index a FapStream with a slice of frames, not {frames!r}")
        step = frames.step or 1
        if step < 1:
            raise ParameterError(f"slice step must be a positive integer, got {step!r}")
        return self._take(frames, self.fps / step)

    def between(self, start: float = 0.0, stop: float | None = None) -> FapStream:
        """The frames shown in ``[start, stop)`` seconds."""
        start = check_number("start", start, low=0.0)
        stop = None if stop is None else check_number("stop", stop, low=start)
        first = int(np.ceil(start * self.fps - 1e-9))
        last = self.n_frames if stop is None else int(np.ceil(stop * self.fps - 1e-9))
        if start < 0 or last < first:
            raise ParameterError(f"bad time span [{start}, {stop}) seconds")
        return self[max(first, 0) : min(last, self.n_frames)]

    def _take(
        self, index: slice | np.ndarray, fps: float, *, values: np.ndarray | None = None
    ) -> FapStream:
        """Frames ``index`` (a slice or an index array) at ``fps``, optionally with new
        ``values`` for them."""
        return FapStream(
            fps,
            self.values[index] if values is None else values,
            self.mask[index],
            None if self.viseme is None else self.viseme[index],
            None if self.expression is None else self.expression[index],
        )

    def resample(self, fps: float) -> FapStream:
        """The stream at another frame rate, covering the same duration.

        FAP values are interpolated linearly in time between neighbouring frames; the mask
        and the high-level FAP 1/2 fields come from the nearest earlier frame.
        """
        fps = check_fps(fps)
        n_out = max(round(self.duration * fps), 1 if self.n_frames else 0)
        if self.n_frames == 0:
            return FapStream.zeros(0, fps=fps)
        t = np.arange(n_out) / fps
        src = np.clip(t * self.fps, 0, self.n_frames - 1)
        lo = np.floor(src + 1e-9).astype(int).clip(0, self.n_frames - 1)
        hi = np.minimum(lo + 1, self.n_frames - 1)
        w = (src - lo)[:, None].clip(0, 1)
        both = self.mask[lo] & self.mask[hi]
        values = np.where(both, (1 - w) * self.values[lo] + w * self.values[hi], self.values[lo])
        return self._take(lo, fps, values=values)

    def at_whole_rate(self) -> FapStream:
        """The stream at the nearest whole frame rate (at least 1 fps), as a ``.fap`` file
        needs: the stream itself when its rate is whole, else resampled with :meth:`resample` (a
        camera's measured 29.97 fps becomes 30, a landmark file's 12.5 becomes 12).
        """
        if float(self.fps).is_integer():
            return self
        return self.resample(max(1, round(self.fps)))

    @staticmethod
    def concat(streams: Iterable[FapStream]) -> FapStream:
        """Join streams end to end; they must share one frame rate."""
        streams = list(streams)
        if not streams:
            raise ParameterError("concat needs at least one stream")
        fps = streams[0].fps
        for s in streams[1:]:
            if s.fps != fps:
                raise ParameterError(f"cannot concatenate streams at {fps} and {s.fps} fps")

        def join(name: str) -> np.ndarray | None:
            parts = [getattr(s, name) for s in streams]
            if all(p is None for p in parts):
                return None
            width = next(p.shape[1] for p in parts if p is not None)
            return np.concatenate(
                [
                    np.zeros((len(s), width), np.int16) if p is None else p
                    for s, p in zip(streams, parts, strict=True)
                ]
            )

        return FapStream(
            fps,
            np.concatenate([s.values for s in streams]),
            np.concatenate([s.mask for s in streams]),
            join("viseme"),
            join("expression"),
        )

    # -- comparison ---------------------------------------------------------------------

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, FapStream):
            return NotImplemented
        return (
            self.fps == other.fps
            and np.array_equal(self.values, other.values)
            and np.array_equal(self.mask, other.mask)
            and _same(self.viseme, other.viseme)
            and _same(self.expression, other.expression)
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"FapStream(fps={self.fps:g}, n_frames={self.n_frames}, "
            f"duration={self.duration:.3f}s, active_faps={len(self.active_faps())})"
        )


def _same(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return np.array_equal(a, b)
