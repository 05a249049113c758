"""Piecewise 2-D angle signals (gaze line, head) built from movements, evaluated at any times.

A :class:`Motion` is a time-ordered list of movements. Each movement starts at ``start``
from wherever the signal was at that moment (so a new movement cleanly interrupts one still
in progress) and reaches ``to`` after ``duration``; the signal then holds until the next
movement. Profiles: ``"saccade"`` (skewed bell velocity, :func:`saccade_profile`),
``"minjerk"`` (minimum-jerk, for the head) and ``"sampled"`` (a path given as samples, for
smooth pursuit).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

import numpy as np

from facelib.gaze.model import saccade_profile

__all__ = ["Motion", "Movement", "minimum_jerk"]


def minimum_jerk(u: np.ndarray) -> np.ndarray:
    """Minimum-jerk position fraction 10u^3 - 15u^4 + 6u^5 at normalised time u in [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


@dataclass(frozen=True, slots=True)
class Movement:
    """One movement of a 2-D angle signal (degrees, (left, up)).

    start, duration: seconds. to: (2,) end point. profile: ``"saccade"``, ``"minjerk"`` or
    ``"sampled"``. For ``"sampled"``, ``path_t`` (m,) seconds relative to ``start`` and
    ``path`` (m, 2) degrees give the trajectory (linear in between; ``to`` is its last row).
    """

    start: float
    duration: float
    to: tuple[float, float]
    profile: str = "saccade"
    path_t: np.ndarray | None = field(default=None, compare=False)
    path: np.ndarray | None = field(default=None, compare=False)


class Motion:
    """A 2-D angle signal starting at ``initial`` (degrees) and changed by movements added in
    time order with :meth:`add`."""

    def __init__(self, initial: tuple[float, float] = (0.0, 0.0)) -> None:
        self._initial = np.asarray(initial, dtype=float)
        self._moves: list[Movement] = []
        self._starts: list[np.ndarray] = []
        self._start_times: list[float] = []

    @property
    def movements(self) -> tuple[Movement, ...]:
        return tuple(self._moves)

    def add(self, move: Movement) -> np.ndarray:
        """Append ``move``; movements planned to start after it are dropped (the newer
        command wins). Returns the (2,) point it starts from."""
        while self._moves and self._moves[-1].start > move.start:
            self._moves.pop()
            self._starts.pop()
            self._start_times.pop()
        origin = self.at(move.start)
        self._moves.append(move)
        self._starts.append(origin)
        self._start_times.append(move.start)
        return origin

    def at(self, t: float) -> np.ndarray:
        """The (2,) value at time ``t`` seconds."""
        k = bisect.bisect_right(self._start_times, t) - 1
        if k < 0:
            return self._initial.copy()
        return self._evaluate(k, np.array([t], dtype=float))[0]

    def sample(self, times: np.ndarray) -> np.ndarray:
        """Values at ``times`` ((n,) seconds, ascending or not) as (n, 2) float64 degrees."""
        times = np.asarray(times, dtype=float)
        out = np.tile(self._initial, (times.size, 1))
        if not self._moves:
            return out
        which = np.searchsorted(np.asarray(self._start_times), times, side="right") - 1
        order = np.argsort(which, kind="stable")
        bounds = np.searchsorted(which[order], np.arange(len(self._moves) + 1))
        for k in range(len(self._moves)):
            sel = order[bounds[k] : bounds[k + 1]]
            if sel.size:
                out[sel] = self._evaluate(k, times[sel])
        return out

    def _evaluate(self, k: int, times: np.ndarray) -> np.ndarray:
        """Movement ``k`` at ``times`` (all at or after its start) -> (n, 2)."""
        move = self._moves[k]
        origin = self._starts[k]
        to = np.asarray(move.to, dtype=float)
        rel = times - move.start
        if move.profile == "sampled":
            path_t, path = move.path_t, move.path
            if path_t is None or path is None:
                raise ValueError("a sampled movement needs path_t and path")
            return np.column_stack(
                [np.interp(rel, path_t, path[:, 0]), np.interp(rel, path_t, path[:, 1])]
            )
        u = rel / move.duration if move.duration > 0 else np.ones_like(rel)
        if move.profile == "saccade":
            frac = saccade_profile(u, float(np.hypot(*(to - origin))))
        else:
            frac = minimum_jerk(u)
        return origin + np.outer(frac, to - origin)
