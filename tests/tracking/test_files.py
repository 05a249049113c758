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
