"""Live Link Face CSVs laid out as the iPhone app records them (issue 36): the app's column
order (``JawRight, JawLeft``, ``MouthRight, MouthLeft``), both spellings of the count column,
timecodes whose frame field counts at 60 while rows come at 30 or 60 Hz; and clear errors."""

import csv

import numpy as np
import pytest

from facelib.errors import ArkitFormatError
from facelib.export import (
    ANGLE_NAMES,
    ArkitCurves,
    arkit_names,
    import_arkit,
    read_live_link_csv,
    write_live_link_csv,
)
from facelib.mpeg4 import fap

# The header of a Live Link Face capture, written out from the app's published layout (the
# order is the app's, not facelib's table order: JawRight before JawLeft, MouthRight before
# MouthLeft).
CAPTURE_NAMES = (  # noqa: SIM905
    "EyeBlinkLeft EyeLookDownLeft EyeLookInLeft EyeLookOutLeft EyeLookUpLeft EyeSquintLeft "
    "EyeWideLeft EyeBlinkRight EyeLookDownRight EyeLookInRight EyeLookOutRight EyeLookUpRight "
    "EyeSquintRight EyeWideRight JawForward JawRight JawLeft JawOpen MouthClose MouthFunnel "
    "MouthPucker MouthRight MouthLeft MouthSmileLeft MouthSmileRight MouthFrownLeft "
    "MouthFrownRight MouthDimpleLeft MouthDimpleRight MouthStretchLeft MouthStretchRight "
    "MouthRollLower MouthRollUpper MouthShrugLower MouthShrugUpper MouthPressLeft "
    "MouthPressRight MouthLowerDownLeft MouthLowerDownRight MouthUpperUpLeft MouthUpperUpRight "
    "BrowDownLeft BrowDownRight BrowInnerUp BrowOuterUpLeft BrowOuterUpRight CheekPuff "
    "CheekSquintLeft CheekSquintRight NoseSneerLeft NoseSneerRight TongueOut HeadYaw HeadPitch "
    "HeadRoll LeftEyeYaw LeftEyePitch LeftEyeRoll RightEyeYaw RightEyePitch RightEyeRoll"
).split()

START = 20 * 3600 + 51 * 60 + 31 + 13.2 / 60  # 20:51:31:13.200, as a capture starts


def _timecode(t: float) -> str:
    """Seconds -> the app's ``HH:MM:SS:FF.mmm`` with the frame field counted at 60."""
    whole = int(t)
    frames = round((t - whole) * 60, 3)
    if frames >= 60:
        whole, frames = whole + 1, frames - 60
    h, rest = divmod(whole, 3600)
    m, s = divmod(rest, 60)
    ff = int(frames)
    return f"{h:02d}:{m:02d}:{s:02d}:{ff:02d}.{round((frames - ff) * 1000):03d}"


def _capture(rate: int, seconds: float, *, count: str = "BlendShapeCount"):
    """Rows of a capture at ``rate`` Hz: left blinks every 0.5 s (frames rising to 1 and back),
    the jaw to the right from 1.0 s to 1.5 s, the mouth to the left from 2.0 s to 2.5 s, a
    head yaw ramp. Returns (header, rows, events) with the event times in seconds."""
    n = round(seconds * rate)
    t = np.arange(n) / rate
    cols = {name: np.zeros(n) for name in CAPTURE_NAMES}
    blinks = np.arange(0.2, seconds - 0.2, 0.5)
    for b in blinks:
        cols["EyeBlinkLeft"] += np.clip(1 - np.abs(t - b) / 0.1, 0, None)
    cols["JawRight"][(t >= 1.0) & (t < 1.5)] = 0.6
    cols["MouthLeft"][(t >= 2.0) & (t < 2.5)] = 0.4
    cols["HeadYaw"] = 0.1 * t
    header = ["Timecode", count, *CAPTURE_NAMES]
    rows = [[_timecode(START + t[i]), "61", *(f"{cols[c][i]:.8f}" for c in CAPTURE_NAMES)]
            for i in range(n)]
    return header, rows, blinks


def _write(path, header, rows):
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\r\n").writerows([header, *rows])
    return path


@pytest.mark.parametrize(("rate", "count"), [(30, "BlendShapeCount"), (60, "BlendshapeCount"),
                                             (30, "BlendshapeCount")])
