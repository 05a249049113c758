"""The expression library and expression curves."""

import numpy as np
import pytest

from facelib import FdlError, fap
from facelib.cues import ExpressionCue
from facelib.expressions import animate, default_library, envelope

# Each expression moves these FAPs in this direction (+1 raises/closes/opens as the FAP's
# positive direction says, -1 the other way).
SIGNS = {
    "joy": {"raise_l_cornerlip": 1, "raise_r_cornerlip": 1, "lift_l_cheek": 1},
    "sadness": {"raise_l_cornerlip": -1, "raise_l_i_eyebrow": 1, "squeeze_l_eyebrow": 1},
    "anger": {"raise_l_i_eyebrow": -1, "squeeze_l_eyebrow": 1},
    "fear": {"raise_l_i_eyebrow": 1, "open_jaw": 1},
    "surprise": {"raise_l_i_eyebrow": 1, "raise_r_o_eyebrow": 1, "open_jaw": 1},
    "disgust": {"nose_l_up": 1, "nose_r_up": 1, "lower_t_midlip_o": -1},
    "trust": {"raise_l_cornerlip": 1, "raise_l_i_eyebrow": 1},
    "tongueout": {"thrust_tongue_tip": 1, "open_jaw": 1},
    "inlove": {"close_t_l_eyelid": 1, "raise_r_cornerlip": 1},
    "worry": {"raise_l_i_eyebrow": 1, "raise_l_cornerlip": -1},
    "sleepy": {"close_t_l_eyelid": 1, "close_t_r_eyelid": 1, "head_pitch": 1},
}


def test_library_has_the_thesis_expressions():
    assert set(default_library().names) == set(SIGNS)


@pytest.mark.parametrize(("name", "signs"), SIGNS.items())
def test_each_expression_moves_its_faps_the_right_way(name, signs):
    expression = default_library().get(name)
    for fap_name, sign in signs.items():
        value = expression.values[fap(fap_name).index]
        assert np.sign(value) == sign, (name, fap_name, value)


def test_unknown_expression_names_the_script_line():
    with pytest.raises(FdlError, match=r"story.sb:7: unknown expression 'joyy'.*'joy'"):
        default_library().get("joyy", origin=("story.sb", 7))


def test_storyboard_definitions_add_and_override():
    lib = default_library().with_defs({"smirk": {"raise_l_cornerlip": 120}, "JOY": {3: 10}})
    assert lib.get("smirk").values[fap("raise_l_cornerlip").index] == 120
    assert lib.get("joy").mask.sum() == 1


def test_mixes_of_library_expressions_with_faps_on_top():
    lib = default_library()
    mixed = lib.with_defs({"bittersweet": {"raise_b_midlip": 20}},
                          mixes={"bittersweet": {"joy": 0.5, "sadness": 0.5}})
    got = mixed.get("bittersweet").values
    for name in ("raise_l_cornerlip", "raise_l_i_eyebrow"):
        col = fap(name).index
        expected = 0.5 * lib.get("joy").values[col] + 0.5 * lib.get("sadness").values[col]
        assert got[col] == pytest.approx(expected)
    assert got[fap("raise_b_midlip").index] == 20


def test_envelope_ramps_linear_and_smooth():
    t = np.arange(0, 1100, 100.0)
    e = envelope(t, start_ms=0, duration_ms=1000, ramp_in_ms=200, ramp_out_ms=400)
    assert e.tolist() == pytest.approx([0, 0.5, 1, 1, 1, 1, 1, 0.75, 0.5, 0.25, 0])
    s = envelope(t, start_ms=0, duration_ms=1000, ramp_in_ms=200, ramp_out_ms=400,
                 easing="smooth")
    assert s[1] == pytest.approx(0.5) and s[7] == pytest.approx(0.84375)


def test_curve_ramps_holds_returns_to_neutral_and_scales_with_intensity():
    cue = ExpressionCue("joy", start_ms=400, duration_ms=2000, intensity=0.5)
    track = animate([cue], fps=25, n_frames=100)
    corner = track.values[:, fap("raise_l_cornerlip").index]
    joy = default_library().get("joy")
    full = joy.values[fap("raise_l_cornerlip").index]
    assert corner[:11].max() == 0  # before the cue (frame 10 = 400 ms)
    # holding, at the share its intensity curve gives 0.5 (more than half)
    assert corner[40] == pytest.approx(0.5**joy.exponent * full)
    assert 0.5 < joy.share(0.5) < 1
    assert corner[70:].max() == 0  # after it: neutral
    assert 0 < corner[13] < corner[40]  # ramping in
    assert track.weight[40, fap("raise_l_cornerlip").index] == 1
    assert track.weight[40, fap("open_jaw").index] == 0  # joy does not drive the jaw


