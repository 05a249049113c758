"""``animate``: eye-behaviour cues -> a FapTrack on FAPs 19-26 and 48-50 plus an event log.

Between cues and after the last one the ``default`` behaviour runs (mode from ``speaking``),
so the eyes never freeze. A cue that starts before the previous one ends cuts it there.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from facelib.checks import check_count, check_fps, check_items, check_number, check_seed
from facelib.cues import GazeCue
from facelib.errors import ParameterError
from facelib.gaze.behaviours import BoundBehaviour, bind_behaviour, merge_behaviours
from facelib.gaze.blinks import blink_closure, schedule_blinks
from facelib.gaze.events import Blink, GazeEvent, HeadMove, Saccade
from facelib.gaze.fixation import Fixational, fixational_motion, hold_envelope
from facelib.gaze.model import gaze_model
from facelib.gaze.motion import Motion
from facelib.gaze.planner import Planner
from facelib.mpeg4.tables import ANGLE_UNIT, N_FAPS, fap
from facelib.mpeg4.track import FapTrack

__all__ = ["GAZE_FAPS", "GazeAnimation", "animate", "pursue", "simulate"]

# The FAPs the eye generator drives, by their names in the standard's table.
_UPPER_LIDS = ("close_t_l_eyelid", "close_t_r_eyelid")
_LOWER_LIDS = ("close_b_l_eyelid", "close_b_r_eyelid")
_YAW = ("yaw_l_eyeball", "yaw_r_eyeball")
_PITCH = ("pitch_l_eyeball", "pitch_r_eyeball")
_HEAD = ("head_pitch", "head_yaw", "head_roll")

GAZE_FAPS = tuple(fap(name).id for name in (*_UPPER_LIDS, *_LOWER_LIDS, *_YAW, *_PITCH, *_HEAD))
"""The FAPs the eye generator drives (ids 19-26 and 48-50)."""

_DEG_AU = float(np.pi / 180.0 / ANGLE_UNIT)  # 1 degree in angle units (1745.33 AU)


@dataclass(frozen=True, eq=False)
class GazeAnimation:
    """What the eye generator produced.

    Attributes
    ----------
    track: FapTrack with weight on FAPs 19-26 (lids, eyeballs; always 1) and 48-50 (head;
        1 where the eyes turn the head, fading to 0 within 0.5 deg of neutral).
    saccades, blinks, head_moves: event records in time order (seconds, degrees).
    gaze: (n_frames, 2) float64 degrees (left, up) of the planned gaze line (eyes plus head,
        without the fixational motion).
    eyes: (n_frames, 2) float64 degrees, eye-in-head rotation (within the eye limits),
        with the fixational drift and micro-saccades of gaze holds.
    head: (n_frames, 2) float64 degrees (left, up), head rotation.
    lid_closure: (n_frames,) float64 in [0, 1], blink closure.
    open_track: the same track with the lids as they would be without blinks; the
        synchronizer blends those with the expressions and applies the blinks after.
    blink_lids: (upper, lower) lid FAP values in IRISD units at full blink closure.
    microsaccades: onsets (s) of the micro-saccades of the gaze holds (their steps and the
        drift are in ``eyes``; see :mod:`facelib.gaze.fixation`).
    """

    track: FapTrack
    saccades: tuple[Saccade, ...]
    blinks: tuple[Blink, ...]
    head_moves: tuple[HeadMove, ...]
    gaze: np.ndarray
    eyes: np.ndarray
    head: np.ndarray
    lid_closure: np.ndarray
    open_track: FapTrack
    blink_lids: tuple[float, float]
    microsaccades: tuple[float, ...] = ()

    @property
    def events(self) -> tuple[GazeEvent, ...]:
        """Saccades (including pursuit catch-ups), blinks and head moves by start time."""
        merged: list[GazeEvent] = [*self.saccades, *self.blinks, *self.head_moves]
        return tuple(sorted(merged, key=lambda e: e.start))


def _checked(fps: object, n_frames: object, seed: object) -> tuple[float, int, int]:
    """The shared argument checks: ``ParameterError`` for a bad frame rate, frame count or
    seed."""
    return check_fps(fps), check_count("n_frames", n_frames), check_seed(seed)


def _start_at_rest(planner: Planner, default: BoundBehaviour) -> None:
    """Start the eyes and the head where the ``default`` behaviour rests (its gaze and head
    offsets, e.g. toward a partner in a dialogue) rather than straight ahead and turning
    there in the first second; the library's default rests straight ahead (unchanged)."""
    gaze_at, head_at = default.gaze_offset_deg, default.head_offset_deg
    if not any(gaze_at) and not any(head_at):
        return
    planner.gaze, planner.gaze_target = Motion(gaze_at), np.asarray(gaze_at, dtype=float)
    planner.head, planner.head_target = Motion(head_at), np.asarray(head_at, dtype=float)


