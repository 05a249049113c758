"""ARKit curves: Live Link Face's CSV layout, the bounded fit and its residual, and the round
trip FapStream -> ARKit CSV -> FapStream."""

import csv
import re
from pathlib import Path

import numpy as np
import pytest

import facelib
from facelib import FapStream
from facelib.engine import default_face
from facelib.errors import ArkitFormatError, FaceModelError
from facelib.export import (
    ANGLE_NAMES,
    arkit_names,
    export_arkit,
    from_arkit,
    import_arkit,
    live_link_names,
    read_arkit_json,
    read_live_link_csv,
    to_arkit,
    write_arkit_json,
    write_live_link_csv,
)
from facelib.mpeg4 import fap

HELLO = Path(__file__).parents[2] / "examples" / "hello" / "hello.fdl"


@pytest.fixture(scope="module")
def hello():
    return facelib.run_fdl(HELLO)


@pytest.fixture(scope="module")
def hello_csv(hello, tmp_path_factory):
    out = tmp_path_factory.mktemp("arkit") / "hello.csv"
    curves = export_arkit(hello, out)
    return out, curves


def test_csv_has_live_link_faces_layout(hello_csv, hello):
    path, _ = hello_csv
    rows = list(csv.reader(path.read_text().splitlines()))
    assert rows[0][:2] == ["Timecode", "BlendShapeCount"]
    assert rows[0][2:54] == list(live_link_names()) and len(arkit_names()) == 52
    assert rows[0][17:19] == ["JawRight", "JawLeft"]  # the app's order, not the table's
    assert rows[0][54:] == ["HeadYaw", "HeadPitch", "HeadRoll", "LeftEyeYaw", "LeftEyePitch",
                            "LeftEyeRoll", "RightEyeYaw", "RightEyePitch", "RightEyeRoll"]
    assert rows[0][2] == "EyeBlinkLeft" and rows[0][19] == "JawOpen" and rows[0][53] == "TongueOut"
    assert len(rows) == hello.faps.n_frames + 1
    assert all(len(r) == 63 and r[1] == "61" for r in rows[1:])
    assert all(re.fullmatch(r"\d\d:\d\d:\d\d:\d\d\.\d\d\d", r[0]) for r in rows[1:])
    # 25 fps rows, the frame field counted at 60 as the app does
    assert rows[26][0] == "00:00:01:00.000" and rows[27][0] == "00:00:01:02.400"
    weights = np.array([[float(v) for v in r[2:54]] for r in rows[1:]])
    assert weights.min() >= 0 and weights.max() <= 1
    assert weights[:, live_link_names().index("JawOpen")].max() > 0.1  # speech opens the jaw


def test_fit_reports_its_residual(hello_csv):
    _, curves = hello_csv
    moving = curves.relative > 0
    assert moving.sum() > 100
    assert np.all(curves.relative[moving] < 1.0)  # better than no fit at all
    assert np.all(curves.residual >= 0) and curves.residual.max() < 0.005  # metres


def test_round_trip_keeps_mouth_brow_and_lid_curves(hello_csv, hello):
    path, _ = hello_csv
    back = import_arkit(path)
    assert back.fps == hello.faps.fps and back.n_frames == hello.faps.n_frames
    face = default_face()
    fp = face.feature_points
    before, after = face.deform(hello.faps), face.deform(back)

    def curves(p):
        y = lambda k: p[:, fp[k], 1]  # noqa: E731
        x = lambda k: p[:, fp[k], 0]  # noqa: E731
        return {"mouth opening": y("8.1") - y("8.2"), "mouth width": x("8.3") - x("8.4"),
                "left corner height": y("8.3"), "left inner brow": y("4.1"),
                "right inner brow": y("4.2"), "left outer brow": y("4.5"),
                "left lids": y("3.1") - y("3.3"), "right lids": y("3.2") - y("3.4")}

    a, b = curves(before), curves(after)
    for name in a:
        assert np.ptp(a[name]) > 1e-3, name  # the curve moves by over a millimetre
        r = np.corrcoef(a[name], b[name])[0, 1]
        assert r >= 0.9, f"{name}: correlation {r:.3f}"
    # the FAP curves themselves: jaw, brows, upper lids
    # (issue 14's refitted library moves the inner brows little in the hello demo, so that
    # curve is small and its round trip noisier: 0.75 there)
    for name, least in (("open_jaw", 0.9), ("raise_l_i_eyebrow", 0.75),
                        ("raise_r_o_eyebrow", 0.9), ("close_t_l_eyelid", 0.9)):
        j = fap(name).index
        assert np.corrcoef(hello.faps.values[:, j], back.values[:, j])[0, 1] >= least, name
    # head and eye angles go through the extra columns (6 decimals of a radian)
    for name in ("head_yaw", "head_pitch", "yaw_l_eyeball", "pitch_r_eyeball"):
        j = fap(name).index
        np.testing.assert_allclose(back.values[:, j], hello.faps.values[:, j], atol=0.2)


def test_still_face_gives_zero_weights_and_eye_look_from_angles():
    values = np.zeros((2, 84), np.float32)
    values[1, fap("yaw_l_eyeball").index] = np.radians(15) / 1e-5  # half of the full 30 deg
    values[1, fap("pitch_r_eyeball").index] = -np.radians(25) / 1e-5  # up, full
    curves = to_arkit(FapStream(25, values))
    names = arkit_names()
    assert not curves.weights[0].any() and curves.relative[0] == 0
    assert curves.weights[1, names.index("EyeLookOutLeft")] == pytest.approx(0.5, abs=1e-4)
    assert curves.weights[1, names.index("EyeLookUpRight")] == pytest.approx(1.0, abs=1e-4)
    assert curves.angles[1, ANGLE_NAMES.index("LeftEyeYaw")] == pytest.approx(np.radians(15))


