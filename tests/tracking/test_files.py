"""Landmark files of other trackers: facelib CSV, generic long CSV, OpenFace 2.x, JSON, .pts."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from facelib.errors import TrackingError, TrackingWarning
from facelib.tracking.files import read_landmarks, write_landmarks_csv


def random_track(n: int = 4, k: int = 68, dim: int = 2) -> np.ndarray:
    rng = np.random.default_rng(3)
    return np.round(rng.uniform(100, 400, (n, k, dim)), 3)


def test_csv_round_trip_keeps_values_rate_and_lost_frames(tmp_path):
    data = random_track(5, 478, 3)
    data[2] = np.nan
    path = write_landmarks_csv(tmp_path / "l.csv", data, fps=29.97)
    assert path.read_text().splitlines()[2] == "frame,point,x,y,z"
    with warnings.catch_warnings():
        warnings.simplefilter("error", TrackingWarning)  # lost frames are no error
        back = read_landmarks(path)
    assert back.fps == pytest.approx(29.97) and back.layout == "mediapipe"
    np.testing.assert_allclose(back.landmarks, data, atol=1e-3, equal_nan=True)


def test_csv_of_a_long_stretch_without_a_face(tmp_path):
    """The writer formats a few hundred frames at a time: a whole batch of lost frames
    (here 300, about 10 s) is left out, and a track with no face at all is a header."""
    data = random_track(700, 68, 2)
    data[200:500] = np.nan
    back = read_landmarks(write_landmarks_csv(tmp_path / "gap.csv", data, fps=30))
    np.testing.assert_allclose(back.landmarks, data, atol=1e-3, equal_nan=True)
    empty = write_landmarks_csv(tmp_path / "none.csv", np.full((300, 68, 2), np.nan), fps=30)
    assert empty.read_text().splitlines()[-1] == "frame,point,x,y"


def test_generic_csv_with_a_missing_point_names_the_frame(tmp_path):
    rows = ["frame,point,x,y"] + [f"{f},{p},{100 + p},{200 + f}" for f in range(3)
                                  for p in range(68) if not (f == 1 and p == 30)]
    (tmp_path / "g.csv").write_text("\n".join(rows))
    with pytest.warns(TrackingWarning, match="frames 1 have missing points"):
        got = read_landmarks(tmp_path / "g.csv")
    assert got.layout == "ibug68" and got.fps is None
    assert np.isnan(got.landmarks[1]).all() and got.landmarks[2, 5].tolist() == [105, 202]


def test_bad_rows_name_file_and_line(tmp_path):
    (tmp_path / "b.csv").write_text("# fps: 25\nframe,point,x,y\n0,0,1,2\n0,1,one,2\n")
    with pytest.raises(TrackingError, match=r"b\.csv:4"):
        read_landmarks(tmp_path / "b.csv")
    (tmp_path / "c.csv").write_text("a,b\n1,2\n")
    with pytest.raises(TrackingError, match="neither"):
        read_landmarks(tmp_path / "c.csv")
    with pytest.raises(TrackingError, match="does not exist"):
        read_landmarks(tmp_path / "missing.csv")


def test_openface_csv(tmp_path):
    data = random_track(4)
    header = (["frame", " face_id", " timestamp", " confidence", " success"]
              + [f" x_{i}" for i in range(68)] + [f" y_{i}" for i in range(68)]
              + [f" X_{i}" for i in range(68)])
    lines = [",".join(header)]
    for f in range(4):
        success = 0 if f == 2 else 1
        cells = [f + 1, 0, f / 30, 0.98, success, *data[f, :, 0], *data[f, :, 1],
                 *np.zeros(68)]
        lines.append(", ".join(str(c) for c in cells))
    (tmp_path / "of.csv").write_text("\n".join(lines) + "\n")
    got = read_landmarks(tmp_path / "of.csv")
    assert got.layout == "ibug68" and got.fps == pytest.approx(30)
    np.testing.assert_allclose(got.landmarks[[0, 1, 3]], data[[0, 1, 3]])
    assert np.isnan(got.landmarks[2]).all()


def test_openface_blank_and_bad_rows(tmp_path):
    """A row of empty cells is skipped; a row that is not numbers is named by its line."""
    lines = openface_lines(random_track(5), 30, {})
    blank = ", ".join([""] * len(lines[0].split(",")))
    (tmp_path / "blank.csv").write_text("\n".join([*lines[:3], blank, *lines[3:]]) + "\n")
    assert len(read_landmarks(tmp_path / "blank.csv").landmarks) == 5
    cells = lines[4].split(", ")
    cells[10] = "n/a"
    (tmp_path / "bad.csv").write_text("\n".join([*lines[:4], ", ".join(cells)]) + "\n")
    with pytest.raises(TrackingError, match=r"bad.csv:5: bad OpenFace row"):
        read_landmarks(tmp_path / "bad.csv")


def test_openface_frames_and_faces_must_be_whole_numbers(tmp_path):
    lines = openface_lines(random_track(4), 30, {})
    for bad in ("nan", "inf", "1e20"):
        cells = lines[3].split(", ")
        cells[0] = bad
        (tmp_path / "of.csv").write_text("\n".join([*lines[:3], ", ".join(cells), lines[4]]))
        with pytest.raises(TrackingError, match=r"of.csv:4: bad OpenFace row: its frame"):
            read_landmarks(tmp_path / "of.csv")


def test_openface_without_a_frame_column_counts_the_first_face_rows(tmp_path):
    """Without ``frame``, each row of the lowest face id is the next frame (the other
    faces' rows in between are no frames of it)."""
    data = random_track(60)
    lines = openface_lines(data, 30, {f: [0, 1] for f in range(60)})
    cut = [", ".join(line.split(", ")[1:]) for line in lines]  # drop the frame column
    (tmp_path / "of.csv").write_text("\n".join(cut))
    got = read_landmarks(tmp_path / "of.csv")
    assert len(got.landmarks) == 60 and got.fps == 30
    np.testing.assert_allclose(got.landmarks, data)


def test_openface_repeated_frames_keep_their_last_row(tmp_path):
    """A frame written twice counts once, by its last row, for the points and the rate."""
    data = random_track(31)
    lines = openface_lines(data, 30, {})
    again = lines[1].split(", ")
    again[2] = "0.100"  # frame 1 again, stamped as frame 4
    (tmp_path / "of.csv").write_text("\n".join([lines[0], lines[1], ", ".join(again),
                                                *lines[2:]]))
    got = read_landmarks(tmp_path / "of.csv")
    assert len(got.landmarks) == 31 and got.fps == pytest.approx(30 / 0.9)  # 30 frames in 0.9 s


def test_json_lists_and_pts(tmp_path):
    data = random_track(3)
    frames = [data[0].tolist(), None, data[2].tolist()]
    (tmp_path / "d.json").write_text(json.dumps({"fps": 25, "frames": frames}))
    got = read_landmarks(tmp_path / "d.json")
    assert got.fps == 25 and np.isnan(got.landmarks[1]).all()
    np.testing.assert_allclose(got.landmarks[2], data[2])
    folder = tmp_path / "pts"
    folder.mkdir()
    for i in range(2):
        body = "\n".join(f"{x + 1} {y + 1}" for x, y in data[i])
        (folder / f"frame_{i:03d}.pts").write_text(
            f"version: 1\nn_points: 68\n{{\n{body}\n}}\n")
    got = read_landmarks(folder)
    np.testing.assert_allclose(got.landmarks, data[:2])  # 1-based .pts -> 0-based pixels
    (tmp_path / "bad.pts").write_text("version: 1\nn_points: 68\n{\n1 2\n}\n")
    with pytest.raises(TrackingError, match="1 points where n_points says 68"):
        read_landmarks(tmp_path / "bad.pts")
    (tmp_path / "e.json").write_text(json.dumps([[[1, 2, 3, 4]]]))
    with pytest.raises(TrackingError, match="frame 0 has shape"):
        read_landmarks(tmp_path / "e.json")


def openface_lines(data: np.ndarray, fps: float, faces: dict[int, list[int]]) -> list[str]:
    """OpenFace 2.x rows as FeatureExtraction writes them: ", " separators, timestamps
    rounded to the millisecond, one row per face id (``faces``: frame index -> ids)."""
    header = (["frame", " face_id", " timestamp", " confidence", " success"]
              + [f" x_{i}" for i in range(68)] + [f" y_{i}" for i in range(68)])
    lines = [",".join(header)]
    for f in range(len(data)):
        for face in faces.get(f, [0]):
            cells = [f + 1, face, f"{f / fps:.3f}", 0.98, 1, *data[f, :, 0] + 50 * face,
                     *data[f, :, 1]]
            lines.append(", ".join(str(c) for c in cells))
    return lines


@pytest.mark.parametrize("fps", [24.0, 30.0, 60.0, 120.0])
def test_openface_rate_from_rounded_timestamps(tmp_path, fps):
    """The rate comes from the whole track's timestamps, which OpenFace rounds to the
    millisecond (the median step once read 30 as 30.3 and 120 as 125)."""
    (tmp_path / "of.csv").write_text("\n".join(openface_lines(random_track(300), fps, {})))
    assert read_landmarks(tmp_path / "of.csv").fps == fps


def test_openface_rows_are_placed_by_frame_and_face(tmp_path):
    """Two people: the lowest face id is read; frames without its row are lost, not closed
    up; a blank last line is no row; a file of face 1 alone is read."""
    data = random_track(40)
    faces = {f: ([1] if 20 <= f < 30 else [1, 0]) for f in range(40)}
    (tmp_path / "two.csv").write_text("\n".join(openface_lines(data, 30, faces)) + "\n\n")
    got = read_landmarks(tmp_path / "two.csv")
    assert len(got.landmarks) == 40 and got.fps == 30
    assert np.isnan(got.landmarks[20:30]).all() and np.isfinite(got.landmarks[30:]).all()
    np.testing.assert_allclose(got.landmarks[35], data[35])
    only = {f: [1] for f in range(40)}
    (tmp_path / "one.csv").write_text("\n".join(openface_lines(data, 30, only)))
    np.testing.assert_allclose(read_landmarks(tmp_path / "one.csv").landmarks[:, :, 0],
                               data[:, :, 0] + 50)


def test_pts_folder_in_frame_number_order(tmp_path):
    """frame_9.pts comes before frame_10.pts, and a missing number is a lost frame."""
    data = random_track(12)
    for i in range(12):
        if i != 5:
            body = "\n".join(f"{x + 1} {y + 1}" for x, y in data[i])
            (tmp_path / f"frame_{i + 1}.pts").write_text(
                f"version: 1\nn_points: 68\n{{\n{body}\n}}\n")
    got = read_landmarks(tmp_path)
    assert len(got.landmarks) == 12 and np.isnan(got.landmarks[5]).all()
    keep = [i for i in range(12) if i != 5]
    np.testing.assert_allclose(got.landmarks[keep], data[keep])


def test_rates_bom_empty_and_normalised_files(tmp_path):
    rows = ["frame,point,x,y"] + [f"{f},{p},{100 + p},{200 + f}" for f in range(3)
                                  for p in range(68)]
    (tmp_path / "ntsc.csv").write_text("\ufeff# fps: 30000/1001\n" + "\n".join(rows))
    assert read_landmarks(tmp_path / "ntsc.csv").fps == pytest.approx(30000 / 1001)
    (tmp_path / "bad.csv").write_text("# source: a tracker\n# fps: 1e\n" + "\n".join(rows))
    with pytest.raises(TrackingError, match=r"bad.csv:2: bad frame rate '1e'"):
        read_landmarks(tmp_path / "bad.csv")
    (tmp_path / "empty.csv").write_text("frame,point,x,y\n")
    with pytest.raises(TrackingError, match="no landmark rows"):
        read_landmarks(tmp_path / "empty.csv")
    frames = [(random_track(1)[0] / 640).tolist(), []]
    (tmp_path / "norm.json").write_text(json.dumps({"fps": 25, "frames": frames}))
    with pytest.raises(TrackingError, match="look normalised"):
        read_landmarks(tmp_path / "norm.json")
    frames = [random_track(1)[0].tolist(), [], random_track(1)[0].tolist()]
    (tmp_path / "gap.json").write_text(json.dumps(frames))
    assert np.isnan(read_landmarks(tmp_path / "gap.json").landmarks[1]).all()


def test_points_numbered_from_one(tmp_path):
    """iBUG's figure numbers the 68 points 1-68: with no point 0 they are shifted."""
    rows = ["frame,point,x,y"] + [f"{f},{p + 1},{100 + p},{200 + f}" for f in range(2)
                                  for p in range(68)]
    (tmp_path / "one.csv").write_text("\n".join(rows))
    got = read_landmarks(tmp_path / "one.csv")
    assert got.layout == "ibug68" and got.landmarks[1, 0].tolist() == [100, 201]
