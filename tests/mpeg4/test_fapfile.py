"""Reading and writing .fap files: dialects of real players, round trips, malformed files."""

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from facelib import FacelibError, FapFormatError, FapStream, ParameterError, read_fap, write_fap
from facelib.errors import FacelibWarning, FileError
from facelib.mpeg4 import DIALECTS, read_fap_file

DATA = Path(__file__).parents[1] / "data" / "fap"


def test_xface_dialect_crlf_floats_and_token_groups():
    file = read_fap_file(DATA / "xface.fap")
    s = file.stream
    assert (file.dialect, file.name, s.fps, s.n_frames) == ("xface", "Xface::FapFile", 25, 3)
    assert s.values[:, 2].tolist() == [120.5, 240.0, 360.75]
    assert s.values[0, 11] == -40 and s.values[0, 12] == -40.25
    assert s.mask[0].nonzero()[0].tolist() == [0, 2, 11, 12]  # the mask changes per frame
    assert s.mask[1].nonzero()[0].tolist() == [1, 2]
    assert s.viseme[0].tolist() == [2, 0, 0, 1]
    assert s.viseme[2].tolist() == [10, 11, 32, 1]
    assert s.expression[1].tolist() == [1, 63, 0, 0, 1, 1]
    assert s.expression[2].tolist() == [3, 40, 0, 0, 0, 1]


def test_greta_dialect_69_tokens_and_spaced_name():
    file = read_fap_file(DATA / "greta.fap")
    assert file.dialect == "greta"
    assert file.name == "C:/greta/output/request 12.fap"
    s = file.stream
    assert s.values[:, 2].tolist() == [200, 300]
    assert s.values[0, 30] == -100 and s.values[1, 47] == 15000
    assert not s.mask[1, 30]


def test_vreng_dialect_one_based_tab_separated():
    file = read_fap_file(DATA / "vreng.fap")
    assert (file.dialect, file.version, file.stream.fps) == ("vreng", "2.0", 10)
    assert file.stream.values[:, 18].tolist() == [100, 200, 300]


def test_comments_missing_frames_held_with_warning():
    with pytest.warns(FacelibWarning, match="frames 2-3 are missing"):
        file = read_fap_file(DATA / "missing.fap")
    s = file.stream
    assert file.missing_frames == (2, 3)
    assert s.values[:, 2].tolist() == [100, 200, 200, 200, 0]
    assert s.values[:, 48].tolist() == [0, 5000, 5000, 5000, -5000]
    assert s.mask[3, 2] and not s.mask[4, 2]


@pytest.mark.parametrize("name", ["xface.fap", "greta.fap", "vreng.fap", "missing.fap"])
def test_strict_mode_rejects_irregular_files(name):
    with pytest.raises(FapFormatError, match=name):
        read_fap(DATA / name, strict=True)


def test_written_standard_file_is_the_plain_profile(tmp_path):
    values = np.zeros((2, 84), np.float32)
    values[:, 2] = [10.4, -3.6]
    values[:, 70] = 7  # an extended FAP: not in the standard dialect
    out = write_fap(FapStream(25, values), tmp_path / "my anim.fap")
    lines = out.read_text().splitlines()
    assert lines[0] == "2.1 my_anim 25 2"
    assert len(lines) == 5
    assert len(lines[1].split()) == 68
    assert lines[2].split()[:2] == ["0", "10"] and lines[4].split()[:2] == ["1", "-4"]
    assert "#" not in out.read_text() and "\r" not in out.read_text()
    back = read_fap(out, strict=True)
    assert back.values[:, 2].tolist() == [10, -4]
    assert not back.mask[:, 68:].any()


@pytest.mark.filterwarnings("ignore::facelib.errors.FacelibWarning")
def test_xface_and_extended_dialects_keep_high_level_and_extended(tmp_path):
    values = np.zeros((3, 84), np.float32)
    values[:, 3] = [10, 20, 30]
    viseme = np.array([[1, 2, 10, 0]] * 3)
    expression = np.array([[1, 40, 2, 20, 0, 1]] * 3)
    stream = FapStream(30, values, viseme=viseme, expression=expression)
    mask = stream.mask.copy()
    mask[:, :2] = True
    stream = FapStream(30, values, mask, viseme, expression)
    # xface writes values with decimals, as XFace does, which strict mode refuses
    xf_file = read_fap_file(write_fap(stream, tmp_path / "a.fap", dialect="xface"))
    xf = xf_file.stream
    assert xf_file.dialect == "xface"
    assert xf.viseme.tolist() == viseme.tolist()
    assert xf.expression.tolist() == expression.tolist()
    ext = read_fap(write_fap(stream, tmp_path / "b.fap", dialect="extended"), strict=True)
    assert ext == stream
    gr = read_fap_file(write_fap(stream, tmp_path / "c.fap", dialect="greta"))
    assert gr.dialect == "greta" and gr.stream.values[:, 2:68].tolist() == \
        stream.values[:, 2:68].tolist()


finite = st.floats(-4000, 4000, allow_nan=False, width=32)


