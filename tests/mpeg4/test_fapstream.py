"""FapStream: validation, time, slicing, resampling, concatenation, equality."""

import numpy as np
import pytest

from facelib import FapStream, FapTrack, ParameterError


@pytest.fixture
def ramp(fap_stream):
    """``ramp(n, fps)``: open_jaw rising 10 FAP units per frame from 0."""
    return lambda n=10, fps=25.0: fap_stream(n, fps=fps, open_jaw=np.arange(n) * 10.0)


def test_arrays_are_copied_read_only_and_typed():
    source = np.zeros((3, 84))
    stream = FapStream(25, source)
    source[0, 2] = 5
    assert stream.values[0, 2] == 0
    assert stream.values.dtype == np.float32
    assert stream.mask.dtype == bool
    with pytest.raises(ValueError, match="read-only"):
        stream.values[0, 0] = 1
    # default mask: the FAPs the values use (none here), never FAP 1/2
    assert not stream.mask.any()


def test_default_mask_marks_only_the_faps_the_values_use():
    values = np.zeros((4, 84), np.float32)
    values[1, 2] = 120.0  # open_jaw moves in one frame
    values[:, 22] = -300.0  # eye yaw in all
    stream = FapStream(25, values)
    assert stream.active_faps() == (3, 23)
    assert stream.mask[:, 2].all()  # set in every frame, zero or not: the FAP is in use
    assert repr(stream) == "FapStream(fps=25, n_frames=4, duration=0.160s, active_faps=2)"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"fps": 0, "values": np.zeros((2, 84))}, "fps"),
        ({"fps": float("nan"), "values": np.zeros((2, 84))}, "fps"),
        ({"fps": "25", "values": np.zeros((2, 84))}, "fps"),
        ({"fps": 25, "values": np.zeros((2, 68))}, r"\(n_frames, 84\)"),
        ({"fps": 25, "values": np.zeros((2, 84)), "mask": np.ones((2, 84))}, "bool"),
        ({"fps": 25, "values": np.zeros((2, 84)), "mask": np.ones((3, 84), bool)}, "mask"),
        ({"fps": 25, "values": np.zeros((2, 84)), "viseme": np.zeros((2, 3))}, "viseme"),
        ({"fps": 25, "values": np.zeros((2, 84)), "expression": np.full((2, 6), 0.5)},
         "integers"),
    ],
)
def test_bad_construction_is_refused_with_the_value(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        FapStream(**kwargs)


def test_non_finite_values_name_frame_and_fap():
    values = np.zeros((4, 84))
    values[2, 18] = np.inf
    with pytest.raises(ParameterError, match="frame 2 FAP 19"):
        FapStream(25, values)


def test_unmasked_values_are_zeroed():
    values = np.ones((2, 84))
    mask = np.zeros((2, 84), bool)
    mask[:, 2] = True
    stream = FapStream(25, values, mask)
    assert stream.values.sum() == 2
    assert stream.active_faps() == (3,)


def test_duration_times_and_slicing(ramp):
    stream = ramp(10, 25)
    assert stream.duration == pytest.approx(0.4)
    assert stream.times[3] == pytest.approx(0.12)
    part = stream[2:5]
    assert part.n_frames == 3 and part.values[0, 2] == 20
    assert stream[::2].fps == 12.5 and stream[::2].n_frames == 5
    span = stream.between(0.1, 0.2)  # frames shown at 0.12 and 0.16
    assert span.values[:, 2].tolist() == [30, 40]
    with pytest.raises(ParameterError):
        stream[3]


def test_resample_interpolates_linearly_and_keeps_duration(ramp):
    stream = ramp(10, 25)
    doubled = stream.resample(50)
    assert doubled.n_frames == 20
    assert doubled.duration == pytest.approx(stream.duration)
    assert doubled.values[1, 2] == pytest.approx(5.0)  # halfway between 0 and 10
    assert doubled.values[2, 2] == pytest.approx(10.0)
    back = doubled.resample(25)
    assert back == stream


def test_at_whole_rate_resamples_to_the_nearest_whole_rate_a_fap_file_takes(ramp):
    from facelib.mpeg4 import format_fap

    stream = ramp(30, 25)
    assert stream.at_whole_rate() is stream  # already whole: untouched
    measured = stream.resample(29.97)  # a camera's measured rate
    with pytest.raises(ParameterError, match="whole frame rate"):
        format_fap(measured)
    whole = measured.at_whole_rate()
    assert whole.fps == 30.0
    assert whole.duration == pytest.approx(measured.duration, abs=1 / 30)
    assert whole == measured.resample(30)
    assert format_fap(whole).count("\n") > 30
    assert ramp(10, 12.5).at_whole_rate().fps == 12.0  # round half to even, as round()
    assert ramp(3, 0.4).at_whole_rate().fps == 1.0  # never 0 fps

def test_concat_and_equality(ramp):
    a, b = ramp(4), ramp(3)
    joined = FapStream.concat([a, b])
    assert joined.n_frames == 7
    assert joined[:4] == a and joined[4:] == b
    assert a != b
    with pytest.raises(ParameterError, match="fps"):
        FapStream.concat([a, ramp(3, 30)])


def test_high_level_fields_follow_slicing_and_concat(ramp):
    viseme = np.tile([1, 2, 32, 0], (4, 1))
    a = FapStream(25, np.zeros((4, 84)), viseme=viseme)
    joined = FapStream.concat([a, ramp(2)])
    assert joined.viseme.shape == (6, 4)
    assert joined.viseme[:4].tolist() == viseme.tolist()
    assert not joined.viseme[4:].any()
    assert joined.expression is None


def test_track_validates_weights():
    with pytest.raises(ParameterError, match=r"\[0, 1\]"):
        FapTrack(25, np.zeros((2, 84)), np.full((2, 84), 1.5))
    track = FapTrack.empty(3, fps=25).padded(5)
    assert track.n_frames == 5 and not track.weight.any()
