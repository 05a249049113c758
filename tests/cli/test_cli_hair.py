"""Hair per character (issue 33 item 1): the storyboard's ``hair`` global, ``--hair STYLE`` on
render / play / view / export, ``facelib list hair``, and the errors for unknown styles."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from facelib import FapStream, load_face
from facelib.cli import main
from facelib.clip import face_for, make_clip
from facelib.engine import hair_style_names
from facelib.errors import FdlError, ParameterError
from facelib.export.source import export_clip
from facelib.fdl import loads


def test_the_bundled_head_lists_its_styles_and_bald(capsys):
    assert hair_style_names() == ("short", "long", "tied", "none")
    assert main(["list", "hair"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == ["short", "long", "tied", "none"]
    assert all(len(line.split()) > 2 for line in lines)  # each with a description


def test_the_storyboard_hair_global_dresses_its_face(tmp_path, storyboard_source):
    bald = make_clip(storyboard_source('hair = "none"\n')).face
    assert "hair" not in bald.parts
    tied = make_clip(storyboard_source('fps = 25\nhair = "tied"\n')).face
    assert len(tied.parts["hair"].vertex_ids) == len(
        load_face(hair="tied").parts["hair"].vertex_ids)
    assert len(tied.parts["hair"].vertex_ids) != len(
        load_face(hair="short").parts["hair"].vertex_ids)
    # exports play on the bundled head but wear the storyboard's hair; a given face keeps its own
    assert "hair" not in export_clip(storyboard_source('hair = "none"\n')).face.parts
    short = load_face(hair="short")
    assert make_clip(storyboard_source('hair = "none"\n'), face=short).face is short


def test_an_unknown_storyboard_style_names_the_file_line_and_the_closest(
        tmp_path, storyboard_source):
    source = storyboard_source('fps = 25\n\nhair = "lnog"\n')
    with pytest.raises(FdlError) as caught:
        make_clip(source)
    assert str(caught.value).startswith(f"{tmp_path / 'story.fdl'}:3: hair style 'lnog'")
    assert "did you mean 'long'?" in str(caught.value)


def test_the_hair_global_must_be_a_name():
    with pytest.raises(FdlError, match=r"^<story>:2: hair must be a hair style name"):
        loads('fps = 25\nhair = 3\n', name="<story>")
    assert loads('hair = " long "\n').hair == "long"
    assert loads("fps = 25\n").hair is None


def test_face_for_dresses_the_given_the_storyboards_or_the_bundled_face(tmp_path):
    assert face_for(None, None, None) is None
    assert face_for(None, "x.json", None) == "x.json"  # no hair: the path as given
    assert "hair" not in face_for(None, None, "none").parts
    with pytest.raises(ParameterError, match=r"did you mean 'tied'\?"):
        face_for(None, None, "tide")


def test_unknown_option_styles_are_usage_errors_with_the_suggestion(tmp_path, capsys):
    fap = tmp_path / "still.fap"
    from facelib.mpeg4 import write_fap

    write_fap(FapStream(25, np.zeros((1, 84), np.float32)), fap)
    for command in (["play", str(fap), "-o", str(tmp_path / "x.png")],
                    ["export", str(fap), "-o", str(tmp_path / "x.glb")]):
        assert main([*command, "--hair", "shrot"]) == 2
        err = capsys.readouterr().err
        assert "--hair: hair style 'shrot' is not one of the bundled head's" in err
        assert "did you mean 'short'?" in err
        assert not (tmp_path / "x.png").exists() and not (tmp_path / "x.glb").exists()


def _render(tmp_path: Path, fap: Path, style: str, framing: str) -> np.ndarray:
    from PIL import Image

    out = tmp_path / f"{style}_{framing}.png"
    assert main(["render", str(fap), "--hair", style, "--framing", framing, "--width", "96",
                 "--height", "72", "-o", str(out)]) == 0
    return np.asarray(Image.open(out).convert("RGB"), float)


@pytest.mark.render
def test_render_hair_none_and_long_differ_above_the_forehead(tmp_path):
    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("rendering needs the render extra")
    from facelib.mpeg4 import write_fap

    fap = tmp_path / "still.fap"
    write_fap(FapStream(25, np.zeros((1, 84), np.float32)), fap)
    bald, haired = (_render(tmp_path, fap, s, "head") for s in ("none", "long"))
    # the top of the head frame, centre columns: bald skin there (~140), dark hair (~55)
    crown = np.s_[4:16, 40:56]
    assert bald[crown].mean() > 1.6 * haired[crown].mean(), (bald[crown].mean(),
                                                             haired[crown].mean())
    # framed on the face (brow to chin, the same camera): eyes to mouth are the same pixels
    bald, haired = (_render(tmp_path, fap, s, "face") for s in ("none", "long"))
    middle = np.s_[30:60, 36:60]
    assert np.abs(bald[middle] - haired[middle]).max() <= 2
    assert np.abs(bald - haired).mean() > 5  # while the hair changes the frame


def test_check_and_batch_jobs_refuse_an_unknown_style(tmp_path, capsys):
    from facelib.batch import RenderJob, plan_jobs, render_job
    from facelib.mpeg4 import write_fap

    story = tmp_path / "story.fdl"
    story.write_text('show { "joy", at = 0, dur = 0.2 }\nhair = "tide"\n')
    assert main(["check", str(story)]) == 1
    assert f"{story}:2: hair style 'tide'" in capsys.readouterr().err
    story.write_text('show { "joy", at = 0, dur = 0.2 }\nhair = "tied"\n')
    assert main(["check", str(story)]) == 0
    assert "hair: tied" in capsys.readouterr().out
    assert [j.hair for j in plan_jobs([story], tmp_path, hair="long")] == ["long"]
    fap = tmp_path / "still.fap"
    write_fap(FapStream(25, np.zeros((1, 84), np.float32)), fap)
    result = render_job(RenderJob(str(fap), str(tmp_path / "x.mp4"), hair="lnog"))
    assert result.output is None and "did you mean 'long'?" in str(result.error)
