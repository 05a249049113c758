"""Thesis eye-script tuples, storyboard-defined behaviours, head-eye and lid coupling, errors."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.cues import GazeCue
from facelib.errors import FdlError
from facelib.gaze import GAZE_FAPS, animate, bind_behaviour, simulate
from facelib.gaze.behaviours import merge_behaviours
from facelib.gaze.model import gaze_model
from facelib.gaze.norms import head_eye_rule

DEG_AU = np.pi / 180 / 1e-5


def test_lookto_left_with_head_turns_eyes_and_head_left():
    anim = simulate("lookTo", "left", 17.0, "yes", seconds=2.0, seed=0)
    assert anim.gaze[-1] == pytest.approx([17.0, 0.0], abs=1e-6)
    share = gaze_model()["head"]["look_share"]
    assert anim.head[-1, 0] == pytest.approx(17.0 * share, abs=1e-3)
    v = anim.track.values[-1]
    assert v[22] > 0 and v[23] > 0  # FAP 23/24 positive = toward the face's left
    assert v[48] == pytest.approx(17.0 * share * DEG_AU, rel=1e-4)  # FAP 49 head yaw
    assert anim.track.weight[-1, 48] == 1.0
    (look,) = [s for s in anim.saccades if s.kind == "look"]
    (move,) = anim.head_moves
    assert look.direction == pytest.approx(0.0) and look.magnitude == pytest.approx(17.0)
    assert move.start - look.start == pytest.approx(gaze_model()["head"]["latency_s"])


def test_a_small_lookto_without_head_keeps_the_head_still():
    """Below the head-eye rule's onset (alive/head_eye.json, 10 deg) the eyes move alone."""
    anim = simulate("lookTo", "upright", 9.0, "no", seconds=1.0, seed=0)
    assert not anim.head_moves and np.abs(anim.head).max() == 0
    target = [-9 * np.sqrt(0.5), 9 * np.sqrt(0.5)]
    assert anim.gaze[-1] == pytest.approx(target, abs=1e-6)
    # the eyes hold the target up to their fixational drift and micro-saccades (< 0.5 deg)
    assert np.hypot(*(anim.eyes[-1] - target)) < 0.5
    # Looking up raises the upper lids (negative FAP 19) and the pupils (negative FAP 25).
    assert anim.track.values[-1, 18] < 0 and anim.track.values[-1, 24] < 0
    assert set(np.flatnonzero(anim.track.weight.max(axis=0)) + 1) <= set(GAZE_FAPS)


def test_large_statistical_shifts_recruit_the_head():
    anim = simulate("default", "talking", seconds=600, seed=4)
    threshold = head_eye_rule().onset_deg
    big = [s for s in anim.saccades if s.kind == "away" and s.head > 0]
    assert big, "some looks away must exceed the head threshold"
    assert all(s.head > 0 for s in anim.saccades if s.magnitude > 2 * threshold + 2)
    small_from_centre = [
        s for s in anim.saccades if s.kind == "mutual" and s.magnitude < 2.0 and s.head == 0
    ]
    assert small_from_centre


def test_upper_lid_follows_vertical_gaze():
    anim = simulate("default", "talking", seconds=120, seed=9)
    open_ = anim.lid_closure == 0
    upper = anim.track.values[open_, 18]
    pitch_up = anim.eyes[open_, 1]
    assert np.corrcoef(upper, pitch_up)[0, 1] < -0.99


def test_blinks_close_fully_fast_and_reopen_slowly():
    anim = simulate("default", "talking", seconds=60, seed=2, fps=25)
    upper = anim.track.values[:, 18]
    for blink in anim.blinks[1:-1]:
        frames = np.arange(int(blink.start * 25), int((blink.start + blink.duration) * 25) + 2)
        assert upper[frames].max() == pytest.approx(1024.0)
    cfg = gaze_model()["blink"]
    assert cfg["close_s"] < cfg["open_s"]


