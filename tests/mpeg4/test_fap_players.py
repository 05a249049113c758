"""The four .fap defects found by running real players' readers (shared/reference/fap_players.md):
Greta's 69th slot, the xface groups, dropped extended FAPs, and FAP 1/2 applied on playback."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from facelib import FapStream, read_fap, write_fap
from facelib.engine import default_face
from facelib.errors import FacelibWarning
from facelib.mpeg4 import fap
from facelib.mpeg4.highlevel import apply_high_level, expression_table, viseme_table
from facelib.mpeg4.visemes import viseme_id

DATA = Path(__file__).parents[1] / "data" / "fap"


def _stream_with_extended() -> FapStream:
    values = np.zeros((4, 84), np.float32)
    values[:, 2] = [0, 100, 200, 300]          # open_jaw
    values[:, 68] = [6900, -6901, 6902, 0]     # FAP 69, an extended FAP
    values[:, 79] = [0, 0, 150, 0]             # FAP 80
    return FapStream(25, values)


def test_greta_dialect_never_sets_the_69th_slot(tmp_path):
    out = tmp_path / "g.fap"
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        write_fap(_stream_with_extended(), out, dialect="greta")
    lines = out.read_text().splitlines()
    masks = lines[1::2]
    assert all(len(m.split()) == 69 and m.split()[68] == "0" for m in masks)
    # no stray value: the value line holds exactly the masked FAPs 3-68
    for mask, value in zip(masks, lines[2::2], strict=True):
        assert len(value.split()) - 1 == mask.split().count("1")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the reader must not meet a non-zero 69th slot
        back = read_fap(out)
    assert back.values[:, 2].tolist() == [0, 100, 200, 300]


def test_standard_dialect_warns_naming_the_dropped_extended_faps(tmp_path):
    with pytest.warns(FacelibWarning, match=r"dropping FAP 69, 80 .*dialect='extended'"):
        write_fap(_stream_with_extended(), tmp_path / "s.fap")
    assert read_fap(tmp_path / "s.fap").values[:, 68:].any() == np.False_
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_fap(_stream_with_extended(), tmp_path / "e.fap", dialect="extended")
    assert read_fap(tmp_path / "e.fap").values[:, 79].tolist() == [0, 0, 150, 0]


def test_xface_groups_warn_and_standard_does_not(tmp_path):
    values = np.zeros((2, 84), np.float32)
    mask = np.zeros((2, 84), bool)
    mask[:, :3] = True
    stream = FapStream(25, values, mask, np.array([[1, 2, 30, 0]] * 2), None)
    with pytest.warns(FacelibWarning, match="shift every later value .* Greta Java and VREng"):
        write_fap(stream, tmp_path / "x.fap", dialect="xface")
    # standard has no token groups to shift; it drops FAP 1 and says so (issue 36)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        write_fap(stream, tmp_path / "s.fap", dialect="standard")
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "has no FAP 1 (viseme)" in messages[0], messages


def test_high_level_faps_decode_as_the_mpeg4_blend():
    n = 3
    mask = np.zeros((n, 84), bool)
    mask[:, :2] = True
    mask[2, 2] = True  # frame 2 sets open_jaw itself: it keeps its own value
    values = np.zeros((n, 84), np.float32)
    values[2, 2] = -5
    aa, pp = viseme_id("aa"), viseme_id("PP")
    viseme = np.array([[aa, pp, 63, 0], [aa, pp, 21, 0], [aa, pp, 21, 0]])
    expression = np.array([[1, 63, 0, 0, 0, 0], [1, 21, 6, 42, 0, 0], [0, 0, 0, 0, 0, 0]])
    out = apply_high_level(FapStream(25, values, mask, viseme, expression))
    v, e = viseme_table(), expression_table()
    np.testing.assert_allclose(out.values[0], (v[aa] + e[1]) * (~mask[0]), atol=1e-3)
    want = (21 * v[aa] + 42 * v[pp]) / 63 + 21 / 63 * e[1] + 42 / 63 * e[6]
    np.testing.assert_allclose(out.values[1, 2:], want[2:], atol=1e-3)
    assert out.values[2, 2] == -5
    jaw = fap("open_jaw").index
    assert v[aa, jaw] > 0 and out.values[2, jaw] == -5


def test_a_file_with_only_fap_1_and_2_animates_the_face():
    stream = read_fap(DATA / "xface.fap")
    face = default_face()
    moved = face.deform(stream) - face.vertices
    plain = FapStream(stream.fps, stream.values, stream.mask & ~np.eye(84, dtype=bool)[0:1]
                      & ~np.eye(84, dtype=bool)[1:2])
    assert np.abs(moved - (face.deform(plain) - face.vertices)).max() > 1e-3  # > 1 mm
    chunks = np.concatenate([v for _, v in face.deform_chunks(stream, frames=2)])
    whole = face.deform(stream)  # another block size may sum in another order: a few ulps
    np.testing.assert_allclose(chunks, whole, rtol=0, atol=4 * np.spacing(np.abs(whole).max()))


def test_warnings_for_greta_frame_rate_and_long_high_level_files(tmp_path):
    with pytest.warns(FacelibWarning, match="plays 25 fps"):
        write_fap(FapStream.zeros(3, fps=30), tmp_path / "g30.fap", dialect="greta")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_fap(FapStream.zeros(3, fps=25), tmp_path / "g25.fap", dialect="greta")
    n = 8001
    mask = np.zeros((n, 84), bool)
    mask[:, 0] = True
    long = FapStream(25, np.zeros((n, 84), np.float32), mask, np.tile([1, 2, 30, 0], (n, 1)))
    with pytest.warns(FacelibWarning, match="8000 frames"):
        write_fap(long, tmp_path / "long.fap", dialect="extended")
