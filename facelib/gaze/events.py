"""Event records of the eye generator, so a run can be checked against the model.

Times are seconds from the start of the animation; angles are degrees. Gaze directions use
the image plane of the face: direction 0 = toward the face's own left (+x), 90 = up.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["Blink", "GazeEvent", "HeadMove", "Saccade", "SaccadeKind"]

SaccadeKind = Literal["mutual", "away", "look", "catch_up"]


@dataclass(frozen=True, slots=True)
class Saccade:
    """One rapid eye movement (of the gaze line: eyes plus head).

    Attributes
    ----------
    start, duration: onset and length in seconds (duration = D0 + d * magnitude).
    magnitude: size of the gaze shift in degrees.
    direction: its direction in degrees in [0, 360): 0 = toward the face's left, 90 = up.
    head: amplitude in degrees of the head movement recruited by this shift (0 if none).
    kind: ``"mutual"`` (a hop onto the partner's face), ``"away"`` (a look away drawn from
        the statistical model), ``"look"`` (a scripted ``lookTo`` or behaviour change) or
        ``"catch_up"`` (a correction during smooth pursuit).
    """

    start: float
    duration: float
    magnitude: float
    direction: float
    head: float
    kind: SaccadeKind


@dataclass(frozen=True, slots=True)
class Blink:
    """One blink: ``start`` and ``duration`` (close + closed + open) in seconds;
    ``evoked`` is True for a blink triggered by a large gaze shift."""

    start: float
    duration: float
    evoked: bool = False


@dataclass(frozen=True, slots=True)
class HeadMove:
    """A head rotation driven by the eyes: ``start``/``duration`` in seconds, ``magnitude``
    and ``direction`` in degrees (same convention as :class:`Saccade`)."""

    start: float
    duration: float
    magnitude: float
    direction: float


GazeEvent = Saccade | Blink | HeadMove
"""One logged event of the eye generator."""