def _mode_lookup(speaking: np.ndarray | None, fps: float, n_frames: int):
    if speaking is None:
        return lambda t: "listening"
    talk = np.asarray(speaking, dtype=bool)
    if talk.shape != (n_frames,):
        raise ParameterError(f"speaking must have shape ({n_frames},), got {talk.shape}")

    def mode_at(t: float) -> str:
        if n_frames == 0:
            return "listening"
        return "talking" if talk[min(max(int(t * fps), 0), n_frames - 1)] else "listening"

    return mode_at


def animate(
    cues: Sequence[GazeCue],
    *,
    fps: float,
    n_frames: int,
    seed: int,
    behaviours: Mapping[str, Mapping[str, Any]] | None = None,
    speaking: np.ndarray | None = None,
    blink_rate: float = 1.0,
) -> GazeAnimation:
    """Eye, lid and eye-driven head animation for ``n_frames`` frames at ``fps``.

    Parameters
    ----------
    cues: eye-behaviour cues (any order); each binds its ``args`` to the behaviour.
    fps, n_frames: the output frame rate and length.
    seed: seed of every random draw (saccades, intervals, blinks); same inputs and seed give
        bit-identical output.
    behaviours: storyboard-defined or overridden behaviours, merged over the library.
    speaking: (n_frames,) bool, True where the character talks; behaviours in mode
        ``auto`` use talking statistics there and listening elsewhere (all listening if None).
    blink_rate: factor on every state's spontaneous blink rate (``alive/blinks.json``),
        e.g. from a mood; the least blink interval holds whatever the factor.

    Raises
    ------
    FdlError: unknown behaviour (with a suggestion) or bad values, with the cue's file/line.
    ParameterError: bad fps, n_frames or speaking.
    """
    fps, n_frames, seed = _checked(fps, n_frames, seed)
    blink_rate = check_number("blink_rate", blink_rate, low=0.0, high=100.0)
    cues = check_items("cues", cues, GazeCue)
    library = merge_behaviours(behaviours)
    bound = [
        (c, bind_behaviour(c.behaviour, c.args, library=library, origin=c.origin))
        for c in sorted(cues, key=lambda c: c.start_ms)
    ]
    default = bind_behaviour("default", (), library=library)
    seconds = n_frames / fps
    gaze_rng, blink_rng, fixation_rng = np.random.default_rng(seed).spawn(3)
    planner = Planner(gaze_rng, _mode_lookup(speaking, fps, n_frames), blink_rate=blink_rate)
    _start_at_rest(planner, default)

    segments = _segments(bound, default, seconds)
    for t0, t1, behaviour in segments:
        if t0 >= seconds:
            break
        engine = getattr(planner, behaviour.engine)
        engine(t0, min(t1, seconds), behaviour)

    blinks = schedule_blinks(
        blink_rng, seconds=seconds, rate_per_min=planner.blink_rate, evoked_at=planner.evoked
    )
    times = np.arange(n_frames, dtype=float) / fps
    fixation = fixational_motion(fixation_rng, times,
                                 still=hold_envelope(times, planner.saccades))
    return _render(planner, blinks, fps=fps, n_frames=n_frames, vergence=None,
                   fixation=fixation)


