"""What the exporters take: a FapStream, an animation (``faps``, its speech audio), or a
:class:`~facelib.clip.Clip`; each export makes the Clip at its entry."""

from __future__ import annotations

import os

from facelib.clip import Clip, make_clip
from facelib.engine import Face
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream

__all__ = ["Source", "export_clip", "face_of"]

Source = FapStream | Clip | object
"""A :class:`~facelib.mpeg4.stream.FapStream`, a :class:`~facelib.clip.Clip`, or an object
with ``faps`` (``audio``, ``audio_offset`` optional), such as ``facelib.run_fdl``'s
``Animation``: see :func:`facelib.clip.make_clip`."""


def export_clip(source: Source, *, face: Face | None = None,
                audio: str | os.PathLike[str] | None = None) -> Clip:
    """The Clip an export plays: ``source`` with ``face`` and ``audio`` as
    :func:`facelib.clip.make_clip` takes them (the audio rule of :mod:`facelib.clip`), except
    that a face the storyboard names is not used: exports play on the bundled head unless
    given a face (its ARKit targets and morph targets belong to it), wearing the
    storyboard's ``hair`` style if it names one. ParameterError for a
    stream without frames or an audio file that does not exist."""
    clip = make_clip(source, face=face, audio=audio, storyboard_face=False)
    if clip.n_frames == 0:
        raise ParameterError("nothing to export: the stream has no frames")
    return clip


def face_of(clip: Clip) -> Face | None:
    """The clip's face as the exports need it (a :class:`facelib.engine.Face`: its operator,
    regions and rig), or None for the bundled head; ParameterError for another face-like."""
    if clip.face is None or isinstance(clip.face, Face):
        return clip.face
    raise ParameterError(f"exports need a facelib.engine.Face, not {type(clip.face).__name__}")