@settings(max_examples=40, deadline=None)
@given(
    values=hnp.arrays(np.float32, st.tuples(st.integers(0, 6), st.just(84)), elements=finite),
    mask=hnp.arrays(bool, st.tuples(st.integers(0, 6), st.just(84))),
    fps=st.integers(1, 120),
    dialect=st.sampled_from(["standard", "extended"]),
)
@pytest.mark.filterwarnings("ignore:.*dropping FAP:facelib.errors.FacelibWarning")
def test_round_trip_within_integer_rounding(tmp_path_factory, values, mask, fps, dialect):
    n = min(len(values), len(mask))
    mask = mask[:n].copy()
    mask[:, :2] = False
    stream = FapStream(fps, values[:n], mask)
    path = tmp_path_factory.mktemp("rt") / "s.fap"
    back = read_fap(write_fap(stream, path, dialect=dialect), strict=True)
    width = 84 if dialect == "extended" else 68
    assert back.fps == fps and back.n_frames == n
    assert np.array_equal(back.mask[:, :width], stream.mask[:, :width])
    assert np.abs(back.values - stream.values)[:, :width].max(initial=0) <= 0.5
    assert not back.mask[:, width:].any()


def test_writer_refuses_bad_requests(tmp_path):
    stream = FapStream(29.97, np.zeros((2, 84)))
    with pytest.raises(ParameterError, match=r"29\.97"):
        write_fap(stream, tmp_path / "x.fap")
    with pytest.raises(ParameterError, match="'mpeg'"):
        write_fap(FapStream(25, np.zeros((1, 84))), tmp_path / "x.fap", dialect="mpeg")
    assert not list(tmp_path.iterdir())


def test_written_files_get_the_usual_permissions(tmp_path):
    import os

    umask = os.umask(0o022)
    try:
        out = write_fap(FapStream(25, np.zeros((1, 84))), tmp_path / "p.fap")
    finally:
        os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o644


def test_failed_write_leaves_the_old_file(tmp_path, monkeypatch):
    path = tmp_path / "keep.fap"
    path.write_text("old")

    def boom(self, *args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(Path, "write_text", boom)
    with pytest.raises(FileError, match="disk full"):
        write_fap(FapStream(25, np.zeros((2, 84))), path)
    monkeypatch.undo()
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.fap"]


MASK = " ".join(["0", "0", "1"] + ["0"] * 65)

MALFORMED = [
    ("", r"empty", None),
    ("# only a comment\n", r"empty", None),
    ("2.1 name 25\n", r"bad header", 1),
    ("x name 25 1\n", r"bad header version 'x'", 1),
    ("2.1 name fast 1\n", r"bad frame rate 'fast'", 1),
    ("2.1 name 25 -1\n", r"bad frame count '-1'", 1),
    ("2.1 name 0 1\n", r"bad frame rate '0'", 1),
    (f"2.1 n 25 2\n{MASK}\n0 10\n{MASK}\n", r"truncated frame", 4),
    (f"2.1 n 25 1\n{MASK}\n0 nan\n", r"'nan' is not a number", 3),
    (f"2.1 n 25 1\n{MASK}\n0 1e999\n", r"outside the format.s range", 3),
    (f"2.1 n 25 1\n{MASK}\n0 ten\n", r"'ten' is not a number", 3),
    (f"2.1 n 25 1\n{MASK}\n0 10 20\n", r"has 2 values, the mask line above sets 1", 3),
    (f"2.1 n 25 1\n{MASK}\n0\n", r"has 0 values", 3),
    (f"2.1 n 25 1\n{MASK} 0 0\n0 10\n", r"70 tokens", 2),
    (f"2.1 n 25 2\n{MASK}\n0 1\n{MASK} 0\n1 2\n", r"69 tokens, expected 68 like", 4),
    (f"2.1 n 25 1\n{MASK.replace('1', '2')}\n0 10\n", r"mask token '2'", 2),
    (f"2.1 n 25 2\n{MASK}\n0 1\n{MASK}\n5 2\n", r"frame number 5 is outside the 2 frames", 5),
    (f"2.1 n 25 3\n{MASK}\n1 1\n{MASK}\n0 2\n", r"frame number 0 does not follow frame 1", 5),
    (f"2.1 n 25 1\n{MASK}\n-1 2\n", r"frame number '-1'", 3),
    ("2.1 n 25 2\n", r"declares 2 frames but the file has none", 1),
    ("2.1 n 25 1\n" + " ".join(["1"] + ["0"] * 67) + "\n0 1 2\n", r"not an integer|values", 3),
]


@pytest.mark.parametrize(("text", "message", "line"), MALFORMED)
def test_malformed_files_raise_fap_format_error(tmp_path, text, message, line):
    path = tmp_path / "bad.fap"
    path.write_text(text)
    with pytest.raises(FapFormatError, match=message) as info:
        read_fap(path)
    assert isinstance(info.value, FacelibError)
    assert info.value.path == str(path)
    assert info.value.line == line
    assert str(info.value).startswith(f"{path}:{line}:" if line else f"{path}:")


def test_unreadable_file(tmp_path):
    with pytest.raises(FapFormatError, match="cannot read"):
        read_fap(tmp_path / "absent.fap")


@pytest.mark.parametrize("dialect", DIALECTS)
def test_every_dialect_read_back_is_the_dialect_written(tmp_path, dialect):
    values = np.zeros((3, 84), np.float32)
    values[:, 2] = [0.0, 120.25, -40.5]
    stream = FapStream(25, values)
    file = read_fap_file(write_fap(stream, tmp_path / "a.fap", dialect=dialect))
    assert file.dialect == dialect
    assert file.stream.n_frames == 3
    exact = dialect == "xface"  # the only dialect with decimals
    expected = values[:, 2] if exact else np.rint(values[:, 2])
    assert file.stream.values[:, 2].tolist() == expected.tolist()
