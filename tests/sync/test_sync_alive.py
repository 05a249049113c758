"""A face alive between cues (issue 32 item 4): breathing in the FAP stream, a listener's
head motion, idle micro-movements, the eyes' counter-rotation, the amplitude and rate
options, and determinism. Every figure is measured on a generated stream."""

from __future__ import annotations

import numpy as np
import pytest

from facelib import animate, fap
from facelib.errors import ParameterError
from facelib.fdl import loads
from facelib.mpeg4.track import FapTrack
from facelib.sync import AliveRules, Liveliness, SyncRules, combine
from facelib.sync.breathing import breath_cycle
from facelib.sync.listening import listening_motion

DEG = np.pi / 180 / 1e-5
HEAD = [fap(n).index for n in ("head_pitch", "head_yaw", "head_roll")]
NOSE = fap("stretch_l_nose").index


def _listening(seed: int, seconds: int = 120):
    return animate(loads(f'fps = 25\nseed = {seed}\nlook {{ "default", "listening", '
                         f'dur = {seconds} }}'))


def _empty(n: int) -> FapTrack:
    return FapTrack.empty(n, fps=25)


def _pulses_per_min(signal: np.ndarray, fps: float = 25) -> float:
    starts = np.count_nonzero((signal[1:] > 0) & (signal[:-1] <= 0))
    return starts * 60 * fps / signal.size


@pytest.mark.parametrize("seed", [0, 1])
def test_listening_head_moves_with_sd_between_1_and_3_deg(seed):
    values = _listening(seed).faps.values / DEG
    for column in HEAD[:2]:  # pitch (nods) and yaw (drift)
        assert 1.0 <= values[:, column].std() <= 3.0
    assert np.abs(np.diff(values[:, HEAD], axis=0)).max() * 25 < 40  # deg/s: no jerk


def test_breathing_shows_in_the_stream_at_12_to_20_a_minute():
    values = _listening(3).faps.values
    rate = _pulses_per_min(values[:, NOSE])
    assert 12 <= rate <= 20
    assert rate == pytest.approx(AliveRules.load().breathing.per_min, abs=1.0)
    sb = loads('fps = 25\nseed = 3\nlook { "default", "listening", dur = 120 }')
    still = animate(sb, rules=SyncRules(head_noise=None),
                    liveliness=Liveliness(listening_amplitude=0.0)).faps.values
    pitch = still[:, HEAD[0]].astype(np.float64)  # without head noise, drift and nods
    spectrum = np.abs(np.fft.rfft(pitch - pitch.mean(), n=8 * pitch.size))
    freq = np.fft.rfftfreq(8 * pitch.size, 1 / 25) * 60
    band = (freq > 9) & (freq < 30)
    assert 12 <= freq[band][np.argmax(spectrum[band])] <= 20  # the head rises with the chest


def test_breathing_rate_and_amplitude_options():
    rules = AliveRules.load().breathing
    base = breath_cycle(25 * 120, fps=25, seed=4, rules=rules)
    fast = breath_cycle(25 * 120, fps=25, seed=4, rules=rules, rate=1.5)
    assert fast.onsets.size == pytest.approx(1.5 * base.onsets.size, abs=2)
    ramp = np.linspace(0.5, 1.5, 25 * 120)
    assert breath_cycle(25 * 120, fps=25, seed=4, rules=rules, rate=ramp).onsets.size > 0
    n = 25 * 20
    empty = _empty(n)
    still = combine(expressions=empty, visemes=empty, gaze=empty, seed=1,
                    liveliness=Liveliness(breathing_amplitude=0.0))
    assert np.abs(still.values[:, NOSE]).max() == 0
    with pytest.raises(ParameterError, match="rate"):
        breath_cycle(10, fps=25, seed=0, rules=rules, rate=np.ones(3))


def test_listening_motion_fades_out_while_speaking_and_scales():
    n = 25 * 60
    empty = _empty(n)
    quiet = SyncRules(head_noise=None, speech_nods=None)
    talk = np.zeros(n, bool)
    talk[n // 2:] = True
    out = combine(expressions=empty, visemes=empty, gaze=empty, speaking=talk, rules=quiet,
                  seed=2).values[:, HEAD[1]] / DEG
    assert out[: n // 2].std() > 1.0
    assert out[n // 2 + 25:].std() < 0.05  # only breathing is left, and it moves pitch
    rules = AliveRules.load().listening
    half = listening_motion(n, fps=25, seed=2, rules=rules, amplitude=0.5)
    full = listening_motion(n, fps=25, seed=2, rules=rules)
    assert np.allclose(half, 0.5 * full)


def test_idle_micro_movements_of_brows_lids_and_mouth_corners():
    values = _listening(5, seconds=60).faps.values
    for group in AliveRules.load().micro:
        for name in group.faps:
            sd = values[:, fap(name).index].std()
            if name.startswith("close_t"):
                continue  # blinks dominate the lids; checked without them below
            assert 0.5 * group.sd <= sd <= 2.0 * group.sd, name
    n = 25 * 60
    empty = _empty(n)
    lids = fap("close_t_l_eyelid").index
    moving = combine(expressions=empty, visemes=empty, gaze=empty, seed=5).values[:, lids]
    assert moving.std() > 0.5 * AliveRules.load().micro[1].sd
    off = combine(expressions=empty, visemes=empty, gaze=empty, seed=5,
                  liveliness=Liveliness(micro_amplitude=0.0)).values[:, lids]
    assert np.abs(off).max() == 0


def test_the_eyes_counter_roll_the_idle_head_motion():
    anim = _listening(6, seconds=60)
    values = anim.faps.values / DEG
    gaze = anim.tracks["gaze"].values / DEG
    yaw, eye = HEAD[1], fap("yaw_l_eyeball").index
    line = values[:, yaw] + values[:, eye]
    planned = gaze[:, yaw] + gaze[:, eye]
    assert values[:, yaw].std() > 1.0
    assert np.abs(line - planned).max() < 0.05


def test_same_seed_same_alive_stream_and_another_seed_differs():
    a, b, c = _listening(7, 20).faps, _listening(7, 20).faps, _listening(8, 20).faps
    assert a == b
    for name in ("raise_l_i_eyebrow", "raise_l_cornerlip", "stretch_l_nose", "head_yaw"):
        k = fap(name).index
        assert not np.array_equal(a.values[:, k], c.values[:, k]), name
