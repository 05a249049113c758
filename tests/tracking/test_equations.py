"""Eq. 4.12-4.17 of the first seed on synthetic landmark tracks with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine.rigid import rotation_matrices
from facelib.errors import ParameterError, TrackingError, TrackingWarning
from facelib.mpeg4 import ANGLE_UNIT
from facelib.tracking.faps import fill_gaps, measure_faps
from facelib.tracking.layouts import feature_point_layout, landmark_layout, layout_names
from facelib.tracking.relations import apply_relations, relations
from facelib.tracking.userfapu import complete_points, user_fapu

# the thesis's tracked points (section 4.3.1), image pixels (column, row)
THESIS = {"3.1": (360, 205), "3.3": (360, 222), "3.2": (280, 205), "3.4": (280, 222),
          "8.1": (320, 305), "8.2": (320, 326), "8.3": (356, 315), "8.4": (284, 315),
          "9.3": (320, 272), "2.1": (320, 380), "4.1": (340, 188), "4.2": (300, 188)}
IDS = tuple(THESIS)
BASE = np.array([THESIS[k] for k in IDS], np.float64)


def track(n: int = 6) -> np.ndarray:
    return np.repeat(BASE[None], n, axis=0)


def faps(points: np.ndarray, **options):
    return measure_faps(points, fps=25, layout=feature_point_layout(IDS), smooth=False,
                        **options)


def col(stream, fap_id: int) -> np.ndarray:
    return stream.values[:, fap_id - 1]


def test_midpoints_of_eq_4_12_to_4_15():
    pts = {k: np.array(v, float) for k, v in THESIS.items()}
    full = complete_points(pts)
    np.testing.assert_allclose(full["3.5"], [360, (205 + 222) / 2])   # 4.12
    np.testing.assert_allclose(full["3.6"], [280, (205 + 222) / 2])   # 4.13
    np.testing.assert_allclose(full["2.2"], [320, (305 + 326) / 2])   # 4.14
    np.testing.assert_allclose(full["9.15"], [320, (272 + 315.5) / 2])  # 4.15 uses 4.14's 2.2
    tracked = {**pts, "2.2": np.array([321.0, 318.0])}
    assert complete_points(tracked)["2.2"].tolist() == [321.0, 318.0]  # tracked: kept


def test_user_fapu_eq_4_1_to_4_5():
    fapu = user_fapu({k: np.array(v, float) for k, v in THESIS.items()})
    assert fapu["IRISD"] == pytest.approx(17 / 1024)
    assert fapu["ES"] == pytest.approx(80 / 1024)
    assert fapu["MW"] == pytest.approx(72 / 1024)
    mid_eye, nose_base = 213.5, (272 + 315.5) / 2
    assert fapu["ENS"] == pytest.approx(abs(mid_eye - nose_base) / 1024)
    assert fapu["MNS"] == pytest.approx(abs(nose_base - 315.5) / 1024)
    assert user_fapu({k: np.array(v, float) for k, v in THESIS.items()},
                     {"MNS": 0.02})["MNS"] == 0.02
    with pytest.raises(TrackingError, match=r"8\.3"):
        user_fapu({k: np.array(v, float) for k, v in THESIS.items() if k != "8.3"})


@pytest.mark.parametrize("shift", [(13.0, -7.0), (-40.0, 25.5)])
def test_pure_translation_changes_no_fap(shift):
    points = track()
    points[2:] += shift
    stream = faps(points).stream
    assert np.abs(stream.values).max() < 1e-6


def test_corner_lift_of_300_mns_comes_back():
    points = track()
    fapu = faps(points).fapu
    points[3, IDS.index("8.3"), 1] -= 300 * fapu["MNS"]  # rows grow downward: up is minus
    points[3:] += (5.0, 3.0)                             # and the head drifts meanwhile
    stream = faps(points).stream
    assert col(stream, 59)[3] == pytest.approx(300, rel=0.05)
    assert abs(col(stream, 53)[3]) < 1e-6
    assert col(stream, 41)[3] == pytest.approx(0.25 * 300, rel=0.05)  # eq. 4.17 cheek
    assert col(stream, 12)[3] == pytest.approx(300, rel=0.05)         # inner corner


def test_signs_follow_the_fap_table():
    points = track(2)
    fapu = faps(points).fapu
    moves = {"2.1": (0, 50), "8.3": (20, 0), "8.4": (-20, 0), "4.1": (0, -10), "3.1": (0, 6)}
    for fp, delta in moves.items():
        points[1, IDS.index(fp)] += delta
    v = faps(points).stream.values[1]
    assert v[2] == pytest.approx(50 / fapu["MNS"])       # open_jaw: chin down
    assert v[52] == pytest.approx(20 / fapu["MW"])       # stretch_l_cornerlip_o: face's left
    assert v[53] == pytest.approx(20 / fapu["MW"])       # stretch_r: face's right (image left)
    assert v[30] == pytest.approx(10 / fapu["ENS"])      # raise_l_i_eyebrow: up
    assert v[18] == pytest.approx(6 / fapu["IRISD"])     # close_t_l_eyelid: down
    assert v[13] == pytest.approx(0.5 * v[2])            # thrust_jaw = 0.5 open_jaw (4.17)


def head_3d() -> tuple[tuple[str, ...], np.ndarray]:
    """A 3-D head: the thesis points plus nose and eye-corner points with depth."""
    extra = {"3.7": (392, 214, 20), "3.11": (338, 214, 15), "3.8": (302, 214, 15),
             "3.12": (248, 214, 20), "9.1": (338, 282, 10), "9.2": (302, 282, 10)}
    ids = IDS + tuple(extra)
    pts = np.array([(*THESIS[k], 0.0) for k in IDS] + list(extra.values()), float)
    pts[IDS.index("9.3"), 2] = -30.0  # image depth: the nose tip is nearest the camera
    return ids, pts


def test_head_rotation_is_pose_not_expression():
    ids, pts = head_3d()
    stable = ("9.3", "3.7", "3.11", "3.8", "3.12", "9.1", "9.2")
    layout = feature_point_layout(ids, stable)
    yaw = np.radians([0, 0, 5, 10, 15])
    pitch = np.radians([0, 0, -4, 3, 8])
    face = pts * [1, -1, -1]                      # image -> face frame
    centre = face.mean(axis=0)
    rot = rotation_matrices(pitch, yaw, np.zeros(5))
    moved = np.einsum("nij,kj->nki", rot, face - centre) + centre
    result = measure_faps(moved * [1, -1, -1], fps=25, layout=layout, smooth=False)
    v = result.stream.values
    np.testing.assert_allclose(v[:, 48] * ANGLE_UNIT, yaw, atol=1e-6)    # head_yaw
    np.testing.assert_allclose(v[:, 47] * ANGLE_UNIT, pitch, atol=1e-6)  # head_pitch
    for fap_id in (3, 19, 51, 52, 53, 54, 59, 60, 31):
        assert np.abs(v[:, fap_id - 1]).max() < 1e-3, fap_id


def test_roll_in_2d():
    layout = feature_point_layout(IDS, ("9.3", "3.1", "3.2", "3.3", "3.4"))
    angle = np.radians(12)
    centre = BASE.mean(axis=0)
    c, s = np.cos(angle), np.sin(angle)
    # head_roll positive tips the top to the face's right = the image's left
    rot = np.array([[c, s], [-s, c]])
    rolled = (BASE - centre) @ rot.T + centre
    v = measure_faps(np.stack([BASE, BASE, rolled]), fps=25, layout=layout,
                     smooth=False).stream.values
    assert v[2, 49] * ANGLE_UNIT == pytest.approx(angle, abs=1e-6)
    assert np.abs(v[2, [2, 52, 58]]).max() < 1e-3


@pytest.mark.parametrize("tilt", [25.0, 90.0, -140.0])
def test_a_tilted_camera_changes_no_fap(tilt):
    """The whole track, neutral included, turned in the image (a camera on its side): the
    FAPs are measured about the face's own axes and come out as from the upright camera,
    head pitch and yaw included."""
    ids, pts = head_3d()
    layout = feature_point_layout(ids, ("9.3", "3.7", "3.11", "3.8", "3.12", "9.1", "9.2"))
    face = pts * [1, -1, -1]
    centre = face.mean(axis=0)
    rot = rotation_matrices(np.radians([0, 0, -4, 3, 8]), np.radians([0, 0, 5, 10, 15]),
                            np.zeros(5))
    frames = np.einsum("nij,kj->nki", rot, face - centre) + centre
    frames[3:, ids.index("2.1"), 1] -= 12.0  # the jaw opens
    frames[4, ids.index("8.3"), 1] += 4.0    # a lip corner rises
    upright = frames * [1, -1, -1]
    c, s = np.cos(np.radians(tilt)), np.sin(np.radians(tilt))
    turned = upright.copy()
    turned[..., :2] = (upright[..., :2] - [320, 240]) @ np.array([[c, -s], [s, c]]).T + [400, 300]
    expected = measure_faps(upright, fps=25, layout=layout, smooth=False)
    found = measure_faps(turned, fps=25, layout=layout, smooth=False)
    for name, value in expected.fapu.items():
        assert found.fapu[name] == pytest.approx(value, rel=1e-9), name
    np.testing.assert_allclose(found.stream.values, expected.stream.values, atol=0.02)
    assert np.abs(expected.stream.values[3:, 2]).min() > 100  # the jaw moved


def test_pucker_state_replaces_the_inner_lip_relation():
    values = np.zeros((3, 84))
    mask = np.zeros((3, 84), bool)
    values[:, 50], mask[:, 50] = 100.0, True   # lower_t_midlip_o
    values[:, 51], mask[:, 51] = 40.0, True    # raise_b_midlip_o
    out, out_mask = apply_relations(values, mask,
                                    frame_states={"pucker": np.array([False, True, True])})
    assert out[0, 3] == 100.0 and out[1, 3] == -150.0       # FAP 4: 1 -> -1.5
    assert out[0, 4] == 40.0 and out[2, 4] == 20.0          # FAP 5: 1 -> 0.5
    assert out[1, 16] == 200.0 and out[1, 15] == 20.0       # push_t_lip 2.0, push_b_lip 0.5
    assert not out_mask[0, 16]
    assert {r.state for r in relations()} == {"", "pucker"}


def test_measured_faps_are_not_overwritten_by_relations():
    values = np.zeros((1, 84))
    mask = np.zeros((1, 84), bool)
    values[0, [3, 50]] = (7.0, 100.0)
    mask[0, [3, 50]] = True
    out, _ = apply_relations(values, mask)
    assert out[0, 3] == 7.0


def test_lost_frames_are_interpolated_and_named():
    points = track(8)
    points[:, IDS.index("2.1"), 1] += np.arange(8) * 2.0
    points[3:5] = np.nan
    with pytest.warns(TrackingWarning, match="frames 3-4 of 8"):
        stream = faps(points).stream
    jaw = col(stream, 3)
    assert jaw[4] == pytest.approx((jaw[2] + jaw[5]) / 2 + (jaw[5] - jaw[2]) / 6, rel=1e-6)
    with pytest.raises(TrackingError, match="no face in any"):
        fill_gaps(np.full((4, 3, 2), np.nan))


def test_the_neutral_is_made_of_frames_with_a_face():
    """By default the neutral is the first frame with a face; a span keeps its frames with
    a face; a span without one is refused, named."""
    points = track(8)
    points[:, IDS.index("2.1"), 1] += np.arange(8) * 2.0  # the jaw opens from frame 0
    lost = points.copy()
    lost[:3] = np.nan
    with pytest.warns(TrackingWarning, match="the neutral is frame 3, the first with a face"):
        first = faps(lost).stream.values
    np.testing.assert_allclose(first[3:], faps(points[3:]).stream.values, atol=1e-9)
    with pytest.warns(TrackingWarning, match="frames 0-2 of 8"):
        span = faps(lost, neutral=(0, 5)).stream.values
    np.testing.assert_allclose(span[3:], faps(points[3:], neutral=(0, 2)).stream.values,
                               atol=1e-9)
    with pytest.warns(TrackingWarning), pytest.raises(TrackingError,
                                                      match="no face in the neutral frames 0-2"):
        faps(lost, neutral=(0, 3))
    with pytest.raises(ParameterError, match="empty span"):
        faps(points, neutral=(4, 4))


def test_bad_shapes_name_the_problem():
    with pytest.raises(TrackingError, match="shape"):
        measure_faps(np.zeros((4, 12)), fps=25, layout=feature_point_layout(IDS))
    with pytest.raises(TrackingError, match="478"):
        measure_faps(np.zeros((4, 70, 3)), fps=25, layout="mediapipe")


def test_packaged_layouts():
    assert set(layout_names()) == {"mediapipe", "ibug68"}
    mp = landmark_layout("mediapipe")
    assert mp.weights.shape == (len(mp.feature_points), 478)
    np.testing.assert_allclose(mp.weights.sum(axis=1), 1.0)
    assert "3.5" in mp.feature_points
    assert "3.5" not in landmark_layout("mediapipe", 468).feature_points
    ibug = landmark_layout("ibug68")
    assert ibug.n_points == 68 and len(ibug.stable) >= 4
    assert ibug.weights[ibug.index("3.1"), [43, 44]].tolist() == [0.5, 0.5]
