"""``FapTrack``: what one animation generator contributes before conflicts are resolved."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.checks import check_fps
from facelib.errors import ParameterError
from facelib.mpeg4.tables import N_FAPS

__all__ = ["FapTrack"]


@dataclass(frozen=True, eq=False)
class FapTrack:
    """The output of one generator (expressions, visemes, gaze, head noise).

    Attributes
    ----------
    fps:
        Frames per second, > 0.
    values:
        ``(n_frames, 84) float32`` FAP values in FAP units (column ``k - 1`` is FAP ``k``).
    weight:
        ``(n_frames, 84) float32`` in [0, 1]: how strongly this generator drives each FAP in
        each frame (0 = not at all; the value there is ignored).

    Arrays are copied on construction and read-only.
    """

    fps: float
    values: np.ndarray
    weight: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "fps", check_fps(self.fps))
        values = np.asarray(self.values, dtype=np.float32)
        weight = np.asarray(self.weight, dtype=np.float32)
        if values.ndim != 2 or values.shape[1] != N_FAPS:
            raise ParameterError(f"values must have shape (n_frames, {N_FAPS}), got {values.shape}")
        if weight.shape != values.shape:
            raise ParameterError(f"weight shape {weight.shape} differs from values {values.shape}")
        if not (np.isfinite(values).all() and np.isfinite(weight).all()):
            raise ParameterError("track values and weights must be finite")
        if weight.size and (weight.min() < 0 or weight.max() > 1):
            raise ParameterError(
                f"weights must lie in [0, 1], got range [{weight.min()}, {weight.max()}]"
            )
        for name, array in (("values", values), ("weight", weight)):
            frozen = array.copy()
            frozen.flags.writeable = False
            object.__setattr__(self, name, frozen)

    @classmethod
    def empty(cls, n_frames: int, *, fps: float) -> FapTrack:
        """A track that drives nothing for ``n_frames`` frames."""
        zeros = np.zeros((n_frames, N_FAPS), np.float32)
        return cls(fps, zeros, zeros)

    @property
    def n_frames(self) -> int:
        return int(self.values.shape[0])

    def __len__(self) -> int:
        return self.n_frames

    @property
    def duration(self) -> float:
        """Length in seconds: ``n_frames / fps``."""
        return self.n_frames / self.fps

    def padded(self, n_frames: int) -> FapTrack:
        """This track cut or extended (with weight 0) to ``n_frames``."""
        if n_frames <= self.n_frames:
            return FapTrack(self.fps, self.values[:n_frames], self.weight[:n_frames])
        pad = ((0, n_frames - self.n_frames), (0, 0))
        return FapTrack(self.fps, np.pad(self.values, pad), np.pad(self.weight, pad))
