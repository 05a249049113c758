"""Face set-up from files and the command line; bad meshes and landmarks fail clearly,
with nothing written."""

from __future__ import annotations

import importlib.util
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import facelib
from facelib.cli import main
from facelib.engine import Face, default_face, load_face
from facelib.engine.face import PART_NAMES
from facelib.engine.setup import read_landmarks, set_up_face, setup_face
from facelib.engine.setup.headmesh import head_mesh, load_head_mesh
from facelib.errors import FaceModelError, ParameterError

ROOT = Path(__file__).resolve().parents[2]
HEADS = ROOT / "examples" / "heads"
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"


@pytest.fixture(scope="module")
def source():  # type: ignore[no-untyped-def]
    return default_face()


@pytest.fixture(scope="module")
def cartoon() -> tuple[object, dict]:
    return load_head_mesh(HEADS / "cartoon_head.obj"), read_landmarks(
        HEADS / "cartoon_landmarks.json")


def _skin_only(source, vertices=None):  # type: ignore[no-untyped-def]
    skin = source.parts["skin"]
    n = skin.vertex_ids.size
    verts = source.vertices[:n] if vertices is None else vertices
    return head_mesh(verts, skin.triangles)


def _skin_marks(source, points: bool = False) -> dict:  # type: ignore[no-untyped-def]
    n = source.parts["skin"].vertex_ids.size
    return {k: (source.vertices[v].tolist() if points else int(v))
            for k, v in source.feature_points.items() if v < n}


def test_test_heads_are_small_and_licensed() -> None:
    for name in ("soma_head.ply", "cartoon_head.obj", "soma_truth.npz"):
        assert (HEADS / name).stat().st_size < 200_000, name
    notice = (HEADS / "NOTICE").read_text()
    assert "Apache" in notice and "CC0" in notice


def test_mesh_files_load_with_their_parts(tmp_path: Path, source) -> None:  # type: ignore[no-untyped-def]
    import trimesh

    scene = trimesh.Scene()
    names = {"skin": "Head", "eye_l": "Eye.L", "eye_r": "Eye.R", "teeth_upper": "TeethUp",
             "teeth_lower": "TeethLow", "tongue": "Tongue"}
    for part, obj in names.items():
        p = source.parts[part]
        local = np.full(source.n_vertices, -1)
        local[p.vertex_ids] = np.arange(p.vertex_ids.size)
        scene.add_geometry(trimesh.Trimesh(source.vertices[p.vertex_ids], local[p.triangles],
                                           process=False), node_name=obj, geom_name=obj)
    path = tmp_path / "head.glb"
    scene.export(path)
    mesh = load_head_mesh(path, parts={"teeth_upper": "TeethUp", "teeth_lower": "TeethLow"})
    assert {k: v.size for k, v in mesh.parts.items()} == {
        k: source.parts[k].vertex_ids.size for k in PART_NAMES}
    result = setup_face(mesh, landmarks=_skin_marks(source, points=True), source=source,
                        report=True)
    assert result.carried == ("lashes",)  # lashes always come from the source
    eye = result.face.parts["eye_l"].vertex_ids
    assert np.allclose(result.face.vertices[eye].mean(axis=0), source.vertices[
        source.parts["eye_l"].vertex_ids].mean(axis=0), atol=1e-6)


def test_unit_is_detected_or_checked(cartoon) -> None:  # type: ignore[no-untyped-def]
    mesh, marks = cartoon
    in_mm = head_mesh(mesh.vertices * 1000, mesh.triangles)
    marks_mm = {k: [c * 1000 for c in v] for k, v in marks.items()}
    result = setup_face(in_mm, landmarks=marks_mm, report=True)
    assert result.unit == "mm"
    # the older name gives the same report; the public one without report=True the Face
    older = set_up_face(in_mm, landmarks=marks_mm)
    np.testing.assert_array_equal(older.face.vertices, result.face.vertices)
    plain = facelib.setup_face(in_mm, landmarks=marks_mm)
    assert isinstance(plain, Face)
    np.testing.assert_array_equal(plain.vertices, result.face.vertices)
    assert np.ptp(result.face.vertices[:, 1]) == pytest.approx(np.ptp(mesh.vertices[:, 1]),
                                                               rel=1e-6)
    with pytest.raises(FaceModelError, match="looks like it is in mm"):
        setup_face(in_mm, landmarks=marks_mm, unit="m")


def test_too_few_coplanar_or_duplicate_landmarks(source) -> None:  # type: ignore[no-untyped-def]
    mesh = _skin_only(source)
    marks = _skin_marks(source)
    with pytest.raises(FaceModelError, match="at least 4"):
        setup_face(mesh, landmarks=dict(list(marks.items())[:3]), source=source)
    same = dict(marks)
    same["9.3"] = same["2.1"]
    with pytest.raises(FaceModelError, match="same position"):
        setup_face(mesh, landmarks=same, source=source)
    flat = {k: [x, y, 0.1] for k, (x, y, _) in _skin_marks(source, points=True).items()}
    with pytest.raises(FaceModelError, match="one plane"):
        setup_face(mesh, landmarks=flat, source=source)
    with pytest.raises(FaceModelError, match="not a feature point"):
        setup_face(mesh, landmarks={**marks, "99.1": 3}, source=source)
    with pytest.raises(FaceModelError, match="outside 0-"):
        setup_face(mesh, landmarks={**marks, "9.3": 10**6}, source=source)


