"""A storyboard's face file is checked before it is trusted (issue 38, class 11): its mesh
path stays inside its folder, a tiny ``.npz`` cannot declare a huge shape (2.18 TiB was
asked for), and deeply nested JSON is a clear error, not a RecursionError."""

from __future__ import annotations

import io
import json
import shutil
import zipfile
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from facelib import fdl
from facelib.cli import main
from facelib.engine import load_face
from facelib.errors import FaceModelError

HEAD = Path(str(resources.files("facelib.data").joinpath("head")))


def _definition(folder: Path, mesh: str) -> Path:
    doc = json.loads((HEAD / "default_head.json").read_text())
    doc["mesh"] = mesh
    out = folder / "face.json"
    out.write_text(json.dumps(doc))
    return out


@pytest.mark.parametrize("kind", ["absolute", "dotdot", "symlink", "folder"])
def test_the_mesh_must_stay_inside_the_definition_folder(tmp_path, kind):
    outside = tmp_path / "outside"
    outside.mkdir()
    shutil.copy(HEAD / "default_head.npz", outside / "head.npz")
    face_dir = tmp_path / "face"
    face_dir.mkdir()
    mesh = {"absolute": str(outside / "head.npz"), "dotdot": "../outside/head.npz",
            "symlink": "link.npz", "folder": "sub"}[kind]
    (face_dir / "link.npz").symlink_to(outside / "head.npz")
    (face_dir / "sub").mkdir()
    with pytest.raises(FaceModelError, match=r"face.json: mesh .* (must be a relative|leads "
                                             r"outside|not a regular file)"):
        load_face(_definition(face_dir, mesh))


def _npz_declaring(path: Path, shape: tuple[int, ...]) -> Path:
    """An .npz whose 'vertices' member claims ``shape`` float32 but holds 12 bytes."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f4", "fortran_order": False, "shape": shape})
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("vertices.npy", header.getvalue() + b"\0" * 12)
        for name in ("triangles", "vertex_colors"):
            buffer = io.BytesIO()
            np.save(buffer, np.zeros((1, 3), np.int32))
            archive.writestr(f"{name}.npy", buffer.getvalue())
    return path


def test_a_tiny_npz_declaring_a_huge_shape_is_refused(tmp_path):
    _npz_declaring(tmp_path / "huge.npz", (200_000_000_000, 3))
    assert (tmp_path / "huge.npz").stat().st_size < 1000
    with pytest.raises(FaceModelError, match=r"huge.npz: array 'vertices.npy' declares shape "
                                             r"\(200000000000, 3\)"):
        load_face(_definition(tmp_path, "huge.npz"))


def test_deep_json_is_a_clear_error(tmp_path):
    deep = tmp_path / "face.json"
    deep.write_text("[" * 200_000 + "]" * 200_000)
    with pytest.raises(FaceModelError, match="nested too deeply"):
        load_face(deep)


def test_a_storyboard_with_a_hostile_face_fails_cleanly(tmp_path, capsys):
    _npz_declaring(tmp_path / "huge.npz", (200_000_000_000, 3))
    _definition(tmp_path, "huge.npz")
    story = tmp_path / "story.fdl"
    story.write_text('face = "face.json"\nshow { "joy", at = 0, dur = 0.2 }\n')
    assert fdl.load(story).face is not None
    assert main(["render", str(story), "-o", str(tmp_path / "out.png")]) != 0
    err = capsys.readouterr().err
    assert "declares shape" in err and "Traceback" not in err
    assert not any(p.suffix == ".png" for p in tmp_path.iterdir())


def test_the_default_head_still_loads():
    assert load_face().vertices.shape[1] == 3
