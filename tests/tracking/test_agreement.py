"""The closed loop's statistics (facelib.tracking.agreement): effective samples, Fisher-z
intervals and the spread rule, on curves whose answers are known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from facelib.errors import ParameterError
from facelib.mpeg4 import N_FAPS
from facelib.tracking.agreement import agreement, effective_samples, fisher_interval
from facelib.tracking.faps import bridge_gaze


def smooth_noise(rng: np.random.Generator, n: int, width: int) -> np.ndarray:
    """White noise through a moving average of ``width`` frames."""
    kernel = np.ones(width) / width
    return np.convolve(rng.normal(size=n + width), kernel, mode="valid")[:n]


def test_effective_samples_white_and_smooth() -> None:
    rng = np.random.default_rng(0)
    white = rng.normal(size=(2, 3000))
    assert effective_samples(*white) == pytest.approx(3000, rel=0.02)
    # a moving average of 10 frames: its autocorrelation is the triangle 1 - k/10, so
    # Bartlett's sum is 1 + 2 * sum (1 - k/10)^2 = 6.7 and 3000 frames are about 450 samples
    a, b = smooth_noise(rng, 3000, 10), smooth_noise(rng, 3000, 10)
    assert 350 < effective_samples(a, b) < 560
    assert effective_samples(a[:4], b[:4]) >= 3


def test_fisher_interval() -> None:
    low, high = fisher_interval(0.9, 40)
    assert low < 0.9 < high
    # z = atanh(0.9) = 1.472, +- 1.96 / sqrt(37)
    assert low == pytest.approx(math.tanh(math.atanh(0.9) - 1.96 / math.sqrt(37)), abs=1e-3)
    assert fisher_interval(0.9, 3) == (-1.0, 1.0)
    wide, narrow = fisher_interval(0.84, 35), fisher_interval(0.84, 350)
    assert wide[1] - wide[0] > narrow[1] - narrow[0]
    assert wide[1] > 0.9 > narrow[1]  # 0.84 from 35 samples cannot be told from 0.9
    with pytest.raises(ParameterError):
        fisher_interval(0.5, 10, level=1.5)


def test_spread_rule_picks_the_judgement() -> None:
    rng = np.random.default_rng(1)
    n = 400
    truth = np.zeros((n, N_FAPS))
    truth[:, 2] = 300 * smooth_noise(rng, n, 8)       # open_jaw: moves a lot
    truth[:, 11] = 20 * smooth_noise(rng, n, 8)       # FAP 12: barely
    found = truth + 10 * rng.normal(size=truth.shape)
    wobble = np.full(N_FAPS, 15.0)
    jaw, corner = agreement([truth[:200], truth[200:]], [found[:200], found[200:]], wobble,
                            (3, 12))
    assert jaw.judged == "correlation" and jaw.correlation > 0.95
    assert jaw.low < jaw.correlation < jaw.high
    assert 0.9 < jaw.gain < 1.1
    assert corner.judged == "error"   # its spread is under 3 times the wobble
    assert corner.error == pytest.approx(10, rel=0.15)
    with pytest.raises(ParameterError):
        agreement([truth], [found, found], wobble, (3,))
    with pytest.raises(ParameterError):
        agreement([truth], [found[:, :10]], wobble, (3,))


def test_gaze_is_drawn_across_closed_lids() -> None:
    values = np.zeros((10, N_FAPS))
    mask = np.zeros((10, N_FAPS), bool)
    mask[:, 18:26] = True
    values[:, 22] = np.arange(10) * 100.0     # a look sweeping right
    values[4:6, 22] = -5000.0                 # read wrongly under the closed lids
    values[4:6, 18:20] = 900.0                # a blink
    out = bridge_gaze(values, mask)
    assert out[4, 22] == pytest.approx(400) and out[5, 22] == pytest.approx(500)
    assert (out[:, 18:20] == values[:, 18:20]).all()
    assert values[4, 22] == -5000.0           # the input is left alone
    mask[:, 22] = False                       # no gaze measured: nothing to draw
    assert bridge_gaze(values, mask) is values
