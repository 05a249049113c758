"""The synchronizer: resolves the generators' conflicts into one FAP stream (thesis 4.2.4).

Each step is a small pure function over :class:`FapTrack` objects:

1. :func:`blend` expressions with visemes (mouth conflict, eq. 4.11);
2. :func:`blend` the result with gaze (eyelid and head conflict, 25 % gaze);
3. idle micro-movements of brows, lids and mouth corners (:mod:`facelib.sync.alive`);
4. :func:`close_lids` for blinks, which no expression may hold open;
5. :func:`add_head_noise` where gaze does not move the head;
6. nods and the mood's brow beats on the stressed syllables (:mod:`facelib.sync.nods`);
7. breathing and a listener's head motion, then the eyes' counter-rotation to all of the
   idle head motion (steps 5-7), so gaze stays on its target;
8. :func:`to_stream`.

A mood (``head_scale``, ``speech_brow``) scales the head motion of 5 and 6 frame by frame.
"""

from __future__ import annotations

import numpy as np

from facelib.checks import check_seed
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import ANGLE_UNIT, fap
from facelib.mpeg4.track import FapTrack
from facelib.sync.alive import (
    Liveliness,
    add_alive_head,
    add_micro,
    counter_roll_eyes,
    eased,
)
from facelib.sync.nods import accents, add_brow_beats, add_nods
from facelib.sync.noise import perlin1d
from facelib.sync.rules import HeadNoise, SyncRules

__all__ = ["HEAD_FAPS", "add_head_noise", "blend", "close_lids", "combine", "to_stream"]

HEAD_FAPS = tuple(fap(name).index for name in ("head_pitch", "head_yaw", "head_roll"))
"""Columns of FAP 48-50."""
_UPPER_LIDS = (fap("close_t_l_eyelid").index, fap("close_t_r_eyelid").index)
_LOWER_LIDS = (fap("close_b_l_eyelid").index, fap("close_b_r_eyelid").index)


def blend(a: FapTrack, b: FapTrack, *, weight_a: float | np.ndarray,
          weight_b: float | np.ndarray) -> FapTrack:
    """Weighted blend of two tracks.

    weight_a, weight_b: one weight for every FAP, or ``(84,)`` arrays of per-FAP weights.

    Per frame and FAP: ``(wa*A + wb*B) / (wa + wb)`` with ``wa = weight_a * a.weight`` and
    ``wb = weight_b * b.weight``. Where only one track drives a FAP, its value is kept as
    it is; with both at full weight and weights (1, 3) this is eq. 4.11, (E + 3V) / 4.
    The result's weight is the larger of the two.
    """
    wa = a.weight.astype(np.float64) * weight_a
    wb = b.weight.astype(np.float64) * weight_b
    total = wa + wb
    mixed = (wa * a.values + wb * b.values) / np.where(total > 0, total, 1.0)
    lone_a = (a.weight > 0) & (b.weight == 0)
    lone_b = (b.weight > 0) & (a.weight == 0)
    values = np.where(lone_a, a.values, np.where(lone_b, b.values, mixed))
    return FapTrack(a.fps, values.astype(np.float32), np.maximum(a.weight, b.weight))


def close_lids(
    track: FapTrack, closure: np.ndarray, *, closed: tuple[float, float]
) -> FapTrack:
    """Blinks: move the lids ``closure`` (``(n_frames,)`` in [0, 1]) of the way from where
    they are to ``closed`` (upper, lower lid values in IRISD units, the eye model's
    ``GazeAnimation.blink_lids``); 1 closes the eye whatever an expression or gaze asked of
    the lids."""
    closure = np.asarray(closure, np.float64)[:, None]
    values = track.values.astype(np.float64)
    weight = track.weight.copy()
    for columns, target in zip((_UPPER_LIDS, _LOWER_LIDS), closed, strict=True):
        cols = list(columns)
        values[:, cols] += closure * np.maximum(target - values[:, cols], 0.0)  # never opens
        weight[:, cols] = np.maximum(weight[:, cols], (closure > 0).astype(np.float32))
    return FapTrack(track.fps, values.astype(np.float32), weight)


