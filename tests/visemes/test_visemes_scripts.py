"""Viseme timelines out and in: JSON, TSV, the thesis Sentence script, stored scripts."""

from __future__ import annotations

import json

import pytest

from facelib.cues import VisemeCue
from facelib.errors import FdlError, ParameterError
from facelib.visemes import (
    timeline_from_json,
    timeline_from_text,
    timeline_to_sentence,
    timeline_to_tsv,
    visemes_from_cues,
    write_timeline,
)


@pytest.fixture(scope="module")
def timeline():
    return timeline_from_text("Bob saw a blue moon, quietly.")


def test_json_round_trip(timeline, tmp_path):
    path = write_timeline(timeline, tmp_path / "out.json")
    data = json.loads(path.read_text())
    assert set(data) >= {"phones", "words", "visemes"}
    assert data["phones"][1] == {"phone": "B", "start": timeline.phones[1].start_ms / 1000,
                                 "end": timeline.phones[1].end_ms / 1000}
    assert data["visemes"][1]["viseme"] == 1 and data["visemes"][1]["name"] == "PP"
    assert timeline_from_json(data) == timeline
    assert not list(tmp_path.glob(".*tmp"))


def test_tsv_rows(timeline):
    rows = timeline_to_tsv(timeline).splitlines()
    assert rows[0] == "tier\tlabel\tstart\tend\tviseme\tconfidence"
    assert len(rows) == 1 + len(timeline.phones) + len(timeline.words) + len(timeline.visemes)
    assert rows[-1].split("\t")[0] == "viseme"


def test_sentence_script_frames_add_up_and_parse_back(timeline):
    text = timeline_to_sentence(timeline, fps=25)
    entries = [line for line in text.splitlines() if line.startswith("{")]
    frames = [int(e.split(",")[1].strip(" }")) for e in entries]
    assert sum(frames) == round(timeline.visemes[-1].end_ms * 25 / 1000)
    names = [e.split('"')[1] for e in entries]
    assert names[0] == "silence" and "pbm" in names and "U" in names
    # a stored script with those names is read back to the same visemes
    cues, t = [], 0
    for name, n in zip(names, frames, strict=True):
        cues.append(VisemeCue(name, t * 40, n * 40))
        t += n
    back = visemes_from_cues(tuple(cues))
    assert [s.viseme for s in back] == [s.viseme for s in timeline.visemes if
                                       round(s.end_ms / 40) > round(s.start_ms / 40)]


def test_unknown_script_viseme_names_file_and_line():
    cues = (VisemeCue("A", 0, 100, ("story.fdl", 3)), VisemeCue("zz", 100, 40, ("story.fdl", 4)))
    with pytest.raises(FdlError, match=r"story\.fdl:4: .*'zz'"):
        visemes_from_cues(cues)


def test_unknown_output_format(timeline, tmp_path):
    with pytest.raises(ParameterError, match=r"\.txt"):
        write_timeline(timeline, tmp_path / "x.txt")


def test_write_timeline_makes_folders_and_normal_permissions(timeline, tmp_path):
    import os
    import stat

    umask = os.umask(0o022)
    try:
        path = write_timeline(timeline, tmp_path / "new" / "folder" / "out.tsv")
    finally:
        os.umask(umask)
    assert path.read_text().startswith(timeline_to_tsv(timeline)[:20])
    assert stat.S_IMODE(path.stat().st_mode) == 0o644  # was 0600 from mkstemp
    assert [p.name for p in path.parent.iterdir()] == ["out.tsv"]  # no temp file left
