"""A face alive between cues: breathing, a listener's head, idle micro-movements and the
eyes' counter-rotation to idle head motion, added to the synchronized track (issue 32 item 4).

The rules are ``facelib/data/alive/idle.json`` (:class:`AliveRules`); how much of each a
face shows is :class:`Liveliness` (amplitude and rate factors, 1 = the data's numbers), the
knob a mood turns. Every part is seeded: the same seed gives the same stream.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib import data
from facelib.checks import check_per_frame
from facelib.errors import DataError
from facelib.mpeg4.tables import ANGLE_UNIT, fap
from facelib.mpeg4.track import FapTrack
from facelib.sync.breathing import Breathing, breath_cycle
from facelib.sync.idle import MicroGroup, micro_movements
from facelib.sync.listening import Listening, listening_motion

__all__ = ["AliveRules", "Liveliness", "add_alive_head", "add_micro", "counter_roll_eyes",
           "eased"]

_HEAD = tuple(fap(n).index for n in ("head_pitch", "head_yaw", "head_roll"))
_EYE_YAW = (fap("yaw_l_eyeball").index, fap("yaw_r_eyeball").index)
_EYE_PITCH = (fap("pitch_l_eyeball").index, fap("pitch_r_eyeball").index)
_DEG = float(np.pi / 180.0 / ANGLE_UNIT)  # 1 degree in angle units


@dataclass(frozen=True)
class AliveRules:
    """The rules of ``alive/idle.json``: breathing, listening, micro-movement groups and
    their size while speaking, and the eyes' counter-rotation gain (``vor_gain``)."""

    breathing: Breathing
    listening: Listening
    micro: tuple[MicroGroup, ...]
    micro_speaking_scale: float
    vor_gain: float

    @classmethod
    def load(cls) -> AliveRules:
        """The package's rules (read once); DataError naming the file if malformed."""
        return _default_rules()


@dataclass(frozen=True)
class Liveliness:
    """How alive a face is: factors on the data's amplitudes and rates, each one number or
    ``(n_frames,)`` per frame (a mood that changes over time). 1 everywhere = the data."""

    breathing_amplitude: float | np.ndarray = 1.0
    breathing_rate: float | np.ndarray = 1.0
    listening_amplitude: float | np.ndarray = 1.0
    listening_rate: float | np.ndarray = 1.0
    micro_amplitude: float | np.ndarray = 1.0
    micro_rate: float | np.ndarray = 1.0
    blink_rate: float = field(default=1.0)


def eased(speaking: np.ndarray | None, n_frames: int, *, fps: float, ease_s: float
          ) -> np.ndarray:
    """``(n_frames,) float64`` in [0, 1]: where the character speaks (``(n,) bool`` or None
    for nowhere), smoothed by a box of ``ease_s`` so motion fades in and out."""
    talk = np.zeros(n_frames)
    if speaking is not None:
        given = np.asarray(speaking, np.float64)[:n_frames]
        talk[: given.size] = given
    width = max(round(ease_s * fps), 1)
    padded = np.pad(talk, width, mode="edge")
    return np.convolve(padded, np.ones(width) / width, "same")[width:-width]


def add_micro(track: FapTrack, *, rules: AliveRules, seed: int, talk: np.ndarray,
              liveliness: Liveliness) -> FapTrack:
    """Idle micro-movements (brows, lids, mouth corners) added to ``track``, at
    ``micro_speaking_scale`` of their size where ``talk`` (eased, ``(n,)``) is 1."""
    n = track.n_frames
    scale = 1.0 + (rules.micro_speaking_scale - 1.0) * talk
    offsets = micro_movements(n, fps=track.fps, seed=seed, groups=rules.micro,
                              amplitude=liveliness.micro_amplitude,
                              rate=liveliness.micro_rate) * scale[:, None]
    values = track.values.astype(np.float64) + offsets
    weight = track.weight.copy()
    driven = sorted({fap(name).index for group in rules.micro for name in group.faps})
    weight[:, driven] = np.maximum(weight[:, driven], np.float32(1.0))
    return FapTrack(track.fps, values.astype(np.float32), weight)