def test_overlapping_cues_blend():
    cues = [ExpressionCue("joy", 0, 4000, ramp_in_ms=0, ramp_out_ms=0),
            ExpressionCue("sadness", 2000, 2000, ramp_in_ms=0, ramp_out_ms=0)]
    track = animate(cues, fps=25, n_frames=100)
    col = fap("raise_l_cornerlip").index
    joy, sad = (default_library().get(n).values[col] for n in ("joy", "sadness"))
    assert track.values[25, col] == pytest.approx(joy)
    assert track.values[75, col] == pytest.approx((joy + sad) / 2)


def test_ramps_that_do_not_fit_are_refused():
    cue = ExpressionCue("joy", 0, 100, ramp_in_ms=80, ramp_out_ms=80, origin=("a.fdl", 3))
    with pytest.raises(FdlError, match=r"a.fdl:3"):
        animate([cue], fps=25, n_frames=10)


def test_unknown_names_suggest_only_close_ones():
    library = default_library()
    with pytest.raises(FdlError) as far:
        library.get("nope")
    assert "did you mean" not in str(far.value)  # it used to suggest 'inlove'
    with pytest.raises(FdlError, match="did you mean 'joy'"):
        library.get("joyy")


def test_default_ramps_come_from_the_data_file():
    from facelib.expressions.curves import default_ramp_ms

    assert default_ramp_ms(10_000) == 400
    assert default_ramp_ms(1000) == 250  # a quarter of a short cue


def _dense_animate(cues, *, fps, n_frames, importance, easing):  # type: ignore[no-untyped-def]
    """The expression track as it was computed before issue 30: every cue's envelope over
    every frame, added into full arrays (quadratic time; the reference for the span form;
    the intensity curves of issue 32 applied)."""
    from facelib.expressions.curves import _ramps

    library = default_library()
    times = np.arange(n_frames) * (1000.0 / fps)
    total, strength, weight = (np.zeros((n_frames, 84)) for _ in range(3))
    for cue in cues:
        expression = library.get(cue.name)
        ramp_in, ramp_out = _ramps(cue)
        e = envelope(times, start_ms=cue.start_ms, duration_ms=cue.duration_ms,
                     ramp_in_ms=ramp_in, ramp_out_ms=ramp_out, easing=easing)[:, None]
        total += e * expression.share(cue.intensity) * expression.values
        strength += e * expression.mask
        weight += e * expression.mask * float(importance.get(expression.name, 1.0))
    return ((total / np.maximum(strength, 1.0)).astype(np.float32),
            np.clip(weight, 0.0, 1.0).astype(np.float32))


@pytest.mark.parametrize("easing", ["linear", "smooth"])
def test_each_cue_on_its_own_span_is_bit_identical_to_the_dense_sum(easing):
    # issue 30: each cue works on the frames of its span only; the track must not change
    rng = np.random.default_rng(30)
    names = sorted(default_library().names)
    cues = []
    for _ in range(60):
        duration = int(rng.integers(1, 3000))
        ramps = (None, None) if rng.random() < 0.4 else (
            int(rng.integers(0, duration // 2 + 1)), int(rng.integers(0, duration // 2 + 1)))
        cues.append(ExpressionCue(str(rng.choice(names)), int(rng.integers(0, 24_000)),
                                  duration, intensity=float(rng.uniform(-0.5, 1.5)),
                                  ramp_in_ms=ramps[0], ramp_out_ms=ramps[1]))
    cues.append(ExpressionCue(names[0], 40, 40, ramp_in_ms=0, ramp_out_ms=0))  # frame-exact
    cues.append(ExpressionCue(names[1], 19_990, 5000))  # past the last frame
    importance = {names[0]: 0.5, names[2]: 0.25}
    for fps in (25.0, 29.97):
        n_frames = int(20 * fps)
        track = animate(cues, fps=fps, n_frames=n_frames, importance=importance,
                        easing=easing)
        values, weight = _dense_animate(cues, fps=fps, n_frames=n_frames,
                                        importance=importance, easing=easing)
        assert np.array_equal(track.values, values)
        assert np.array_equal(track.weight, weight)
        assert np.array_equal(np.signbit(track.values), np.signbit(values))
