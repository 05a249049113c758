"""Blinks: when they happen (spontaneous rate by state, never closer than the least interval,
gaze-evoked on large shifts; ``alive/blinks.json``) and the lid closure curve (fast close,
short closed phase, slower open).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from facelib.gaze.events import Blink
from facelib.gaze.model import gaze_model
from facelib.gaze.norms import blink_norms

__all__ = ["blink_closure", "blink_duration", "schedule_blinks"]


def blink_duration() -> float:
    """Seconds from the start of a blink to the lids fully open again."""
    b = gaze_model()["blink"]
    return float(b["close_s"] + b["closed_s"] + b["open_s"])


def schedule_blinks(
    rng: np.random.Generator,
    *,
    seconds: float,
    rate_per_min: Callable[[float], float],
    evoked_at: Sequence[float] = (),
) -> list[Blink]:
    """Blink times over ``[0, seconds)``.

    Spontaneous blinks form a renewal process: each interval is the least blink interval
    (``min_interval_s`` of ``alive/blinks.json``) plus a gamma variable, with mean
    ``60 / rate`` (rate read from ``rate_per_min(t)`` at the previous blink, so it follows
    changes of state) and the norms' coefficient of variation. ``evoked_at`` are onsets of
    gaze shifts that carry a blink (already thinned by the evoked probability): such a blink
    takes the place of the pending spontaneous one when it comes first, and the blink after
    keeps its time, so the rate stays the measured one; one within the least interval of
    the blink before is dropped. No two onsets are closer than the least interval.
    """
    norms = blink_norms()
    cv, least = norms.interval_cv, norms.min_interval_s
    evoked = sorted(evoked_at)
    blinks: list[Blink] = []
    duration = blink_duration()

    def draw(t: float) -> float:
        rate = rate_per_min(t)
        if rate <= 0:
            return np.inf
        mean = 60.0 / rate
        excess = max(mean - least, 1e-3)
        shape = (excess / max(cv * mean, 1e-9)) ** 2
        return least + float(rng.gamma(shape, excess / shape))

    # The first blink comes after a uniform fraction of an interval (stationary start).
    pending = draw(0.0) * float(rng.random())
    i = 0
    last = -np.inf
    while True:
        while i < len(evoked) and evoked[i] < last + least:
            i += 1
        is_evoked = i < len(evoked) and evoked[i] <= pending
        t = evoked[i] if is_evoked else pending
        i += int(is_evoked)
        if t >= seconds:
            break
        blinks.append(Blink(start=float(t), duration=duration, evoked=bool(is_evoked)))
        last = t
        pending += draw(pending)
    return blinks


def blink_closure(times: np.ndarray, blinks: Sequence[Blink], *, frame_s: float) -> np.ndarray:
    """Lid closure in [0, 1] at ``times`` ((n,) seconds) -> (n,) float64.

    Closing is an ease-in (accelerating) quarter-sine, opening a slower ease-out; each
    frame shows the largest closure within +-half a frame, so a blink whose closed phase is
    shorter than a frame still reaches full closure in some frame.
    """
    b = gaze_model()["blink"]
    close, closed, opening = float(b["close_s"]), float(b["closed_s"]), float(b["open_s"])
    times = np.asarray(times, dtype=float)
    out = np.zeros(times.shape)
    if not blinks:
        return out
    offsets = np.linspace(-0.5 * frame_s, 0.5 * frame_s, 7)
    starts = np.array([bl.start for bl in blinks])
    for off in offsets:
        t = times + off
        k = np.searchsorted(starts, t, side="right") - 1
        rel = np.where(k >= 0, t - starts[np.maximum(k, 0)], np.inf)
        c = np.zeros_like(rel)
        m = rel < close
        c[m] = 1.0 - np.cos(0.5 * np.pi * rel[m] / close)
        m = (rel >= close) & (rel < close + closed)
        c[m] = 1.0
        m = (rel >= close + closed) & (rel < close + closed + opening)
        u = (rel[m] - close - closed) / opening
        c[m] = (1.0 - u) ** 2
        np.maximum(out, c, out=out)
    return out
