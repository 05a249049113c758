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
from facelib.expressions import default_library
from facelib.fdl import load
from facelib.mpeg4 import FapStream
from facelib.mpeg4.action_units import compose
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


def _eyeball_points(vertices: np.ndarray, triangles: np.ndarray, n: int = 4) -> np.ndarray:
    """``(T * (n+1)(n+2)/2, 3)`` points on the triangles (a barycentric grid of each)."""
    grid = np.array([(i / n, j / n) for i in range(n + 1) for j in range(n + 1 - i)])
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    w = np.stack([1 - grid.sum(1), grid[:, 0], grid[:, 1]], 1)  # (G, 3)
    return np.einsum("gk,tkd->tgd", w, np.stack([a, b, c], 1)).reshape(-1, 3)


def _front_z(vertices: np.ndarray, triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(P,)`` the largest z (towards the camera) of the triangles over each point's x and
    y; ``-inf`` where no triangle is."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    keep = np.abs(det) > 1e-12
    a, e1, e2, det = a[keep], e1[keep], e2[keep], det[keep]
    d = points[:, None, :2] - a[None, :, :2]
    s = (d[..., 0] * e2[:, 1] - d[..., 1] * e2[:, 0]) / det
    t = (e1[:, 0] * d[..., 1] - e1[:, 1] * d[..., 0]) / det
    z = a[:, 2] + s * e1[:, 2] + t * e2[:, 2]
    return np.where((s >= 0) & (t >= 0) & (s + t <= 1), z, -np.inf).max(1)


def _lower_lid_cover(face, vertices: np.ndarray, side: str) -> float:
    """The least depth (metres) of lid and cheek skin in front of the eyeball ``side``
    below its lower lid: over the eyeball's front points more than a millimetre below the
    lower lid margin (the lash anchors below the eye's centre, its height interpolated
    across), the skin's front-most z over the point less that of the eyeball. Negative:
    the eyeball shows through the skin there."""
    pivot = np.asarray(face.pivots[f"eye_{side}"])
    margin = np.unique(face.riders.anchors)
    margin = margin[np.sign(vertices[margin, 0]) == np.sign(pivot[0])]
    lower = vertices[margin][vertices[margin, 1] < vertices[margin, 1].mean()]
    lower = lower[np.argsort(lower[:, 0])]
    part = face.parts[f"eye_{side}"]
    points = _eyeball_points(vertices, part.triangles)
    points = points[(points[:, 2] > pivot[2] + 0.004)
                    & (points[:, 0] > lower[0, 0]) & (points[:, 0] < lower[-1, 0])]
    points = points[points[:, 1] < np.interp(points[:, 0], lower[:, 0], lower[:, 1]) - 0.001]
    skin = face.parts["skin"].triangles
    centres = vertices[skin].mean(1)
    near = skin[(np.linalg.norm(centres[:, :2] - pivot[:2], axis=1) < 0.025)
                & (centres[:, 2] > pivot[2])]
    z = _front_z(vertices, near, points)
    assert np.isfinite(z).all()  # skin over every point below the lid
    return float((z - points[:, 2]).min())


def test_no_characters_eyeball_shows_through_its_lower_lid_when_smiling(character):
    """The reviewer's blue patches under ben's smiling eyes (the iris through the lower
    lid): anny's helper eyes had grown and moved forward of ben's and omar's sockets; the
    builder now fits each eyeball to its socket's skin. Smiling (the library's joy at 0.8)
    and with the cheek raiser (AU6) at full intensity, the lower lids and cheeks lift over
    the eyeball and must stay in front of it."""
    name, face = character
    joy = default_library().get("joy")
    au6, _ = compose([("AU6", 1.0)])
    poses = {"neutral": face.vertices,
             "joy 0.8": face.deform_frame((joy.share(0.8) * joy.values).astype(np.float32)),
             "AU6": face.deform_frame(au6.astype(np.float32))}
    for pose, vertices in poses.items():
        for side in ("l", "r"):
            cover = _lower_lid_cover(face, vertices, side)
            assert cover > 0.0001, (name, pose, side, f"{cover * 1000:.2f} mm")


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
