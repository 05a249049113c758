"""Landmark files cannot size memory by their own numbers: a frame number, a gap between
frames or a point number is bounded by what the file holds, and is refused with an error
naming the file, the line (or the .pts file) and the value."""

from __future__ import annotations

import pytest
from test_files import openface_lines, random_track

from facelib.errors import TrackingError
from facelib.tracking import files
from facelib.tracking.files import read_landmarks


def _long_csv(tmp_path, rows: list[str]):  # type: ignore[no-untyped-def]
    path = tmp_path / "l.csv"
    path.write_text("# fps: 25\nframe,point,x,y\n" + "\n".join(rows) + "\n")
    return path


@pytest.mark.parametrize(("frame", "shown"), [
    ("1000000000000", "1000000000000"),  # asked for 14.6 TiB
    ("1e20", r"1e\+20"),                   # overflowed int64
    ("1e300", r"1e\+300"),
    ("inf", "inf"),
    ("9007199254740993", "9007199254740992"),  # past 2^53: as the float it reads as
])
def test_a_huge_frame_number_in_a_long_csv(tmp_path, frame, shown):
    path = _long_csv(tmp_path, ["0,0,100,200", "0,1,110,210", f"{frame},0,100,200",
                                f"{frame},1,110,210"])
    with pytest.raises(TrackingError, match=rf"l\.csv:5: .*frame {shown}") as info:
        read_landmarks(path)
    assert info.value.line == 5


def test_a_huge_point_number_in_a_long_csv(tmp_path):
    path = _long_csv(tmp_path, ["0,0,100,200", "0,1000000000,110,210"])
    with pytest.raises(TrackingError, match=r"l\.csv:4: point 1000000000"):
        read_landmarks(path)


def test_gaps_are_bounded_by_the_frames_present(tmp_path, monkeypatch):
    """A lost stretch is fine up to 16 frames for every frame the file holds plus a fixed
    allowance of lost coordinates; past that the frame after the gap is named."""
    monkeypatch.setattr(files, "MAX_LOST_VALUES", 4 * 1000)  # 1000 lost frames of 2 2-D points
    rows = [f"{f},{p},{100 + p},{200 + f}" for f in (0, 1, 2) for p in (0, 1)]
    ok = _long_csv(tmp_path, [*rows, "1040,0,100,200", "1040,1,110,210"])  # 1041 <= 4*16+1000
    assert len(read_landmarks(ok).landmarks) == 1041
    bad = _long_csv(tmp_path, [*rows, "1070,0,100,200", "1070,1,110,210"])  # 1071 > 1064
    with pytest.raises(TrackingError, match=r"l\.csv:9: frame 1070 comes 1068 frames after "
                                            r"frame 2") as info:
        read_landmarks(bad)
    assert "4 frames" in info.value.message and "1064" in info.value.message


def test_openface_frame_gaps(tmp_path):
    lines = openface_lines(random_track(3), 30, {})
    cells = lines[3].split(", ")
    cells[0] = "1000000000000"
    (tmp_path / "of.csv").write_text("\n".join([*lines[:3], ", ".join(cells)]) + "\n")
    with pytest.raises(TrackingError, match=r"of\.csv:4: frame 1000000000000 comes"):
        read_landmarks(tmp_path / "of.csv")
    cells[0] = "-1000000000000"  # the outlier may come first in time, too
    (tmp_path / "of.csv").write_text("\n".join([*lines[:3], ", ".join(cells)]) + "\n")
    with pytest.raises(TrackingError, match=r"of\.csv:2: frame 1 comes"):
        read_landmarks(tmp_path / "of.csv")


def test_deep_json_is_an_error_not_a_crash(tmp_path):
    (tmp_path / "deep.json").write_text("[" * 200_000 + "]" * 200_000)
    with pytest.raises(TrackingError, match=r"deep\.json: .*nested"):
        read_landmarks(tmp_path / "deep.json")
    (tmp_path / "deep2.json").write_text('{"frames": [' + "[" * 40 + "1" + "]" * 40 + "]}")
    with pytest.raises(TrackingError, match=r"deep2\.json: frame 0"):
        read_landmarks(tmp_path / "deep2.json")


def test_pts_folders_with_huge_gaps(tmp_path):
    data = random_track(2)
    for number in (1, 10**12):
        body = "\n".join(f"{x + 1} {y + 1}" for x, y in data[0])
        (tmp_path / f"frame_{number}.pts").write_text(
            f"version: 1\nn_points: 68\n{{\n{body}\n}}\n")
    with pytest.raises(TrackingError, match=r"frame_1000000000000\.pts: frame 1000000000000 "
                                            "comes"):
        read_landmarks(tmp_path)
    (tmp_path / f"frame_{10**12}.pts").rename(tmp_path / f"frame_{10**40}.pts")
    with pytest.raises(TrackingError, match=rf"frame_{10**40}\.pts: frame {10**40} "):
        read_landmarks(tmp_path)
