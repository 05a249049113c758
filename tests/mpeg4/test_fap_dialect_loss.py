"""What each written dialect keeps (issue 36): the ``vreng`` dialect as VREng's reader parses it
(single spaces: tabs are not separators to it), FAP 1/2 dropped with a warning like the
extended FAPs, and a writer that keeps every FAP the frames show."""

import warnings

import numpy as np
import pytest

from facelib import FapStream, read_fap
from facelib.errors import FacelibWarning
from facelib.mpeg4 import fap as fap_info
from facelib.mpeg4 import format_fap, write_fap_complete


def _stream(n=4):
    values = np.zeros((n, 84), np.float32)
    mask = np.zeros((n, 84), bool)
    for name, base in (("open_jaw", 100), ("raise_b_midlip", -40), ("head_yaw", 15000)):
        j = fap_info(name).index
        values[:, j] = base + np.arange(n)
        mask[:, j] = True
    return FapStream(25, values, mask)


def _vreng_parse(text):
    """The frames as VREng's FAP path reads them (shared/reference/fap_players.md, section 2):
    header split on spaces; the mask and value lines joined into one string split on ' '
    only; 68 mask tokens, the 69th token the frame number, one token per masked FAP (atof)."""
    lines = text.split("\n")
    header = lines[0].split(" ")
    frames = []
    for k in range(int(header[3])):
        tokens = (lines[1 + 2 * k] + " " + lines[2 + 2 * k]).split(" ")
        mask = [t == "1" for t in tokens[:68]]
        number = int(tokens[68])
        values = np.zeros(68)
        rest = iter(tokens[69:])
        for i in np.flatnonzero(mask):
            values[i] = float(next(rest))
        frames.append((number, values))
    return int(header[2]), int(header[3]), frames


def test_vreng_dialect_reads_in_vrengs_parser():
    stream = _stream()
    text = format_fap(stream, dialect="vreng")
    assert "\t" not in text
    fps, n, frames = _vreng_parse(text)
    assert (fps, n) == (25, 4)
    # frames count from 1, so VREng's `frame < frames` check lets the last frame play
    assert [number for number, _ in frames] == [1, 2, 3, 4]
    for i, (_, values) in enumerate(frames):
        np.testing.assert_array_equal(values, np.rint(stream.values[i, :68]))


@pytest.mark.parametrize("dialect", ["standard", "greta", "vreng"])
def test_fap_1_and_2_dropped_with_a_warning(dialect):
    n = 3
    viseme = np.tile([4, 0, 63, 0], (n, 1))
    mask = np.zeros((n, 84), bool)
    mask[:, 0] = True
    stream = FapStream(25, np.zeros((n, 84), np.float32), mask, viseme, None)
    with pytest.warns(FacelibWarning, match=r"FAP 1 \(viseme\).*3 frames"):
        format_fap(stream, dialect=dialect)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        format_fap(stream, dialect="extended")  # keeps them: no warning


def test_write_fap_complete_keeps_every_fap_the_frames_show(tmp_path):
    stream = _stream()
    nose = fap_info(80).index
    values, mask = np.array(stream.values), np.array(stream.mask)
    values[:, nose], mask[:, nose] = 300, True
    mask[:, 0] = True
    viseme = np.tile([4, 0, 63, 0], (4, 1))
    full = FapStream(25, values, mask, viseme, None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing is lost, so nothing to warn about
        paths = write_fap_complete(full, tmp_path / "clip.fap")
    assert paths == (tmp_path / "clip.fap", tmp_path / "clip.extended.fap")
    players = read_fap(paths[0])
    # the standard file carries FAP 1 decoded into the lip and jaw FAPs the frames show
    assert players.values[:, 2].tolist() == np.rint(values[:, 2]).tolist()
    assert np.abs(players.values[:, 3:68]).sum() > np.abs(np.rint(values[:, 3:68])).sum()
    everything = read_fap(paths[1])
    assert everything.values[:, nose].tolist() == [300] * 4
    assert everything.viseme is not None and everything.viseme[:, 0].tolist() == [4] * 4
    # a stream that standard holds whole gets one file
    only = write_fap_complete(stream, tmp_path / "plain.fap")
    assert only == (tmp_path / "plain.fap",) and not (tmp_path / "plain.extended.fap").exists()