def test_concentration_tuple_keeps_eyes_nearly_still_and_blinks_rarely():
    anim = simulate("concentration", 0.01, seconds=600, seed=1)
    away = [s.magnitude for s in anim.saccades if s.kind == "away"]
    assert max(away) < 0.5
    assert len(anim.blinks) / 10 < 8  # reading-like rate, far below 17/min
    assert anim.eyes[:, 1].mean() < -3  # attention slightly below eye level


def test_discomfort_tuple_avoids_mutual_gaze():
    anim = simulate("discomfort", 0.99, 0.6, seconds=600, seed=1)
    kinds = [s.kind for s in anim.saccades]
    assert kinds.count("mutual") / len(kinds) < 0.03
    base = simulate("default", "talking", seconds=600, seed=1)
    assert len(anim.blinks) > len(base.blinks)


def test_distress_and_ironic_differ_in_the_expected_directions():
    distress = simulate("distress", 0.5, seconds=300, seed=3)
    ironic = simulate("ironic", 0.5, seconds=300, seed=3)
    neutral = simulate("default", "talking", seconds=300, seed=3)
    assert distress.gaze[:, 1].mean() < neutral.gaze[:, 1].mean() - 2
    assert distress.track.values[:, 47].mean() > 0  # FAP 48 head pitch positive = down
    assert ironic.gaze[:, 1].mean() > neutral.gaze[:, 1].mean() + 1
    lid = lambda a: np.median(a.track.values[:, 18])  # noqa: E731
    assert lid(distress) > lid(neutral) and lid(ironic) > lid(neutral)
    full = bind_behaviour("distress", (1.0,), library=merge_behaviours(None))
    half = bind_behaviour("distress", (0.5,), library=merge_behaviours(None))
    assert half.gaze_offset_deg[1] == pytest.approx(0.5 * full.gaze_offset_deg[1])


def test_pursuit_tuple_follows_smoothly_to_the_right():
    anim = simulate("pursuit", "right", 17.0, "yes", seconds=2.0, seed=0)
    assert anim.gaze[-1, 0] == pytest.approx(-17.0, abs=1.6)
    step = np.abs(np.diff(anim.gaze[:, 0]))
    assert step.max() < 2.0  # no big jumps at 8.5 deg/s
    assert anim.head[-1, 0] < -3.0


def test_gaps_and_tail_keep_the_eyes_alive():
    cues = [GazeCue("lookTo", ("left", 10.0, "no"), 20_000, 1000)]
    anim = animate(cues, fps=25, n_frames=25 * 60, seed=0, speaking=np.ones(1500, bool))
    before = [s for s in anim.saccades if s.start < 20]
    after = [s for s in anim.saccades if s.start > 21]
    assert len(before) > 5 and len(after) > 5
    assert len(anim.blinks) > 15


def test_storyboard_behaviour_overrides_the_library():
    custom = {"nervous": {"base": "discomfort", "blink_scale": 3.0}}
    anim = simulate("nervous", 0.5, seconds=300, seed=0, behaviours=custom)
    assert len(anim.blinks) / 5 > 40
    with pytest.raises(FdlError, match="did you mean 'blink_scale'"):
        merge_behaviours({"x": {"blink_scal": 2}})


@pytest.mark.parametrize(
    ("name", "args", "message"),
    [
        ("lookto", ("left", 17.0, "yes"), "did you mean 'lookTo'"),
        ("lookTo", ("lfet", 17.0, "yes"), "did you mean 'left'"),
        ("lookTo", ("left", "far", "yes"), "angle must be a number"),
        ("lookTo", ("left", 17.0, "maybe"), '"yes" or "no"'),
        ("default", ("talkng",), "did you mean 'talking'"),
        ("discomfort", (1.5, 0.6), r"outside \[0.0, 1.0\]"),
        ("distress", (0.5, 0.2), "at most 1 values"),
    ],
)
def test_bad_cues_raise_fdl_errors_with_file_and_line(name, args, message):
    cue = GazeCue(name, args, 0, 1000, origin=("eyes.fdl", 7))
    with pytest.raises(FdlError, match=message) as info:
        animate([cue], fps=25, n_frames=25, seed=0)
    assert info.value.path == "eyes.fdl" and info.value.line == 7
    assert str(info.value).startswith("eyes.fdl:7:")