def test_json_round_trip_and_resampled_capture(tmp_path):
    rng = np.random.default_rng(7)
    weights = rng.uniform(0, 1, (10, 52)).astype(np.float32)
    angles = rng.uniform(-0.3, 0.3, (10, 9)).astype(np.float32)
    from facelib.export import ArkitCurves

    nan = np.full(10, np.nan, np.float32)
    curves = ArkitCurves(60.0, weights, angles, nan, nan)
    back = read_arkit_json(write_arkit_json(curves, tmp_path / "c.json"))
    np.testing.assert_allclose(back.weights, weights, atol=1e-6)
    path = write_live_link_csv(curves, tmp_path / "c.csv", start=3600 + 0.9)
    lines = path.read_text().splitlines()
    assert lines[1].startswith("01:00:00:54.000,61,")
    del lines[4]  # a dropped frame: the reader interpolates it back onto the 60 fps grid
    path.write_text("\n".join(lines) + "\n")
    read = read_live_link_csv(path)
    assert read.fps == 60 and read.n_frames == 10
    np.testing.assert_allclose(read.weights[3], (weights[2] + weights[4]) / 2, atol=1e-5)
    np.testing.assert_allclose(read.angles[5], angles[5], atol=1e-5)
    stream = from_arkit(read)
    assert stream.fps == 60 and np.isfinite(stream.values).all()


def test_bad_files_and_faces(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("Timecode,BlendShapeCount,Foo\n")
    with pytest.raises(ArkitFormatError, match="Live Link Face"):
        read_live_link_csv(bad)
    rows = ["Timecode,BlendShapeCount," + ",".join((*arkit_names(), *ANGLE_NAMES)),
            "00:00:00:00.000,61," + ",".join(["0"] * 61), "00:00:00:01.000,61,x" + ",0" * 60]
    bad.write_text("\n".join(rows) + "\n")
    with pytest.raises(ArkitFormatError, match=r"bad\.csv:3"):
        read_live_link_csv(bad)
    face = default_face()
    other = type(face).build(
        vertices=face.vertices * 1.1, triangles=face.triangles, vertex_colors=face.vertex_colors,
        parts={k: p.vertex_ids for k, p in face.parts.items()},
        feature_points=face.feature_points, regions=face.regions, pivots=face.pivots,
        neck=(np.zeros(3), np.array([0.0, 1.0, 0.0]), 0.04))
    with pytest.raises(FaceModelError, match="default head"):
        to_arkit(FapStream.zeros(2, fps=25), face=other)


def test_tongue_out_follows_the_tongue_tip_and_comes_back():
    """TongueOut moves no skin, so it is read from the tongue: 0 with the tip behind the
    teeth (DD), most of the way out on a /th/, and an import puts the tip back there."""
    from facelib.visemes import viseme_id, viseme_targets

    targets = viseme_targets()
    frames = np.stack([np.zeros(84, np.float32), targets[viseme_id("DD")],
                       targets[viseme_id("TH")], 0.8 * targets[viseme_id("TH")]])
    stream = FapStream(25, frames)
    curves = to_arkit(stream)
    out = curves.weights[:, arkit_names().index("TongueOut")]
    assert out[0] == 0 and out[1] == 0
    assert 0.5 < out[2] <= 1 and 0 < out[3] < out[2]
    face = default_face()
    tip = face.feature_points["6.1"]
    back = face.deform(from_arkit(curves))[:, tip, 2]
    sent = face.deform(stream)[:, tip, 2]
    # within 2.5 mm: the jaw, which carries the tongue, comes back from the lossy ARKit fit
    np.testing.assert_allclose(back[2:], sent[2:], atol=2.5e-3)


def test_round_trip_carries_the_outer_lip_faps(hello_csv, hello):
    """Issue 36: the outer-lip FAPs came back at correlation 0.17-0.79 (the ARKit shapes span
    under a third of each lip FAP's motion); with the learned correction of the import
    (``tools/build_arkit_correction.py``, trained on the other examples, not on hello) the
    outer-lip FAPs with real motion come back at 0.9 or more."""
    back = import_arkit(hello_csv[0])
    values = hello.faps.values
    for number in (51, 52, 55, 56, 57, 58, 4, 5, 10, 11):
        r = np.corrcoef(values[:, number - 1], back.values[:, number - 1])[0, 1]
        assert r >= 0.9, f"FAP {number} {fap(number).name}: correlation {r:.2f}"
    # a still face stays still: the correction has no constant term
    zeros = from_arkit(to_arkit(FapStream.zeros(3, fps=25)))
    assert not np.any(zeros.values)


def test_residual_per_region(hello):
    residuals = {r.region: r for r in facelib.arkit_residuals(hello)}
    assert {"upper_lip", "lower_lip", "jaw", "brow_l", "upper_lid_r", "tongue_tip"} <= set(
        residuals)
    assert not any(k.startswith("field_") for k in residuals)
    for name in ("upper_lip", "lower_lip", "jaw"):
        r = residuals[name]
        assert r.motion_m > 3e-3 and r.residual_m < 0.5e-3 and r.relative < 0.1, name
    # the tongue is carried only as TongueOut: most of its motion is lost, and it says so
    assert residuals["tongue_tip"].relative > 0.3
    assert np.isnan(residuals["ear_top_l"].relative)  # no motion without the head turn
