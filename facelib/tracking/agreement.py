"""How well recovered FAP curves agree with the true ones, with the statistics a closed loop
needs to be fair (issue 37's review).

A correlation of 0.9 is a fair goal only for a FAP that moves well above what tracking reads
when the face does not move at all: the *wobble*, the spread of the recovered curve of a
still face whose head turns as in the clip (a still SOMA-X head turning reads a lip-corner
raise wobbling by 43-47 units, and expressive.fdl raises those corners by 89-91 units, so no
tracker could correlate at 0.9 there). So each FAP is judged by a rule picked from the
truth's spread: where the true curve's standard deviation is at least ``ratio`` (3) times the
wobble, its correlation; elsewhere its error in FAP units. Curves are pooled over several
clips per head (each clip's mean taken out), and every correlation carries a confidence
interval from Fisher's z with the *effective* number of independent samples: neighbouring
frames of smooth curves are not independent (one 110-frame clip gives 30-40 samples).

Pure numpy; the rendering and tracking are :mod:`facelib.tracking.closedloop`'s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from facelib.errors import ParameterError

__all__ = ["SPREAD_RATIO", "FapAgreement", "agreement", "effective_samples",
           "fisher_interval"]

SPREAD_RATIO = 3.0
"""A FAP is judged by its correlation where its true spread is at least this many times the
still head's wobble (the review's rule)."""


@dataclass(frozen=True)
class FapAgreement:
    """One FAP's agreement over pooled clips.

    fap: FAP id; spread: the true curves' standard deviation (FAP units, clip means out);
    wobble: the still face's error standard deviation (FAP units); judged: ``"correlation"``
    where ``spread >= ratio * wobble``, else ``"error"``; correlation, low, high: Pearson's r
    and its 95 % interval; samples: effective independent samples; gain: least-squares slope
    of recovered on true; error: root-mean-square error (FAP units, clip means out);
    bias_error: the same with the clip means left in (a constant offset counts).
    """

    fap: int
    spread: float
    wobble: float
    judged: str
    correlation: float
    low: float
    high: float
    samples: float
    gain: float
    error: float
    bias_error: float


def effective_samples(a: np.ndarray, b: np.ndarray) -> float:
    """Effective number of independent samples behind the correlation of two ``(n,)``
    curves (Bartlett): ``n / (1 + 2 sum_k rho_a(k) rho_b(k))`` over the lags ``k >= 1`` until
    either curve's autocorrelation first falls to 0 or below; at least 3, at most ``n``."""
    x = np.asarray(a, np.float64) - np.mean(a)
    y = np.asarray(b, np.float64) - np.mean(b)
    n = len(x)
    if n < 4 or x @ x == 0 or y @ y == 0:
        return float(max(min(n, 3), 0))
    total = 0.0
    for lag in range(1, n // 2):
        ra = (x[:-lag] @ x[lag:]) / (x @ x)
        rb = (y[:-lag] @ y[lag:]) / (y @ y)
        if ra <= 0 or rb <= 0:
            break
        total += ra * rb
    return float(min(max(n / (1 + 2 * total), 3.0), n))


def fisher_interval(r: float, samples: float, *, level: float = 0.95) -> tuple[float, float]:
    """``(low, high)`` interval of a correlation ``r`` from ``samples`` independent samples
    (Fisher's z, normal approximation); ``(-1, 1)`` with 3 samples or fewer, NaNs for a NaN
    ``r``."""
    if not 0 < level < 1:
        raise ParameterError(f"level must be in (0, 1), got {level}")
    if math.isnan(r):
        return float("nan"), float("nan")
    if samples <= 3:
        return -1.0, 1.0
    z = math.atanh(min(max(r, -0.999999), 0.999999))
    quantile = math.sqrt(2) * _erfinv(level)
    half = quantile / math.sqrt(samples - 3)
    return math.tanh(z - half), math.tanh(z + half)


def _erfinv(y: float) -> float:
    """Inverse error function on ``(0, 1)`` by bisection (a few calls per report)."""
    low, high = 0.0, 6.0
    for _ in range(80):
        mid = (low + high) / 2
        if math.erf(mid) < y:
            low = mid
        else:
            high = mid
    return (low + high) / 2


def agreement(truths: Sequence[np.ndarray], founds: Sequence[np.ndarray],
              wobble: np.ndarray, faps: Sequence[int], *,
              ratio: float = SPREAD_RATIO) -> list[FapAgreement]:
    """Each FAP of ``faps`` judged over the pooled clips: ``truths`` and ``founds`` are one
    ``(n_i, 84)`` true and recovered array per clip (same shapes pairwise), ``wobble`` the
    ``(84,)`` standard deviations of the error (recovered minus true) on a still face with
    the clips' head motion (FAP units: for the face FAPs what is read where nothing moves,
    for the head's what the pose misses). ParameterError when the clips do not pair up."""
    if len(truths) != len(founds) or not truths:
        raise ParameterError(f"give one recovered array per true one, got {len(truths)} and "
                             f"{len(founds)}")
    pairs = []
    for true_clip, found_clip in zip(truths, founds, strict=True):
        t, f = np.asarray(true_clip, np.float64), np.asarray(found_clip, np.float64)
        if t.shape != f.shape or t.ndim != 2 or t.shape[1] < max(faps):
            raise ParameterError(f"true and recovered clips must be (n, 84) alike, got "
                                 f"{t.shape} and {f.shape}")
        pairs.append((t, f))
    spread_floor = np.asarray(wobble, np.float64)
    out = []
    for fap_id in faps:
        col = fap_id - 1
        a = np.concatenate([t[:, col] - t[:, col].mean() for t, _ in pairs])
        b = np.concatenate([f[:, col] - f[:, col].mean() for _, f in pairs])
        raw = np.concatenate([f[:, col] - t[:, col] for t, f in pairs])
        samples = sum(effective_samples(t[:, col], f[:, col]) for t, f in pairs)
        r = (float(np.corrcoef(a, b)[0, 1]) if a.std() > 0 and b.std() > 0
             else float("nan"))
        low, high = fisher_interval(r, samples)
        spread, shake = float(a.std()), float(spread_floor[col])
        out.append(FapAgreement(
            fap=int(fap_id), spread=spread, wobble=shake,
            judged="correlation" if spread >= ratio * shake and spread > 0 else "error",
            correlation=r, low=low, high=high, samples=samples,
            gain=float(a @ b / (a @ a)) if a @ a > 0 else float("nan"),
            error=float(np.sqrt(np.mean((b - a) ** 2))),
            bias_error=float(np.sqrt(np.mean(raw ** 2)))))
    return out
