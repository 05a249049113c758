"""The bundled characters (issue 33 item 4): each loads by name wherever a face is named
(load_face, a storyboard's ``face``, ``--face``), is listed, differs from the others, and is
animated by FAPs like the default head; an unknown name gets a did-you-mean."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import facelib
from facelib.cli import main
from facelib.clip import make_clip, storyboard_definition
from facelib.engine import hair_style_names, load_face
from facelib.engine.characters import character_names, characters, face_definition
from facelib.errors import FaceModelError, FdlError
from facelib.fdl import load
from facelib.mpeg4 import FapStream
from facelib.mpeg4.tables import fap

NAMES = character_names()


@pytest.fixture(scope="module", params=NAMES)
def character(request):
    return request.param, load_face(request.param)


def test_there_are_at_least_four_characters_each_with_its_own_files():
    assert len(NAMES) >= 4
    assert {"ada", "ben"} <= set(NAMES)
    for c in characters():
        assert c.definition.is_file() and c.description
        assert face_definition(c.name) == c.definition


def test_each_character_keeps_the_default_layout_with_its_own_shape_and_colours(character):
    name, face = character
    default = load_face(None)
    skin = default.parts["skin"].vertex_ids
    assert face.feature_points == default.feature_points
    assert [r.name for r in face.regions] == [r.name for r in default.regions]
    assert set(face.parts) >= {"skin", "eye_l", "teeth_upper", "tongue", "lashes", "bust",
                               "garment", "hair"}
    moved = np.linalg.norm(face.vertices[skin] - default.vertices[skin], axis=1)
    assert np.median(moved) > 0.003  # another shape, not the default head
    assert np.abs(face.vertex_colors[skin] - default.vertex_colors[skin]).mean() > 0.01
    assert hair_style_names(name)[-1] == "none" and len(hair_style_names(name)) == 2


def test_the_characters_differ_from_each_other():
    faces = {n: load_face(n, hair="none") for n in NAMES}
    skin = faces[NAMES[0]].parts["skin"].vertex_ids
    for i, a in enumerate(NAMES):
        for b in NAMES[i + 1:]:
            gap = np.linalg.norm(faces[a].vertices[skin] - faces[b].vertices[skin], axis=1)
            assert np.median(gap) > 0.002, (a, b)
            tone = np.abs(faces[a].vertex_colors[skin].mean(0)
                          - faces[b].vertex_colors[skin].mean(0)).sum()
            height = np.ptp(faces[a].vertices[skin, 1]) - np.ptp(faces[b].vertices[skin, 1])
            assert tone > 0.02 or abs(height) > 0.005, (a, b)


def test_an_open_jaw_moves_each_characters_lower_lip_down(character):
    name, face = character
    frames = np.zeros((2, 84), np.float32)
    frames[1, fap("open_jaw").index] = 400.0
    frames[1, fap("raise_l_cornerlip").index] = 150.0  # any FAP: a smile's corner
    moved = face.deform(FapStream(25, frames))
    lower = face.feature_points["8.2"]
    drop = moved[0, lower, 1] - moved[1, lower, 1]
    assert drop > 0.004, (name, drop)  # metres: 400 MNS is about a centimetre
    region = next(r for r in face.regions if r.name == "lower_lip")
    assert (moved[1, region.vertices, 1] < moved[0, region.vertices, 1] - 1e-4).mean() > 0.5
    upper = face.feature_points["8.1"]
    assert abs(moved[1, upper, 1] - moved[0, upper, 1]) < 0.3 * drop
    # the lashes and the hair ride with the head: a head turn moves both
    frames[1] = 0.0
    frames[1, fap("head_yaw").index] = np.radians(20) / face.fapu["AU"]
    turned = face.deform(FapStream(25, frames))
    for part in ("lashes", "hair"):
        ids = face.parts[part].vertex_ids
        assert np.abs(turned[1, ids, 0] - turned[0, ids, 0]).mean() > 0.005, (name, part)


def test_load_face_and_the_package_name_take_a_character(tmp_path, monkeypatch):
    assert facelib.load_face("ben").n_vertices == load_face("ben").n_vertices
    # an existing file or folder of that name wins over the character
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ben").mkdir()
    assert face_definition("ben") == Path("ben") / "face.json"


def test_an_unknown_character_gets_a_did_you_mean():
    with pytest.raises(FaceModelError, match=r"did you mean 'ben'\?"):
        load_face("bne")
    with pytest.raises(FaceModelError, match="characters: ada, ben"):
        face_definition("nobody")


def test_the_storyboard_face_names_a_character(tmp_path, storyboard_source):
    source = storyboard_source('fps = 25\nface = "mei"\nsay { text = "hi" }\n')
    assert source.storyboard.face == "mei"
    assert storyboard_definition(source.storyboard) == face_definition("mei")
    face = make_clip(source).face
    assert np.allclose(face.vertices, load_face("mei").vertices)
    # a file beside the storyboard of that name is the storyboard's own face
    (tmp_path / "mei").write_text("{}")
    assert load(tmp_path / "story.fdl").face == (tmp_path / "mei").resolve()


def test_a_misspelled_storyboard_character_names_its_line(storyboard_source):
    source = storyboard_source('fps = 25\n\nface = "omra"\n')
    with pytest.raises(FdlError, match=r"story\.fdl:3.*did you mean 'omar'\?"):
        make_clip(source)


def test_the_commands_take_a_character(tmp_path, capsys):
    assert main(["list", "characters"]) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert listed == list(NAMES)
    story = tmp_path / "story.fdl"
    story.write_text('fps = 25\nface = "ada"\nsay { text = "hi" }\n')
    assert main(["check", str(story)]) == 0
    assert "face: ada" in capsys.readouterr().out
    out = tmp_path / "ben.glb"
    assert main(["export", str(story), "--face", "ben", "-o", str(out)]) == 0
    assert out.stat().st_size > 100_000
    assert main(["export", str(story), "--face", "bem", "-o", str(out)]) == 2
    assert "did you mean 'ben'?" in capsys.readouterr().err
    story.write_text('fps = 25\nface = "adaa"\n')
    assert main(["check", str(story)]) != 0
    assert "story.fdl:2" in capsys.readouterr().err


def test_a_dialogue_character_may_be_a_bundled_character(tmp_path):
    story = tmp_path / "d.fdl"
    story.write_text('characters {\n  ada = { face = "ada" },\n  ben = { face = "bne" },\n}\n'
                     'say { who = "ada", "Hi." }\nsay { who = "ben", "Hello." }\n')
    board = load(story)
    assert [c.face for c in board.characters] == ["ada", "bne"]
    assert storyboard_definition(board.characters[0].part) == face_definition("ada")
    with pytest.raises(FdlError, match=r"d\.fdl:3.*did you mean 'ben'\?"):
        storyboard_definition(board.characters[1].part)
    assert face_definition("default") == face_definition("ada").parent / "default_head.json"
