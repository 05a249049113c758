"""Expression curves: each cue ramps in, holds and ramps out; overlapping cues blend."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Literal

import numpy as np

from facelib.checks import check_count, check_fps
from facelib.cues import ExpressionCue
from facelib.errors import FdlError, ParameterError
from facelib.expressions.library import ExpressionLibrary, default_library
from facelib.mpeg4.tables import N_FAPS
from facelib.mpeg4.track import FapTrack

__all__ = ["DEFAULT_RAMP_MS", "animate", "envelope"]

DEFAULT_RAMP_MS = 400
"""Default ramp in and out, capped at a quarter of the cue's duration."""

Easing = Literal["linear", "smooth"]


def envelope(
    times_ms: np.ndarray,
    *,
    start_ms: int,
    duration_ms: int,
    ramp_in_ms: int,
    ramp_out_ms: int,
    easing: Easing = "linear",
) -> np.ndarray:
    """The cue's strength over time: 0 before it, rising over ``ramp_in_ms``, 1 while it
    holds, falling to 0 over ``ramp_out_ms`` at its end.

    times_ms: ``(n,)`` times in milliseconds. Returns ``(n,) float64`` in [0, 1].
    ``easing="linear"`` ramps as the thesis does; ``"smooth"`` uses the smoothstep
    3s^2 - 2s^3, which starts and ends with zero velocity.
    """
    end = start_ms + duration_ms
    rise = (times_ms - start_ms) / ramp_in_ms if ramp_in_ms > 0 else (times_ms >= start_ms) * 1.0
    fall = (end - times_ms) / ramp_out_ms if ramp_out_ms > 0 else (times_ms < end) * 1.0
    s = np.clip(np.minimum(rise, fall), 0.0, 1.0)
    s = np.where((times_ms >= start_ms) & (times_ms <= end), s, 0.0)
    if easing == "smooth":
        return s * s * (3.0 - 2.0 * s)
    if easing != "linear":
        raise ParameterError(f"unknown easing {easing!r}; choose 'linear' or 'smooth'")
    return s


def _ramps(cue: ExpressionCue) -> tuple[int, int]:
    default = min(DEFAULT_RAMP_MS, cue.duration_ms // 4)
    ramp_in = default if cue.ramp_in_ms is None else cue.ramp_in_ms
    ramp_out = default if cue.ramp_out_ms is None else cue.ramp_out_ms
    if ramp_in < 0 or ramp_out < 0 or ramp_in + ramp_out > cue.duration_ms:
        path, line = cue.origin if cue.origin else (None, None)
        raise FdlError(f"expression {cue.name!r}: ramps of {ramp_in} ms and {ramp_out} ms do "
                       f"not fit its {cue.duration_ms} ms", path=path, line=line)
    return ramp_in, ramp_out


def animate(
    cues: Sequence[ExpressionCue],
    *,
    fps: float,
    n_frames: int,
    library: ExpressionLibrary | None = None,
    importance: Mapping[str, float] | None = None,
    easing: Easing = "linear",
) -> FapTrack:
    """The expression track of a storyboard.

    Each cue contributes ``envelope * intensity * expression`` to the FAPs its expression
    drives. Where cues overlap, the values are averaged with their envelopes as weights
    once the envelopes add up to more than 1, so two full expressions blend half and half
    and a fading one hands over smoothly. Between cues the face is neutral.

    The track's weight on a FAP is the summed envelope (at most 1) times the expression's
    ``importance`` (name -> [0, 1], default 1), which the synchronizer uses to blend the
    expressions against visemes and gaze.

    Returns a :class:`FapTrack` of ``n_frames`` at ``fps``.
    """
    fps = check_fps(fps)
    n_frames = check_count("n_frames", n_frames)
    library = library or default_library()
    importance = importance or {}
    times = np.arange(n_frames) * (1000.0 / fps)
    total = np.zeros((n_frames, N_FAPS))
    strength = np.zeros((n_frames, N_FAPS))
    weight = np.zeros((n_frames, N_FAPS))
    for cue in cues:
        expression = library.get(cue.name, origin=cue.origin)
        ramp_in, ramp_out = _ramps(cue)
        e = envelope(times, start_ms=cue.start_ms, duration_ms=cue.duration_ms,
                     ramp_in_ms=ramp_in, ramp_out_ms=ramp_out, easing=easing)[:, None]
        total += e * cue.intensity * expression.values
        strength += e * expression.mask
        weight += e * expression.mask * float(importance.get(expression.name, 1.0))
    values = total / np.maximum(strength, 1.0)
    return FapTrack(fps, values.astype(np.float32), np.clip(weight, 0.0, 1.0).astype(np.float32))
