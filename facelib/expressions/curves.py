"""Expression curves: each cue ramps in, holds and ramps out; overlapping cues blend."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import cache
from typing import Literal

import numpy as np

from facelib import data
from facelib.checks import check_count, check_fps, check_items
from facelib.cues import ExpressionCue
from facelib.errors import DataError, FdlError, ParameterError
from facelib.expressions.library import ExpressionLibrary, default_library
from facelib.expressions.moods import MoodCurves
from facelib.mpeg4.tables import N_FAPS
from facelib.mpeg4.track import FapTrack

__all__ = ["animate", "default_ramp_ms", "envelope"]

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


@cache
def _ramp_rules() -> tuple[int, float]:
    doc = data.json_data("expression_ramps.json")
    try:
        return int(doc["ramp_ms"]), float(doc["max_fraction"])
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad ramp rules: {exc!r}",
                        path=str(data.path("expression_ramps.json"))) from exc


def default_ramp_ms(duration_ms: int) -> int:
    """Ramp in and out (ms) of a cue of ``duration_ms`` that gives none:
    ``expression_ramps.json``'s ``ramp_ms``, capped at its ``max_fraction`` of the cue."""
    ramp_ms, fraction = _ramp_rules()
    return min(ramp_ms, int(duration_ms * fraction))


def _ramps(cue: ExpressionCue) -> tuple[int, int]:
    default = default_ramp_ms(cue.duration_ms)
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
    moods: MoodCurves | None = None,
) -> FapTrack:
    """The expression track of a storyboard.

    Each cue contributes ``envelope * share(intensity) * expression`` to the FAPs its
    expression drives (``share``: the expression's intensity curve, ``intensity.csv``).
    Where cues overlap, the values are averaged with their envelopes as weights once the
    envelopes add up to more than 1, so two full expressions blend half and half and a
    fading one hands over smoothly. Between cues the face is neutral.

    The track's weight on a FAP is the summed envelope (at most 1) times the expression's
    ``importance`` (name -> [0, 1], default 1), which the synchronizer uses to blend the
    expressions against visemes and gaze.

    moods: the storyboard's mood baseline (:func:`facelib.expressions.moods.mood_curves`),
    or None. It shows where no expression drives a FAP and blends under the explicit ones:
    ``explicit + (1 - s) * baseline`` with ``s`` the summed envelopes on that FAP (at most 1).

    Returns a :class:`FapTrack` of ``n_frames`` at ``fps``. Each cue touches only the frames
    of its own span (its envelope is 0 elsewhere), so time grows linearly with the length
    of the storyboard.
    """
    cues = check_items("cues", cues, ExpressionCue)
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
        # the frames at start_ms <= t <= end_ms; outside them the envelope is exactly 0 and
        # adding its zeros would change nothing, bit for bit
        span = slice(int(np.searchsorted(times, cue.start_ms, side="left")),
                     int(np.searchsorted(times, cue.end_ms, side="right")))
        e = envelope(times[span], start_ms=cue.start_ms, duration_ms=cue.duration_ms,
                     ramp_in_ms=ramp_in, ramp_out_ms=ramp_out, easing=easing)[:, None]
        total[span] += e * expression.share(cue.intensity) * expression.values
        strength[span] += e * expression.mask
        weight[span] += e * expression.mask * float(importance.get(expression.name, 1.0))
    values = total / np.maximum(strength, 1.0)
    if moods is not None:
        values, weight = _under(moods, values, weight, strength)
    return FapTrack(fps, values.astype(np.float32), np.clip(weight, 0.0, 1.0).astype(np.float32))


def _under(moods: MoodCurves, values: np.ndarray, weight: np.ndarray,
           strength: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The mood baseline blended under the explicit expressions' ``values`` and ``weight``
    (``(n_frames, 84)``), uncovered where their summed envelopes ``strength`` are below 1."""
    if moods.values.shape != values.shape:
        raise ParameterError(f"moods cover {moods.values.shape[0]} frames; the expression "
                             f"track has {values.shape[0]}")
    free = 1.0 - np.clip(strength, 0.0, 1.0)
    return values + free * moods.values, weight + free * moods.mask