def test_landmark_off_the_surface(source) -> None:  # type: ignore[no-untyped-def]
    marks = _skin_marks(source, points=True)
    marks["9.3"] = [marks["9.3"][0], marks["9.3"][1], marks["9.3"][2] + 0.03]
    with pytest.raises(FaceModelError, match=r"landmark 9\.3 is 30\.\d mm off the mesh"):
        setup_face(_skin_only(source), landmarks=marks, source=source)


def test_bad_meshes(source, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    skin = source.parts["skin"]
    verts = source.vertices[: skin.vertex_ids.size]
    tris = skin.triangles
    fan = np.vstack([tris, [[tris[0, 0], tris[0, 1], 100]]])  # a third triangle on an edge
    with pytest.raises(FaceModelError, match="non-manifold"):
        head_mesh(verts, fan)
    flipped = tris.copy()
    flipped[:10] = flipped[:10, ::-1]
    with pytest.raises(FaceModelError, match="not wound consistently"):
        head_mesh(verts, flipped)
    soup = verts[tris].reshape(-1, 3)  # an unwelded triangle soup is welded, with a note
    welded = head_mesh(soup, np.arange(len(soup)).reshape(-1, 3))
    assert len(welded.vertices) == len(np.unique(verts[np.unique(tris)], axis=0))
    assert welded.repairs == (f"merged {len(soup) - len(welded.vertices)} duplicate vertices",)
    apart = soup + np.arange(len(soup))[:, None] * 1e-3  # no two vertices at one place
    with pytest.raises(FaceModelError, match="triangle soup"):
        head_mesh(apart, np.arange(len(apart)).reshape(-1, 3))
    with pytest.raises(FaceModelError, match="unknown mesh format"):
        load_head_mesh(tmp_path / "head.fbx")
    broken = tmp_path / "broken.ply"
    broken.write_text("ply\nthis is not a mesh\n")
    with pytest.raises(FaceModelError, match=r"broken\.ply"):
        load_head_mesh(broken)


@pytest.mark.render  # renders the set-up face
def test_cli_face_setup_then_render(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "cartoon"
    assert main(["face", "setup", str(HEADS / "cartoon_head.obj"), "--landmarks",
                 str(HEADS / "cartoon_landmarks.json"), "-o", str(out)]) == 0
    text = capsys.readouterr().err  # status lines go to stderr
    assert "eye_l, eye_r, teeth_upper, teeth_lower, tongue, lashes warped into place" in text
    face = load_face(out / "face.json")
    assert face.n_vertices > load_head_mesh(HEADS / "cartoon_head.obj").vertices.shape[0]
    story = tmp_path / "story.fdl"
    story.write_text(SMALL.read_text().replace("fps = 25", 'fps = 25\nface = "cartoon/face.json"'))
    from facelib.fdl import load

    assert load(story).face == (out / "face.json").resolve()
    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("rendering needs the render extra")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gif = tmp_path / "small.gif"
        assert main(["render", str(story), "-o", str(gif), "--width", "96", "--height",
                     "72", "--fps", "5"]) == 0
        assert gif.stat().st_size > 1000
        frames = tmp_path / "frames"
        assert main(["play", str(ROOT / "examples" / "fap" / "xface_smile.fap"), "--face",
                     str(out), "-o", str(frames), "--width", "96", "--height", "72",
                     "--fps", "2"]) == 0
        assert len(list(frames.glob("*.png"))) >= 2


def test_cli_bad_input_writes_nothing(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    marks = tmp_path / "few.json"
    marks.write_text(json.dumps({"9.3": 10, "2.1": 20, "4.1": 30}))
    out = tmp_path / "out"
    assert main(["face", "setup", str(HEADS / "cartoon_head.obj"), "--landmarks", str(marks),
                 "-o", str(out)]) == 1
    assert "at least 4" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow  # two face set-ups
def test_given_axes_turn_a_z_up_mesh(cartoon, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    mesh, marks = cartoon
    # a CAD-style copy: +z up, the face looking along -y
    to_cad = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    cad = mesh.rotated(to_cad)
    cad_marks = {k: (to_cad @ np.asarray(v)).tolist() for k, v in marks.items()}
    upright = setup_face(mesh, landmarks=marks)
    given = setup_face(cad, landmarks=cad_marks, up="+z", forward="-y", report=True)
    np.testing.assert_allclose(given.rotation, to_cad.T, atol=1e-12)
    np.testing.assert_allclose(given.face.vertices, upright.vertices, atol=1e-6)
    # guessed: the best rotation onto the default head's feature points, a few degrees
    # from the true one since the cartoon has other proportions
    guessed = setup_face(cad, landmarks=cad_marks, report=True).rotation @ to_cad
    assert np.degrees(np.arccos((np.trace(guessed) - 1) / 2)) < 5
    with pytest.raises(ParameterError, match="right angles"):
        setup_face(cad, landmarks=cad_marks, up="+z", forward="-z")
