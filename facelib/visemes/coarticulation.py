"""Viseme spans -> FAP curves: a dominance-function blend (Cohen & Massaro 1993) with
guaranteed bilabial closure, and the weight envelope that says when speech drives the mouth.

Rules (dominance magnitudes and fall-off rates per viseme and FAP class, timing) are data:
``facelib/data/visemes/coarticulation.json``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from facelib.errors import ParameterError
from facelib.mpeg4.tables import N_FAPS, fap
from facelib.visemes.articulation import bound
from facelib.visemes.tables import (
    coarticulation_classes,
    dominance_table,
    lower_lip_per_jaw,
    peak_hold,
    timing_rules,
    viseme_targets,
)
from facelib.visemes.timeline import VisemeSpan

__all__ = ["blend", "driven_faps", "envelope", "frame_times_ms", "speaking_mask", "window_ms"]

_BILABIAL = 1
_LOWER_LIP = ("raise_b_midlip", "raise_b_lip_lm", "raise_b_lip_rm", "raise_b_midlip_o",
              "raise_b_lip_lm_o", "raise_b_lip_rm_o")


def frame_times_ms(n_frames: int, fps: float) -> np.ndarray:
    """``(n_frames,) float64``: the time of frame i, ``1000 * i / fps`` ms."""
    return np.arange(n_frames, dtype=np.float64) * (1000.0 / fps)


def driven_faps() -> np.ndarray:
    """``(84,) bool``: the mouth, jaw and tongue FAPs the viseme track drives."""
    mask = np.zeros(N_FAPS, bool)
    for columns in coarticulation_classes().values():
        mask[list(columns)] = True
    return mask


_CHUNK_FRAMES = 512
_NEGLIGIBLE = 1e-7
"""Relative dominance below which a span no longer shapes a frame (sets the window)."""


def window_ms() -> float:
    """How far (ms) a span's influence reaches: beyond it, the dominance of any span is below
    :data:`_NEGLIGIBLE` times that of the span under the frame, whatever their magnitudes
    (``ln(alpha_max / alpha_min / 1e-7) / theta_min``; about 2.5 s with the shipped table).
    Coarticulation is local, so each frame needs only the spans within this window."""
    table = dominance_table().values()
    ratio = max(d.alpha for d in table) / min(d.alpha for d in table)
    theta = min(min(d.theta_before, d.theta_after) for d in table)
    return 1000.0 * float(np.log(ratio / _NEGLIGIBLE)) / theta


def blend(visemes: Sequence[VisemeSpan], times_ms: np.ndarray, *,
          jaw_gain: np.ndarray | None = None, levels: np.ndarray | None = None) -> np.ndarray:
    """FAP values ``(len(times_ms), 84) float32`` (FAP units) of the viseme sequence.

    For each FAP class k (jaw, lip height, lip shape, tongue) and span s the dominance is
    ``alpha_sk * exp(-theta_sk * d)``, d the distance in seconds from the time to the span
    (``theta_before`` before it, ``theta_after`` after it); inside a vowel's span it grows
    as ``alpha_sk * exp(hold * depth)``, depth the distance to the span's nearer end, so
    that a long vowel reaches its target while a short one still blends with its
    neighbours (``peak_hold`` of the data file). Each FAP is the dominance-weighted mean
    of the spans' targets, each span's scaled by its ``levels`` (``(len(visemes), 2)``: the
    jaw class by column 0, the lip classes by column 1; see
    :mod:`facelib.visemes.articulation`; None: 1). The lips then close on every p/b/m
    (see ``_close_bilabials``). FAPs outside the classes stay 0. ``jaw_gain``
    (``(len(times_ms),)``, from the speech's loudness) scales the jaw opening; then the
    values are held within the anatomical bounds (:func:`facelib.visemes.articulation.bound`),
    both before the bilabial closure, so p/b/m still close.

    Frames are taken in chunks, each with the spans within :func:`window_ms` of it only, so
    memory and time grow linearly with the length of the speech (``times_ms`` ascending).
    """
    times = np.asarray(times_ms, dtype=np.float64)
    out = np.zeros((times.size, N_FAPS), np.float32)
    if not visemes or times.size == 0:
        return out
    ids = np.array([s.viseme for s in visemes])
    start = np.array([s.start_ms for s in visemes], np.float64)
    end = np.array([s.end_ms for s in visemes], np.float64)
    reach = window_ms()
    n_spans = len(visemes)
    for lo in range(0, times.size, _CHUNK_FRAMES):
        t = times[lo:lo + _CHUNK_FRAMES]
        first = min(int(np.searchsorted(end, t.min() - reach, side="left")), n_spans - 1)
        last = max(int(np.searchsorted(start, t.max() + reach, side="right")), first + 1)
        part = slice(first, last)
        scale = None if levels is None else levels[part]
        out[lo:lo + t.size] = _blend_dense(ids[part], start[part], end[part], t, scale)
    if jaw_gain is not None:
        out[:, fap("open_jaw").index] *= np.asarray(jaw_gain, np.float32)
    bound(out)
    _close_bilabials(out, visemes, times, reach)
    return out


_LEVEL_COLUMN = {"jaw": 0, "lip_height": 1, "lip_shape": 1}
"""Which articulation level scales each FAP class (the tongue keeps its targets)."""


def _blend_dense(ids: np.ndarray, start: np.ndarray, end: np.ndarray,
                 times: np.ndarray, levels: np.ndarray | None = None) -> np.ndarray:
    """The dominance blend of spans ``ids`` ``[start, end)`` at ``times``: ``(len(times),
    84) float32``, with a ``(len(times), len(ids))`` dominance matrix per FAP class."""
    out = np.zeros((times.size, N_FAPS), np.float32)
    before = np.maximum(start[None, :] - times[:, None], 0.0) / 1000.0  # (n_frames, n_spans)
    after = np.maximum(times[:, None] - end[None, :], 0.0) / 1000.0
    depth = np.maximum(np.minimum(times[:, None] - start[None, :],
                                  end[None, :] - times[:, None]), 0.0) / 1000.0
    held = peak_hold()[ids][None, :] * depth
    targets = viseme_targets()[ids]  # (n_spans, 84)
    table = dominance_table()
    for cls, columns in coarticulation_classes().items():
        params = [table[int(v), cls] for v in ids]
        alpha = np.array([p.alpha for p in params])
        theta_b = np.array([p.theta_before for p in params])
        theta_a = np.array([p.theta_after for p in params])
        # log-domain so far-away spans underflow to 0 instead of overflowing anything
        log_dom = (np.log(alpha)[None, :] - theta_b[None, :] * before
                   - theta_a[None, :] * after + held)
        log_dom -= log_dom.max(axis=1, keepdims=True)
        dom = np.exp(log_dom)
        cols = list(columns)
        shown = targets[:, cols]
        if levels is not None and cls in _LEVEL_COLUMN:
            shown = shown * levels[:, _LEVEL_COLUMN[cls], None]
        out[:, cols] = (dom @ shown) / dom.sum(axis=1, keepdims=True)
    return out


def _close_bilabials(out: np.ndarray, visemes: Sequence[VisemeSpan], times: np.ndarray,
                     reach: float) -> None:
    """Make the lips meet on every p/b/m, whatever the jaw does (speakers close the lips
    with the jaw part open): inside the span the lip heights are the closure's, and the
    lower lip rises by the jaw's extra opening (the jaw carries the lower lip,
    ``lower_lip_per_jaw`` MNS per jaw unit).
    The correction fades outside the span with the bilabial's own dominance fall-off, so
    the lips close smoothly; the frame nearest a span shorter than a frame is closed too.
    Only frames within ``reach`` ms of the span are touched (beyond, the fade is nil)."""
    classes = coarticulation_classes()
    lip = list(classes["lip_height"])
    targets = viseme_targets()
    jaw = fap("open_jaw").index
    lower = [fap(n).index for n in _LOWER_LIP]
    dom = dominance_table()[_BILABIAL, "lip_height"]
    for span in visemes:
        if span.viseme != _BILABIAL:
            continue
        lo = int(np.searchsorted(times, span.start_ms - reach, side="left"))
        hi = int(np.searchsorted(times, span.end_ms + reach, side="right"))
        t = times[lo:hi]
        if t.size == 0:
            continue
        before = np.maximum(span.start_ms - t, 0.0) / 1000.0
        after = np.maximum(t - span.end_ms, 0.0) / 1000.0
        c = np.exp(-dom.theta_before * before - dom.theta_after * after)
        if not np.any((t >= span.start_ms) & (t < span.end_ms)):
            centre = 0.5 * (span.start_ms + span.end_ms)
            c[int(np.argmin(np.abs(t - centre)))] = 1.0
        block = out[lo:hi]
        block[:, lip] += c[:, None] * (targets[_BILABIAL, lip][None, :] - block[:, lip])
        extra = lower_lip_per_jaw() * np.maximum(block[:, jaw] - targets[_BILABIAL, jaw], 0.0)
        block[:, lower] += (c * extra)[:, None]


def speaking_mask(visemes: Sequence[VisemeSpan], times_ms: np.ndarray) -> np.ndarray:
    """``(len(times_ms),) bool``: True where a viseme other than silence is shown."""
    times = np.asarray(times_ms, dtype=np.float64)
    mask = np.zeros(times.size, bool)
    for span in visemes:
        if not span.is_silence:
            lo = int(np.searchsorted(times, span.start_ms, side="left"))
            hi = int(np.searchsorted(times, span.end_ms, side="left"))
            mask[lo:hi] = True
    return mask


def envelope(
    visemes: Sequence[VisemeSpan],
    times_ms: np.ndarray,
    *,
    ramp_ms: int | None = None,
    release_pause_ms: int | None = None,
) -> np.ndarray:
    """``(len(times_ms),) float32`` in [0, 1]: how strongly speech drives the mouth.

    1 while speaking and through pauses shorter than ``release_pause_ms``; a raised-cosine
    ramp of ``ramp_ms`` before the first and after the last sound of each stretch of
    speech; 0 elsewhere (defaults from the data file's timing rules).
    """
    rules = timing_rules()
    ramp = rules["envelope_ramp_ms"] if ramp_ms is None else ramp_ms
    release = rules["release_pause_ms"] if release_pause_ms is None else release_pause_ms
    if ramp < 0 or release < 0:
        raise ParameterError(f"ramp_ms and release_pause_ms must be >= 0, got {ramp}, {release}")
    active: list[list[float]] = []
    for span in visemes:
        if span.is_silence or span.duration_ms == 0:
            continue
        if active and span.start_ms - active[-1][1] < release:
            active[-1][1] = span.end_ms
        else:
            active.append([span.start_ms, span.end_ms])
    times = np.asarray(times_ms, dtype=np.float64)
    env = np.zeros(times.size, np.float64)
    for lo, hi in active:
        first = int(np.searchsorted(times, lo - ramp, side="left"))
        last = int(np.searchsorted(times, hi + ramp, side="right"))
        t = times[first:last]
        dist = np.maximum(np.maximum(lo - t, t - hi), 0.0)
        if ramp > 0:
            part = np.where(dist < ramp, 0.5 * (1.0 + np.cos(np.pi * dist / ramp)), 0.0)
        else:
            part = (dist == 0).astype(np.float64)
        env[first:last] = np.maximum(env[first:last], part)
    return env.astype(np.float32)