def _segments(
    bound: Sequence[tuple[GazeCue, BoundBehaviour]], default: BoundBehaviour, seconds: float
) -> list[tuple[float, float, BoundBehaviour]]:
    """(start s, end s, behaviour) runs covering ``[0, seconds]``: each cue until the next
    cue starts, the default behaviour in the gaps and after the last cue."""
    segments: list[tuple[float, float, BoundBehaviour]] = []
    t = 0.0
    for k, (cue, behaviour) in enumerate(bound):
        start = cue.start_ms / 1000.0
        end = cue.end_ms / 1000.0
        if k + 1 < len(bound):
            end = min(end, bound[k + 1][0].start_ms / 1000.0)
        if start > t:
            segments.append((t, start, default))
        if end > start:
            segments.append((start, end, behaviour))
        t = max(t, end)
    if t < seconds or not segments:
        segments.append((t, max(seconds, t), default))
    return segments


def _columns(names: Sequence[str]) -> list[int]:
    """0-based columns of the named FAPs in a frame of 84 values."""
    return [fap(name).index for name in names]


def _open_lids(aperture: np.ndarray, pitch_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Upper and lower lid values (IRISD units, ``(n,)``) without blinks: the behaviour's
    ``aperture`` (closure fraction) and the lid-eye coupling to the eyes' ``pitch_deg``."""
    lids = gaze_model()["lids"]
    closed = gaze_model()["blink"]["upper_closure_irisd"]
    upper = aperture * closed - lids["upper_irisd_per_deg"] * pitch_deg
    upper_open = np.clip(upper, lids["upper_min_irisd"], lids["upper_max_irisd"])
    return upper_open, lids["lower_irisd_per_deg"] * pitch_deg


def _render(
    planner: Planner,
    blinks: list[Blink],
    *,
    fps: float,
    n_frames: int,
    vergence: np.ndarray | None,
    fixation: Fixational | None = None,
) -> GazeAnimation:
    model = gaze_model()
    times = np.arange(n_frames, dtype=float) / fps
    gaze = planner.gaze.sample(times)
    head = planner.head.sample(times)
    drift = 0.0 if fixation is None else fixation.offsets  # (n, 2) deg: drift, micro-saccades
    eyes = np.clip(gaze - head + drift, planner.eye_lo, planner.eye_hi)
    closure = blink_closure(times, blinks, frame_s=1.0 / fps)
    b = model["blink"]
    upper_open, lower_open = _open_lids(planner.lid.sample(times)[:, 0], eyes[:, 1])
    upper = upper_open + (b["upper_closure_irisd"] - upper_open) * closure
    lower = lower_open + (b["lower_closure_irisd"] - lower_open) * closure
    half_v = np.zeros(n_frames) if vergence is None else 0.5 * vergence

    values = np.zeros((n_frames, N_FAPS), dtype=np.float64)
    weight = np.zeros((n_frames, N_FAPS), dtype=np.float32)
    upper_lids, lower_lids = _columns(_UPPER_LIDS), _columns(_LOWER_LIDS)
    (yaw_l, yaw_r), pitch = _columns(_YAW), _columns(_PITCH)
    head_pitch, head_yaw, _roll = head_cols = _columns(_HEAD)
    values[:, upper_lids] = upper[:, None]
    values[:, lower_lids] = lower[:, None]
    values[:, yaw_l] = (eyes[:, 0] - half_v) * _DEG_AU
    values[:, yaw_r] = (eyes[:, 0] + half_v) * _DEG_AU
    values[:, pitch] = (-eyes[:, 1] * _DEG_AU)[:, None]
    values[:, head_pitch] = -head[:, 1] * _DEG_AU
    values[:, head_yaw] = head[:, 0] * _DEG_AU
    weight[:, [*upper_lids, *lower_lids, yaw_l, yaw_r, *pitch]] = 1.0
    full = float(model["head"]["weight_full_deg"])
    head_w = np.clip(np.hypot(head[:, 0], head[:, 1]) / full, 0.0, 1.0)
    weight[:, head_cols] = head_w[:, None]
    track = FapTrack(fps, values.astype(np.float32), weight)
    values[:, upper_lids] = upper_open[:, None]
    values[:, lower_lids] = lower_open[:, None]
    open_track = FapTrack(fps, values.astype(np.float32), weight)
    arrays = []
    for array in (gaze, eyes, head, closure):
        frozen = np.ascontiguousarray(array)
        frozen.flags.writeable = False
        arrays.append(frozen)
    return GazeAnimation(
        track=track,
        saccades=tuple(sorted(planner.saccades, key=lambda s: s.start)),
        blinks=tuple(blinks),
        head_moves=tuple(planner.head_moves),
        gaze=arrays[0],
        eyes=arrays[1],
        head=arrays[2],
        lid_closure=arrays[3],
        open_track=open_track,
        blink_lids=(float(b["upper_closure_irisd"]), float(b["lower_closure_irisd"])),
        microsaccades=() if fixation is None else tuple(fixation.microsaccades.tolist()),
    )


def simulate(
    behaviour: str,
    *args: str | float,
    seconds: float,
    fps: float = 25.0,
    seed: int = 0,
    behaviours: Mapping[str, Mapping[str, Any]] | None = None,
    speaking: bool = False,
    blink_rate: float = 1.0,
) -> GazeAnimation:
    """Run one behaviour for ``seconds`` as an eye-script tuple would, e.g.
    ``simulate("default", "talking", 0.9, seconds=600)``. ``speaking`` says whether the
    character talks throughout (for mode ``auto``); ``blink_rate`` scales the blink rate
    (see :func:`animate`)."""
    seconds = check_number("seconds", seconds, low=0.0, low_open=True)
    fps = check_fps(fps)
    n_frames = round(seconds * fps)
    cue = GazeCue(behaviour, tuple(args), 0, round(seconds * 1000))
    talk = np.full(n_frames, bool(speaking))
    return animate(
        [cue], fps=fps, n_frames=n_frames, seed=seed, behaviours=behaviours, speaking=talk,
        blink_rate=blink_rate,
    )


def pursue(
    target_deg: np.ndarray,
    *,
    fps: float,
    seed: int = 0,
    head: bool = False,
    distance_m: float | np.ndarray | None = None,
    start_deg: tuple[float, float] = (0.0, 0.0),
) -> GazeAnimation:
    """Follow a moving target with the eyes (the thesis's "Follower Eyes").

    Parameters
    ----------
    target_deg: (n_frames, 2) degrees (left, up) of the target direction seen from between
        the eyes, one row per frame (e.g. a tracked user's face mapped to angles).
    fps: frame rate of ``target_deg`` and of the output.
    seed: seed of the blinks (pursuit itself is deterministic).
    head: let the head follow (``pursuit.head_share`` of the motion, lagged).
    distance_m: target distance in metres (scalar or (n_frames,)); when given, the eyes
        converge on it (vergence 2 atan(IPD / 2d)); None = far target, parallel eyes.
    start_deg: gaze direction at frame 0.
    """
    target = np.asarray(target_deg, dtype=float)
    if target.ndim != 2 or target.shape[1] != 2 or not np.isfinite(target).all():
        raise ParameterError(f"target_deg must be a finite (n_frames, 2) array, got {target.shape}")
    fps, n_frames, seed = _checked(fps, target.shape[0], seed)
    planner = Planner(np.random.default_rng(seed).spawn(2)[0], lambda t: "listening")
    if start_deg != (0.0, 0.0):
        planner.gaze = Motion(start_deg)
        planner.gaze_target = np.asarray(start_deg, dtype=float)
    default = bind_behaviour("default", (), library=merge_behaviours(None))
    planner.begin(0.0, default)
    if n_frames > 0:
        planner.follow(0.0, np.arange(n_frames) / fps, target, head=head)
    vergence = None
    if distance_m is not None:
        dist = np.broadcast_to(np.asarray(distance_m, dtype=float), (n_frames,))
        if not (np.isfinite(dist).all() and (dist > 0).all()):
            raise ParameterError(f"distance_m must be positive and finite, got {distance_m!r}")
        ipd = float(gaze_model()["pursuit"]["interocular_m"])
        vergence = np.degrees(2.0 * np.arctan(0.5 * ipd / dist))
    blinks = schedule_blinks(
        np.random.default_rng(seed).spawn(2)[1],
        seconds=n_frames / fps,
        rate_per_min=planner.blink_rate,
        evoked_at=planner.evoked,
    )
    return _render(planner, blinks, fps=fps, n_frames=n_frames, vergence=vergence)
