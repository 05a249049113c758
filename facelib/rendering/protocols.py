"""What rendering needs of a face and of a source: small structural types.

Any object with these attributes can be rendered, so rendering depends on no concrete face
class; :class:`facelib.engine.Face` satisfies :class:`Deformable` (defined with the
:class:`~facelib.clip.Clip` that carries it), an ``Animation`` satisfies :class:`HasFaps`.
Every render entry turns its source into a Clip first (:func:`facelib.clip.make_clip`).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from facelib.clip import Deformable
from facelib.mpeg4.stream import FapStream

__all__ = ["Deformable", "HasFaps"]


@runtime_checkable
class HasFaps(Protocol):
    """An animation: a FapStream as ``faps`` (``audio`` and ``audio_offset`` are optional)."""

    @property
    def faps(self) -> FapStream: ...