def test_capture_layout_gives_the_events_at_their_times(tmp_path, rate, count):
    header, rows, blinks = _capture(rate, 3.0, count=count)
    path = _write(tmp_path / "capture.csv", header, rows)
    curves = read_live_link_csv(path)
    assert curves.fps == rate and curves.n_frames == len(rows)
    names = arkit_names()
    t = np.arange(curves.n_frames) / rate
    blink = curves.weights[:, names.index("EyeBlinkLeft")]
    peaks = t[np.flatnonzero(blink > 0.99)]
    np.testing.assert_allclose(peaks, blinks, atol=0.5 / rate)
    assert not curves.weights[:, names.index("EyeBlinkRight")].any()
    jaw_right = curves.weights[:, names.index("JawRight")]
    np.testing.assert_array_equal(t[jaw_right > 0.5][[0, -1]],
                                  [1.0, 1.5 - 1 / rate])
    assert not curves.weights[:, names.index("JawLeft")].any()
    mouth_left = curves.weights[:, names.index("MouthLeft")]
    assert t[mouth_left > 0.3][0] == 2.0 and np.isclose(mouth_left.max(), 0.4)
    assert not curves.weights[:, names.index("MouthRight")].any()
    np.testing.assert_allclose(curves.angles[:, ANGLE_NAMES.index("HeadYaw")], 0.1 * t,
                               atol=1e-6)
    # and as a FapStream: the left upper lid closes at each blink, the jaw shifts once
    stream = import_arkit(path)
    assert stream.fps == rate and stream.n_frames == len(rows)
    lid = stream.values[:, fap("close_t_l_eyelid").index]
    assert np.all(lid[np.round(blinks * rate).astype(int)] > 0.5 * lid.max())
    shift = np.abs(stream.values[:, fap("shift_jaw").index])
    inside = (t >= 1.0) & (t < 1.5)
    assert shift[inside].min() > 10 * shift[~inside & (t < 2.0)].max()


def test_written_csv_is_in_the_apps_layout_and_reads_back(tmp_path):
    rng = np.random.default_rng(3)
    n = 40
    weights = rng.uniform(0, 1, (n, 52)).astype(np.float32)
    angles = rng.uniform(-0.3, 0.3, (n, 9)).astype(np.float32)
    nan = np.full(n, np.nan, np.float32)
    path = write_live_link_csv(ArkitCurves(30.0, weights, angles, nan, nan), tmp_path / "w.csv",
                               start=1.0)
    rows = list(csv.reader(path.read_text().splitlines()))
    assert rows[0] == ["Timecode", "BlendShapeCount", *CAPTURE_NAMES]
    # the frame field counts at 60: 30 Hz rows step it by 2
    assert [r[0] for r in rows[1:4]] == ["00:00:01:00.000", "00:00:01:02.000",
                                         "00:00:01:04.000"]
    assert rows[31][0] == "00:00:02:00.000"
    jaw = CAPTURE_NAMES.index("JawRight") + 2
    np.testing.assert_allclose([float(r[jaw]) for r in rows[1:]],
                               weights[:, arkit_names().index("JawRight")], atol=1e-6)
    back = read_live_link_csv(path)
    assert back.fps == 30 and back.n_frames == n
    np.testing.assert_allclose(back.weights, weights, atol=1e-6)
    np.testing.assert_allclose(back.angles, angles, atol=1e-6)


def _bad(tmp_path, header, rows):
    return _write(tmp_path / "bad.csv", header, rows)


def test_nan_missing_and_extra_columns_name_line_and_column(tmp_path):
    header, rows, _ = _capture(30, 0.5)
    rows[3][header.index("JawOpen")] = "nan"
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:5: .*column 20 \(JawOpen\)"):
        read_live_link_csv(_bad(tmp_path, header, rows))
    header, rows, _ = _capture(30, 0.5)
    gone = header.index("MouthLeft")
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:1: .*MouthLeft"):
        read_live_link_csv(_bad(tmp_path, header[:gone] + header[gone + 1:],
                                [r[:gone] + r[gone + 1:] for r in rows]))
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:1: .*column 64 \(Extra\)"):
        read_live_link_csv(_bad(tmp_path, [*header, "Extra"], [[*r, "0"] for r in rows]))
    header, rows, _ = _capture(30, 0.5)
    rows[2].append("0.5")
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:4: 64 cells"):
        read_live_link_csv(_bad(tmp_path, header, rows))
    rows[2] = rows[2][:40]
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:4: 40 cells"):
        read_live_link_csv(_bad(tmp_path, header, rows))
    header, rows, _ = _capture(30, 0.5)
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:1: .*columns 1 and 2 .*Count"):
        read_live_link_csv(_bad(tmp_path, ["Timecode", "Count", *header[2:]], rows))


def test_no_negative_zero_cells(tmp_path):
    weights = np.zeros((3, 52), np.float32)
    weights[1, 5] = -1e-9  # a solver's round-off below zero
    angles = np.full((3, 9), -2e-7, np.float32)  # a still head, a hair below zero
    angles[2, 0] = -0.25
    nan = np.full(3, np.nan, np.float32)
    text = write_live_link_csv(ArkitCurves(60.0, weights, angles, nan, nan),
                               tmp_path / "z.csv").read_text()
    assert "-0.000000" not in text
    assert ",-0.250000," in text and text.count(",0.000000") > 100
