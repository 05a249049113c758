"""Turns eye behaviours into movements over time: gaze-line and head motions, lid aperture,
blink rate and the event log. Head-eye coordination lives here: a gaze shift beyond the
head threshold recruits the head, which starts ``head.latency_s`` after the eyes.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from facelib.gaze.behaviours import BoundBehaviour
from facelib.gaze.events import HeadMove, Saccade, SaccadeKind
from facelib.gaze.model import (
    gaze_model,
    mode_stats,
    saccade_duration,
    sample_direction,
    sample_interval,
    sample_magnitude,
)
from facelib.gaze.motion import Motion, Movement
from facelib.gaze.norms import blink_norms, head_eye_rule
from facelib.gaze.pursuit import pursue_path

__all__ = ["Planner"]


def _polar(vec: np.ndarray) -> tuple[float, float]:
    """(magnitude, direction in [0, 360)) of a (left, up) vector in degrees."""
    return float(np.hypot(*vec)), float(math.degrees(math.atan2(vec[1], vec[0])) % 360.0)


def head_move_duration(amplitude_deg: float) -> float:
    """Seconds for a head rotation of ``amplitude_deg``: minimum-jerk movement whose peak
    velocity 1.875 A / T equals Greta's (4/3 A/50 + 2/5) * 50 deg/s (``model.json``
    ``head``)."""
    head = gaze_model()["head"]
    peak = float(head["peak_velocity_per_deg"]) * amplitude_deg + float(
        head["peak_velocity_base_deg_s"])
    duration = float(head["minjerk_peak_factor"]) * amplitude_deg / peak
    return max(duration, float(head["min_duration_s"]))


class Planner:
    """Accumulates the plan of one animation; used once by :func:`facelib.gaze.animate`.

    ``mode_at(t)`` says ``"talking"`` or ``"listening"`` for behaviours in mode ``auto``.
    """

    def __init__(self, rng: np.random.Generator, mode_at: Callable[[float], str], *,
                 blink_rate: float = 1.0) -> None:
        self.rng = rng
        self.blink_rate_scale = float(blink_rate)
        self.norms = blink_norms()
        self.head_eye = head_eye_rule()
        self.mode_at = mode_at
        model = gaze_model()
        self.head_cfg = model["head"]
        self.spread = float(model["mutual_spread_deg"])
        lim = model["eye_limits_deg"]
        self.eye_lo = np.array([-lim["yaw"], -lim["down"]], dtype=float)
        self.eye_hi = np.array([lim["yaw"], lim["up"]], dtype=float)
        hl = self.head_cfg["limits_deg"]
        self.head_lo = np.array([-hl["yaw"], -hl["down"]], dtype=float)
        self.head_hi = np.array([hl["yaw"], hl["up"]], dtype=float)
        self.gaze = Motion()
        self.head = Motion()
        self.lid = Motion()
        self.gaze_target = np.zeros(2)
        self.head_target = np.zeros(2)
        self.saccades: list[Saccade] = []
        self.head_moves: list[HeadMove] = []
        self.evoked: list[float] = []
        self.rate_segments: list[tuple[float, str, float, str | None]] = []  # start, mode,
        # scale, blink state (None: the mode's)
        self._lid_value = 0.0

    # -- shared pieces -------------------------------------------------------------------
    def mode(self, behaviour: BoundBehaviour, t: float) -> str:
        return self.mode_at(t) if behaviour.mode == "auto" else behaviour.mode

    def blink_rate(self, t: float) -> float:
        """Spontaneous blinks per minute at time ``t``: the rate of the segment's blink state
        (or its mode's) times the behaviour's ``blink_scale`` and the planner's
        ``blink_rate``."""
        starts = [s for s, _, _, _ in self.rate_segments]
        k = int(np.searchsorted(starts, t, side="right")) - 1
        if k < 0:
            return mode_stats(self.mode_at(t)).blinks_per_min * self.blink_rate_scale
        _, mode, scale, state = self.rate_segments[k]
        mode = self.mode_at(t) if mode == "auto" else mode
        rate = self.norms.rate(state) if state is not None else mode_stats(mode).blinks_per_min
        return rate * scale * self.blink_rate_scale

    def _head_for(self, gaze: np.ndarray, behaviour: BoundBehaviour) -> np.ndarray:
        """Head orientation a gaze target recruits: the head-eye rule (``alive/head_eye.json``,
        or the behaviour's ``head_coupling`` beyond ``head_threshold_deg``) applied to the
        shift from the behaviour's head offset."""
        base = np.asarray(behaviour.head_offset_deg, dtype=float)
        return base + self.head_eye.head_for(gaze - base, onset_deg=behaviour.head_threshold_deg,
                                             slope=behaviour.head_coupling)

    def shift(self, t: float, gaze: np.ndarray, head: np.ndarray | None, kind: SaccadeKind) -> None:
        """A saccade at ``t`` to gaze ``gaze``, moving the head to ``head`` (None: keep)."""
        head_to = self.head_target if head is None else np.clip(head, self.head_lo, self.head_hi)
        gaze = np.clip(gaze, head_to + self.eye_lo, head_to + self.eye_hi)
        start = self.gaze.at(t)
        magnitude, direction = _polar(gaze - start)
        head_amp = 0.0
        if float(np.hypot(*(head_to - self.head_target))) >= float(self.head_cfg["min_move_deg"]):
            t_head = t + float(self.head_cfg["latency_s"])
            head_from = self.head.at(t_head)
            head_amp, head_dir = _polar(head_to - head_from)
            dur = head_move_duration(head_amp)
            self.head.add(Movement(t_head, dur, (float(head_to[0]), float(head_to[1])), "minjerk"))
            self.head_moves = [m for m in self.head_moves if m.start <= t_head]
            self.head_moves.append(HeadMove(t_head, dur, head_amp, head_dir))
            self.head_target = head_to
        duration = saccade_duration(magnitude)
        self.gaze.add(Movement(t, duration, (float(gaze[0]), float(gaze[1])), "saccade"))
        self.saccades.append(Saccade(t, duration, magnitude, direction, head_amp, kind))
        self.gaze_target = gaze
        p_blink = self.norms.evoked_probability(magnitude)
        if p_blink > 0 and self.rng.random() < p_blink:
            self.evoked.append(t)

    def begin(self, t: float, behaviour: BoundBehaviour, *, blink_scale: float = 1.0) -> None:
        """Start a segment: lid aperture ramps to the behaviour's, blink rate follows it."""
        if behaviour.lid_closure != self._lid_value:
            ramp = float(gaze_model()["lids"]["aperture_ramp_s"])
            self.lid.add(Movement(t, ramp, (behaviour.lid_closure, 0.0), "minjerk"))
            self._lid_value = behaviour.lid_closure
        self.rate_segments.append((t, behaviour.mode, blink_scale, behaviour.blink_state))

    # -- engines -------------------------------------------------------------------------
    def statistical(self, t0: float, t1: float, b: BoundBehaviour) -> None:
        """Eyes Alive gaze states from ``t0`` to ``t1``: each state draws mutual gaze (with
        probability p_mutual) or a look away (magnitude law, direction table), lasts a
        duration drawn for its mode and state, and starts with a saccade."""
        self.begin(t0, b, blink_scale=b.blink_scale)
        rng = self.rng
        centre = np.asarray(b.gaze_offset_deg, dtype=float)
        min_gap = float(gaze_model()["saccade"]["min_gap_s"])
        t = t0
        while t < t1:
            stats = mode_stats(self.mode(b, t))
            p_mutual = stats.p_mutual if b.p_mutual is None else b.p_mutual
            if rng.random() < p_mutual:
                r = self.spread * math.sqrt(rng.random())
                phi = rng.uniform(0.0, 2.0 * math.pi)
                gaze = centre + r * np.array([math.cos(phi), math.sin(phi)])
                kind: SaccadeKind = "mutual"
                mean, sd = stats.mutual_s
            else:
                gaze = self._away_target(b, stats.magnitude_max_deg, stats.direction_percent)
                kind = "away"
                mean, sd = stats.away_s
            self.shift(t, gaze, self._head_for(gaze, b), kind)
            interval = sample_interval(rng, mean, sd) * b.interval_scale
            t += max(interval, self.saccades[-1].duration + min_gap)

    def _away_target(
        self, b: BoundBehaviour, mode_max: float, mode_percent: tuple[float, ...]
    ) -> np.ndarray:
        """Current gaze plus a drawn saccade; if that leaves the disk of radius ``limit``
        around the mutual-gaze point, the saccade is shortened along its direction (or,
        when impossible, taken from the mutual-gaze point)."""
        rng = self.rng
        scale = b.magnitude_scale
        amp = scale * sample_magnitude(rng, max_deg=mode_max)
        clamp = b.magnitude_max_deg if b.magnitude_max_deg is not None else math.inf
        amp = min(amp, clamp)
        direction = math.radians(sample_direction(rng, b.direction_percent or mode_percent))
        unit = np.array([math.cos(direction), math.sin(direction)])
        centre = np.asarray(b.gaze_offset_deg, dtype=float)
        limit = min(mode_max * max(scale, 1.0), clamp) + self.spread
        d = self.gaze_target - centre
        target = self.gaze_target + amp * unit
        if float(np.hypot(*(target - centre))) <= limit:
            return target
        du = float(d @ unit)
        disc = du * du - float(d @ d) + limit * limit
        if disc >= 0:
            a = -du + math.sqrt(disc)
            if a > 0:
                return self.gaze_target + min(a, amp) * unit
        return centre + amp * unit

    def look(self, t0: float, t1: float, b: BoundBehaviour) -> None:
        """``lookTo``: one shift to the target, held until ``t1``. The head takes its share
        by the head-eye rule (:meth:`_head_for`); with ``head`` it turns at least
        ``look_share`` of the angle toward the target."""
        self.begin(t0, b, blink_scale=b.blink_scale)
        target = np.asarray(b.target_deg, dtype=float)
        head = self._head_for(target, b)
        if b.head:
            toward = target * float(self.head_cfg["look_share"])
            head = toward if np.hypot(*toward) > np.hypot(*head) else head
        self.shift(t0, target, head, "look")

    def pursuit(self, t0: float, t1: float, b: BoundBehaviour) -> None:
        """``pursuit``: a target moves at constant speed from the current gaze by the cue's
        vector until ``t1``; the eyes follow it (:func:`pursue_path`), the head too if asked."""
        self.begin(t0, b)
        start = self.gaze.at(t0)
        span = max(t1 - t0, 1e-3)
        target_t = np.array([0.0, span])
        target = np.vstack([start, start + np.asarray(b.target_deg)])
        self.follow(t0, target_t, target, head=b.head)

    def follow(self, t0: float, target_t: np.ndarray, target: np.ndarray, *, head: bool) -> None:
        """Pursue ``target`` ((k, 2) degrees at ``target_t`` seconds after ``t0``)."""
        path = pursue_path(target_t, target, start_gaze=tuple(self.gaze.at(t0)))
        end = (float(path.gaze[-1, 0]), float(path.gaze[-1, 1]))
        self.gaze.add(Movement(t0, float(path.t[-1]), end, "sampled", path.t, path.gaze))
        self.gaze_target = np.asarray(end)
        for start, dur, shift in path.catch_ups:
            mag, direction = _polar(np.asarray(shift))
            self.saccades.append(Saccade(t0 + start, dur, mag, direction, 0.0, "catch_up"))
        if not head:
            return
        cfg = gaze_model()["pursuit"]
        share, tau = float(cfg["head_share"]), float(cfg["head_tau_s"])
        h0 = self.head.at(t0)
        goal = h0 + share * (path.gaze - path.gaze[0])
        alpha = 1.0 - math.exp(-(path.t[1] - path.t[0]) / tau) if path.t.size > 1 else 1.0
        head_path = np.empty_like(goal)
        h = h0.copy()
        for i in range(goal.shape[0]):
            h += alpha * (goal[i] - h)
            head_path[i] = h
        head_path = np.clip(head_path, self.head_lo, self.head_hi)
        end_h = (float(head_path[-1, 0]), float(head_path[-1, 1]))
        self.head.add(Movement(t0, float(path.t[-1]), end_h, "sampled", path.t, head_path))
        self.head_moves = [m for m in self.head_moves if m.start <= t0]
        amp, direction = _polar(head_path[-1] - h0)
        self.head_moves.append(HeadMove(t0, float(path.t[-1]), amp, direction))
        self.head_target = head_path[-1]