def add_head_noise(
    track: FapTrack,
    *,
    noise: HeadNoise,
    seed: int,
    head_driven: np.ndarray,
    speaking: np.ndarray | None = None,
    scale: np.ndarray | None = None,
) -> FapTrack:
    """Add Perlin head motion to FAP 48-50, faded out where ``head_driven`` (``(n_frames,)``
    in [0, 1], how strongly gaze moves the head) is 1, so gaze-driven head turns are kept.

    While ``speaking`` (``(n_frames,) bool``) the motion is livelier: amplitude and
    frequency grow by ``noise.speaking_amplitude`` / ``speaking_frequency``, eased over
    about half a second so there is no jolt. ``scale`` (``(n_frames,)``, the mood's head
    motion; None: 1) multiplies the amplitude.
    """
    n = track.n_frames
    t = np.arange(n) / track.fps
    talk = np.zeros(n) if speaking is None else np.asarray(speaking, np.float64)[:n]
    if talk.size < n:
        talk = np.pad(talk, (0, n - talk.size))
    width = max(round(0.5 * track.fps), 1)
    padded = np.pad(talk, width, mode="edge")
    talk = np.convolve(padded, np.ones(width) / width, "same")[width:-width]
    rate = noise.frequency_hz * (1.0 + (noise.speaking_frequency - 1.0) * talk)
    phase = np.concatenate([[0.0], np.cumsum(rate[:-1])]) / track.fps if n else t
    gain = 1.0 + (noise.speaking_amplitude - 1.0) * talk
    free = 1.0 - np.clip(np.asarray(head_driven, np.float64), 0.0, 1.0)
    if scale is not None:
        free = free * np.asarray(scale, np.float64)
    values = track.values.astype(np.float64)
    weight = track.weight.copy()
    for axis, column in enumerate(HEAD_FAPS):
        wave = perlin1d(phase, seed=seed * 3 + axis, octaves=noise.octaves)
        amplitude = np.deg2rad(noise.amplitude_deg[axis]) / ANGLE_UNIT
        values[:, column] += wave * amplitude * gain * free
        weight[:, column] = np.maximum(weight[:, column], np.float32(1.0))
    return FapTrack(track.fps, values.astype(np.float32), weight)


def to_stream(track: FapTrack) -> FapStream:
    """The final stream: every FAP that is driven anywhere is set in every frame (0, the
    neutral value, where nothing drives it), so players never hold a stale value."""
    driven = (track.weight > 0).any(axis=0)
    mask = np.broadcast_to(driven, track.values.shape)
    return FapStream(track.fps, track.values, mask.copy())


def combine(
    *,
    expressions: FapTrack,
    visemes: FapTrack,
    gaze: FapTrack,
    blinks: np.ndarray | None = None,
    blink_lids: tuple[float, float] | None = None,
    speaking: np.ndarray | None = None,
    rules: SyncRules | None = None,
    seed: int = 0,
    liveliness: Liveliness | None = None,
    head_scale: np.ndarray | None = None,
    speech_brow: np.ndarray | None = None,
) -> FapStream:
    """Resolve the three generators' tracks (all of one length and fps) into a stream.

    gaze: the eye track with its lids open (blinks are applied after the lid blend).
    blinks: ``(n_frames,)`` lid closure in [0, 1] from the eye-behaviour model, or None;
    blink_lids: the (upper, lower) lid values at full closure (``GazeAnimation.blink_lids``);
        needed with ``blinks``.
    speaking: ``(n_frames,) bool`` where the character talks (livelier head noise, no
        listening motion).
    liveliness: amplitude and rate factors of the idle motion (default: all 1).
    head_scale, speech_brow: ``(n_frames,)`` the mood's head-motion factor and brow beat
        (ENS units; :class:`facelib.expressions.MoodCurves` ``scales``), or None.
    """
    seed = check_seed(seed)
    rules = rules or SyncRules.load()
    lively = liveliness or Liveliness()
    mouth_e, mouth_v = rules.mouth_weights()
    face = blend(expressions, visemes, weight_a=mouth_e, weight_b=mouth_v)
    face = blend(face, gaze, weight_a=rules.eyes_head[0], weight_b=rules.eyes_head[1])
    alive = rules.alive
    if alive is not None:
        talk = eased(speaking, face.n_frames, fps=face.fps, ease_s=alive.listening.ease_s)
        face = add_micro(face, rules=alive, seed=seed, talk=talk, liveliness=lively)
    if blinks is not None:
        if blink_lids is None:
            raise ParameterError("combine: blinks need blink_lids (GazeAnimation.blink_lids)")
        face = close_lids(face, blinks, closed=blink_lids)
    head_driven = gaze.weight[:, list(HEAD_FAPS)].max(axis=1, initial=0.0)
    head_before = face.values[:, list(HEAD_FAPS)].astype(np.float64)
    if rules.head_noise is not None:
        face = add_head_noise(face, noise=rules.head_noise, seed=seed,
                              head_driven=head_driven, speaking=speaking, scale=head_scale)
    if rules.speech_nods is not None:
        beats = accents(visemes, nods=rules.speech_nods)
        face = add_nods(face, strength=beats, nods=rules.speech_nods, seed=seed,
                        head_driven=head_driven, scale=head_scale)
        if speech_brow is not None:
            face = add_brow_beats(face, strength=beats, nods=rules.speech_nods,
                                  brow=speech_brow)
    if alive is not None:
        face = add_alive_head(face, rules=alive, seed=seed, talk=talk, liveliness=lively)
        face = counter_roll_eyes(face, head_before=head_before, gain=alive.vor_gain)
    return to_stream(face)