def add_alive_head(track: FapTrack, *, rules: AliveRules, seed: int, talk: np.ndarray,
                   liveliness: Liveliness) -> FapTrack:
    """Breathing (nostrils, head pitch) and the listener's head motion (faded out where
    ``talk`` is 1) added to ``track``."""
    n = track.n_frames
    b = rules.breathing
    breath = breath_cycle(n, fps=track.fps, seed=seed, rules=b, rate=liveliness.breathing_rate)
    shown = check_per_frame("breathing_amplitude", liveliness.breathing_amplitude, n) * (
        1.0 + (b.speaking_scale - 1.0) * talk)
    head = listening_motion(n, fps=track.fps, seed=seed, rules=rules.listening,
                            amplitude=liveliness.listening_amplitude,
                            rate=liveliness.listening_rate) * (1.0 - talk)[:, None]
    head[:, 0] -= (breath.volume - 0.5) * b.head_pitch_up_deg * shown
    values = track.values.astype(np.float64)
    weight = track.weight.copy()
    for axis, column in enumerate(_HEAD):
        values[:, column] += head[:, axis] * _DEG
    for name, flare in b.nostril_flare.items():
        values[:, fap(name).index] += breath.inflow * flare * shown
    driven = [*_HEAD, *(fap(name).index for name in b.nostril_flare)]
    if n:
        weight[:, driven] = np.maximum(weight[:, driven], np.float32(1.0))
    return FapTrack(track.fps, values.astype(np.float32), weight)


def counter_roll_eyes(track: FapTrack, *, head_before: np.ndarray, gain: float) -> FapTrack:
    """The vestibulo-ocular reflex for idle head motion: the change of head pitch and yaw
    since ``head_before`` (``(n, 3)`` FAP 48-50 values) turns the eyes back by ``gain`` of
    it, so gaze stays where the eye generator put it."""
    values = track.values.astype(np.float64)
    moved = values[:, list(_HEAD)] - head_before
    for column in _EYE_YAW:
        values[:, column] -= gain * moved[:, 1]
    for column in _EYE_PITCH:
        values[:, column] -= gain * moved[:, 0]
    return FapTrack(track.fps, values.astype(np.float32), track.weight)


@cache
def _default_rules() -> AliveRules:
    where = str(data.path("alive/idle.json"))
    try:
        return _rules(data.json_data("alive/idle.json"))
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise DataError(f"bad idle rules: {exc!r}", path=where) from exc


_BREATH_NUMBERS = ("per_min", "rate_jitter", "jitter_smooth_s", "inhale_fraction",
                   "head_pitch_up_deg", "speaking_scale")


def _rules(doc: dict[str, Any]) -> AliveRules:
    """AliveRules from the parsed ``idle.json``; KeyError, TypeError or ValueError when a
    part is missing or not a number (an unknown FAP name raises too)."""
    br = doc["breathing"]
    breathing = Breathing(
        **{k: float(br[k]) for k in _BREATH_NUMBERS},
        nostril_flare=MappingProxyType({fap(k).name: float(v)
                                        for k, v in br["nostril_flare"].items()}))
    if not 0.0 < breathing.inhale_fraction < 1.0:
        raise ValueError(f"inhale_fraction {breathing.inhale_fraction} not in (0, 1)")
    li = doc["listening"]
    sd = li["drift_sd_deg"]
    listening = Listening(
        drift_sd_deg=(float(sd["pitch"]), float(sd["yaw"]), float(sd["roll"])),
        **{k: float(li[k]) for k in Listening.__dataclass_fields__ if k != "drift_sd_deg"})
    groups = tuple(
        MicroGroup(name=str(g["name"]), faps=tuple(fap(n).name for n in g["faps"]),
                   sd=float(g["sd"]), smooth_s=float(g["smooth_s"]),
                   symmetric=min(max(float(g["symmetric"]), 0.0), 1.0))
        for g in doc["micro"]["groups"])
    return AliveRules(breathing=breathing, listening=listening, micro=groups,
                      micro_speaking_scale=float(doc["micro"]["speaking_scale"]),
                      vor_gain=float(doc["vor"]["gain"]))
