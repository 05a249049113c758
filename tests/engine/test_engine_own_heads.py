"""Own heads as people have them (issue 38): mesh faults repaired with a note, OBJ objects
and groups read as parts, left and right told by the face's own midline, the documented
``--up +z --forward -y`` spelling, and lashes reported as carried."""

from __future__ import annotations

import importlib.util
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from facelib.cli import main
from facelib.engine import load_face
from facelib.engine.setup.headmesh import head_mesh, load_head_mesh

pytest.importorskip("trimesh")

ROOT = Path(__file__).resolve().parents[2]
HEADS = ROOT / "examples" / "heads"
SHIFT = np.array([0.048, 0.0, 0.0])  # the midline 4.8 cm off x = 0


def _sphere(centre: np.ndarray, radius: float, n: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """A closed UV sphere ``(V, 3)``, ``(F, 3)`` wound outwards."""
    m = 2 * n
    rings = [centre + radius * np.array([np.sin(a) * np.cos(b), np.cos(a), np.sin(a) * np.sin(b)])
             for a in np.linspace(0, np.pi, n + 1)[1:-1]
             for b in np.linspace(0, 2 * np.pi, m, endpoint=False)]
    pole = np.array([0.0, radius, 0.0])
    verts = np.array([centre + pole, *rings, centre - pole])
    tris = [[0, 1 + (j + 1) % m, 1 + j] for j in range(m)]
    for i in range(n - 2):
        for j in range(m):
            a, b = 1 + i * m + j, 1 + i * m + (j + 1) % m
            tris += [[a, b, b + m], [a, b + m, a + m]]
    last, base = len(verts) - 1, 1 + (n - 2) * m
    tris += [[last, base + j, base + (j + 1) % m] for j in range(m)]
    return verts, np.array(tris)


def _obj_lines(name: str, verts: np.ndarray, tris: np.ndarray, offset: int,
               keyword: str = "o") -> list[str]:
    return ([f"{keyword} {name}"] + [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in verts]
            + [f"f {a + 1 + offset} {b + 1 + offset} {c + 1 + offset}" for a, b, c in tris])


# where the cartoon's eyeballs sit once set up (the carried default eyes), and their radius
_EYES = {"eye_l": np.array([0.0307, 0.0311, 0.1148]), "eye_r": np.array([-0.0307, 0.0311,
                                                                          0.1148])}
_EYE_RADIUS = 0.0142


@pytest.fixture(scope="module")
def user_head(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A user's OBJ: the cartoon skin moved 4.8 cm in x, ``o eye_l`` and ``o eye_r``
    eyeballs, 30 triangles with a repeated vertex and one triangle present twice."""
    folder = tmp_path_factory.mktemp("user")
    skin = load_head_mesh(HEADS / "cartoon_head.obj")
    verts = skin.vertices + SHIFT
    rng = np.random.default_rng(38)
    bad = [[a, a, b] for a, b in rng.integers(0, len(verts), (30, 2))]
    tris = np.concatenate([skin.triangles, bad, skin.triangles[:1]])
    lines = ["# exported by someone else's tool", *_obj_lines("skin", verts, tris, 0)]
    offset = len(verts)
    for name, centre in _EYES.items():
        ev, et = _sphere(centre + SHIFT, _EYE_RADIUS)
        lines += _obj_lines(name, ev, et, offset)
        offset += len(ev)
    mesh = folder / "my_head.obj"
    mesh.write_text("\n".join(lines) + "\n")
    marks = json.loads((HEADS / "cartoon_landmarks.json").read_text())["landmarks"]
    moved = folder / "my_landmarks.json"
    moved.write_text(json.dumps({"landmarks": {k: (np.array(p) + SHIFT).tolist()
                                               for k, p in marks.items()}}))
    return mesh, moved


def test_degenerate_and_duplicate_triangles_are_repaired_with_a_note():
    verts, tris = _sphere(np.zeros(3), 1.0)
    faulty = np.concatenate([tris, [[0, 0, 5], [3, 7, 7]], tris[:1], tris[1:2, ::-1]])
    mesh = head_mesh(verts, faulty, name="ball.obj")
    assert mesh.repairs == ("dropped 2 zero-area triangles", "dropped 2 duplicate triangles")
    np.testing.assert_array_equal(mesh.triangles, tris)
    # the same place twice in one part: merged, the triangles re-indexed onto the first
    doubled = np.concatenate([verts, verts[:1]])
    moved = tris.copy()
    moved[moved == 0] = len(verts)
    merged = head_mesh(doubled, np.concatenate([tris[:len(tris) // 2], moved[len(tris) // 2:]]))
    assert merged.repairs == ("merged 1 duplicate vertices",)
    assert len(merged.vertices) == len(verts)
    assert head_mesh(verts, tris).repairs == ()


def test_obj_objects_and_groups_are_parts(tmp_path):
    ball, tris = _sphere(np.zeros(3), 1.0)
    lines = _obj_lines("face", ball * 10, tris, 0)
    lines += _obj_lines("LeftEyeball", ball + np.array([3.0, 2.0, 8.0]), tris, len(ball),
                        keyword="g")
    lines += _obj_lines("RightEyeball", ball + np.array([-3.0, 2.0, 8.0]), tris, 2 * len(ball),
                        keyword="g")
    path = tmp_path / "head.obj"
    path.write_text("\n".join(lines) + "\n")
    mesh = load_head_mesh(path)
    assert sorted(mesh.parts) == ["eye_l", "eye_r", "skin"]
    assert mesh.vertices[mesh.parts["eye_l"]][:, 0].mean() == pytest.approx(3.0)
    named = load_head_mesh(path, parts={"eye_l": "RightEyeball", "eye_r": "LeftEyeball"})
    assert named.vertices[named.parts["eye_l"]][:, 0].mean() == pytest.approx(-3.0)


def test_eyes_are_told_apart_by_the_face_midline(user_head):
    mesh = load_head_mesh(user_head[0])
    left, right = (mesh.vertices[mesh.parts[p]][:, 0].mean() for p in ("eye_l", "eye_r"))
    assert right > 0 and left > right  # both on +x, yet one of each
    assert left == pytest.approx(0.0307 + 0.048, abs=1e-4)


def test_a_user_head_sets_up_and_renders_with_its_own_eyes(user_head, tmp_path, capsys):
    mesh_file, marks = user_head
    out = tmp_path / "face"
    assert main(["face", "setup", str(mesh_file), "--landmarks", str(marks), "-o", str(out),
                 "--part", "eye_l=eye_l", "--part", "eye_r=eye_r"]) == 0
    err = capsys.readouterr().err
    assert "repaired:  dropped 30 zero-area triangles; dropped 1 duplicate triangles" in err
    assert ("parts:     skin, eye_l, eye_r from the mesh; teeth_upper, teeth_lower, tongue, "
            "lashes warped into place") in err
    face = load_face(out / "face.json")
    sphere_vertices = len(_sphere(np.zeros(3), 1.0)[0])
    for part, sign in (("eye_l", 1), ("eye_r", -1)):
        ids = face.parts[part].vertex_ids
        assert ids.size == sphere_vertices
        centre = face.vertices[ids].mean(axis=0)
        np.testing.assert_allclose(centre, _EYES[part] + SHIFT, atol=1e-3)
        assert np.sign(centre[0] - 0.048) == sign
    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("rendering needs the render extra")
    story = tmp_path / "story.fdl"
    story.write_text('fps = 2\nface = "face/face.json"\nshow { "joy", at = 0, dur = 1 }\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["render", str(story), "-o", str(tmp_path / "frames"), "--width", "96",
                     "--height", "96"]) == 0
    assert len(list((tmp_path / "frames").glob("*.png"))) >= 2


def test_axis_values_starting_with_a_minus_are_accepted(tmp_path, capsys):
    missing = tmp_path / "none.obj"
    code = main(["face", "setup", str(missing), "--landmarks", "x.json", "-o", str(tmp_path),
                 "--up", "+z", "--forward", "-y"])
    err = capsys.readouterr().err
    assert code == 1 and "expected one argument" not in err and "none.obj" in err
