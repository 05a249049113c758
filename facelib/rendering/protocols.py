"""What rendering needs of a face and of a source: small structural types.

Any object with these attributes can be rendered, so rendering depends on no concrete face
class; :class:`facelib.engine.Face` satisfies :class:`Deformable`, a
:class:`~facelib.mpeg4.stream.FapStream` or an ``Animation`` satisfies :class:`HasFaps`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np

from facelib.mpeg4.stream import FapStream

__all__ = ["Deformable", "HasFaps"]


@runtime_checkable
class Deformable(Protocol):
    """A face mesh that FAPs deform.

    ``vertices``: ``(V, 3) float32`` neutral positions; ``triangles``: ``(F, 3)`` vertex ids;
    ``parts``: part name -> object with ``triangles``; ``vertex_colors``: ``(V, 3)`` sRGB in
    [0, 1] or None.
    """

    @property
    def vertices(self) -> np.ndarray: ...

    @property
    def triangles(self) -> np.ndarray: ...

    @property
    def parts(self) -> Mapping[str, Any]: ...

    def deform(self, stream: FapStream) -> np.ndarray:
        """``(n_frames, V, 3) float32`` vertex positions for every frame of ``stream``."""
        ...

    def deform_frame(self, values: np.ndarray) -> np.ndarray:
        """``(V, 3) float32`` positions for one frame of 84 FAP values."""
        ...


@runtime_checkable
class HasFaps(Protocol):
    """An animation: a FapStream as ``faps`` (``audio`` and ``audio_offset`` are optional)."""

    @property
    def faps(self) -> FapStream: ...
