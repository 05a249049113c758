"""facelib.data: every package data file goes through one reader that names file and line."""

import json
from pathlib import Path

import pytest

from facelib import data
from facelib.errors import DataError

PACKAGE = Path(__file__).parents[2] / "facelib"


def test_csv_rows_carry_their_line_numbers():
    rows = data.csv_rows("mpeg4_visemes.csv")
    text = data.text("mpeg4_visemes.csv").splitlines()
    for line, row in rows[:3]:
        assert row["name"] in text[line - 1]


def test_every_packaged_csv_and_json_parses():
    root = PACKAGE / "data"
    for path in root.rglob("*"):
        name = path.relative_to(root).as_posix()
        if path.suffix == ".csv":
            assert data.csv_rows(name), name
        elif path.suffix == ".json" and "head" not in path.parts:
            assert isinstance(data.json_data(name), dict), name


def test_a_row_with_an_extra_cell_is_a_data_error(monkeypatch):
    monkeypatch.setattr(data, "text", lambda name: "# comment\na,b\n1,2\n3,4,5\n")
    with pytest.raises(DataError, match=r":4: 3 cells where the header has 2"):
        data.csv_rows("broken.csv")


def test_invalid_json_is_a_data_error_with_its_line(monkeypatch):
    monkeypatch.setattr(data, "text", lambda name: '{\n "a": 1,\n}')
    with pytest.raises(DataError, match=r":3: invalid JSON"):
        data.json_data("broken.json")


def test_no_module_reads_package_data_around_the_reader():
    """importlib.resources is used in facelib/data only."""
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("data/"):
            continue
        if "importlib import resources" in path.read_text(encoding="utf-8"):
            offenders.append(rel)
    assert offenders == [], offenders


def test_comment_keys_are_dropped_from_json():
    assert not any(k.startswith("_") for k in data.json_data("gaze/model.json"))
    assert "_about" in json.loads(data.text("gaze/model.json"))
