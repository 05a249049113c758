"""Files a head mesh refers to (glTF buffers and images, an OBJ's material library and its
textures, a PLY's texture) must stay inside the mesh's folder: absolute paths, ``..``,
symbolic links out, folders, devices and oversized files are refused with an error naming
the mesh and the reference, before any byte of them is read."""

from __future__ import annotations

import base64
import json
import os
import struct
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("trimesh")

from facelib.engine.setup.headmesh import load_head_mesh
from facelib.errors import FaceModelError

VERTS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
TRIS = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.uint32)
# the smallest valid PNG (1 x 1, one red pixel), to make an image reference readable
PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGP4z8AAAAMBAQDJ/pLvAAAAAElFTkSu"
    "QmCC")


def _gltf(buffer_uri: str | None, *, image_uri: str | None = None) -> tuple[dict, bytes]:
    """A glTF document of a closed tetrahedron and its one buffer's bytes."""
    data = VERTS.tobytes() + TRIS.tobytes()
    doc: dict = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "head"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(data)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": VERTS.nbytes},
                        {"buffer": 0, "byteOffset": VERTS.nbytes, "byteLength": TRIS.nbytes}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5125, "count": 12, "type": "SCALAR"}],
    }
    if buffer_uri is not None:
        doc["buffers"][0]["uri"] = buffer_uri
    if image_uri is not None:
        doc["images"] = [{"uri": image_uri}]
        doc["textures"] = [{"source": 0}]
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["meshes"][0]["primitives"][0]["material"] = 0
    return doc, data


def _glb(doc: dict, binary: bytes) -> bytes:
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = (struct.pack("<I4s", len(text), b"JSON") + text
            + struct.pack("<I4s", len(binary), b"BIN\0") + binary)
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def _obj(mtllib: str) -> str:
    lines = [f"mtllib {mtllib}", "o head"]
    lines += [f"v {x} {y} {z}" for x, y, z in VERTS]
    lines += ["usemtl skin"]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in TRIS]
    return "\n".join(lines) + "\n"


@pytest.fixture
def folders(tmp_path: Path) -> tuple[Path, Path]:
    """(the mesh's folder, a folder beside it holding a 'secret' buffer, image and mtl)."""
    home = tmp_path / "mesh"
    home.mkdir()
    secret = tmp_path / "secret"
    secret.mkdir()
    _, data = _gltf(None)
    (secret / "data.bin").write_bytes(data)
    (secret / "red.png").write_bytes(PNG)
    (secret / "skin.mtl").write_text("newmtl skin\nKd 1 0 0\nmap_Kd red.png\n")
    return home, secret


def test_references_inside_the_folder_still_load(folders: tuple[Path, Path]) -> None:
    home, _ = folders
    doc, data = _gltf("data.bin", image_uri="tex/red.png")
    (home / "data.bin").write_bytes(data)
    (home / "tex").mkdir()
    (home / "tex" / "red.png").write_bytes(PNG)
    (home / "head.gltf").write_text(json.dumps(doc))
    mesh = load_head_mesh(home / "head.gltf")
    np.testing.assert_allclose(mesh.vertices, VERTS)
    # an embedded (data:) buffer needs no file at all
    doc, data = _gltf("data:application/octet-stream;base64," + base64.b64encode(data).decode())
    (home / "embedded.gltf").write_text(json.dumps(doc))
    np.testing.assert_allclose(load_head_mesh(home / "embedded.gltf").vertices, VERTS)
    # a symbolic link that stays inside is fine
    (home / "alias.bin").symlink_to("data.bin")
    doc, _ = _gltf("alias.bin")
    (home / "alias.gltf").write_text(json.dumps(doc))
    np.testing.assert_allclose(load_head_mesh(home / "alias.gltf").vertices, VERTS)
    (home / "skin.mtl").write_text("newmtl skin\nKd 1 0 0\n")
    (home / "head.obj").write_text(_obj("skin.mtl"))
    assert len(load_head_mesh(home / "head.obj").vertices) == 4


@pytest.mark.parametrize(("kind", "message"), [
    ("gltf-buffer-absolute", "absolute"),
    ("gltf-buffer-dotdot", "leaves"),
    ("gltf-buffer-symlink-out", "leaves"),
    ("gltf-buffer-url", "scheme"),
    ("gltf-image-absolute", "absolute"),
    ("gltf-image-dotdot", "leaves"),
    ("glb-buffer-absolute", "absolute"),
    ("glb-image-dotdot", "leaves"),
    ("obj-mtllib-dotdot", "leaves"),
    ("obj-mtllib-etc-passwd", "leaves"),
    ("obj-mtllib-absolute", "absolute"),
    ("obj-texture-dotdot", "leaves"),
    ("gltf-buffer-folder", "not a regular file"),
    ("gltf-buffer-device", "absolute"),
    ("gltf-buffer-fifo", "not a regular file"),
])
def test_references_outside_the_folder_are_refused(folders: tuple[Path, Path], kind: str,
                                                   message: str) -> None:
    home, secret = folders
    _, data = _gltf(None)
    target = home / "head.gltf"
    reference = ""
    if kind.startswith(("gltf-buffer", "glb-buffer")):
        reference = {"gltf-buffer-absolute": str(secret / "data.bin"),
                     "gltf-buffer-dotdot": "../secret/data.bin",
                     "gltf-buffer-symlink-out": "link.bin",
                     "gltf-buffer-url": "file:///" + str(secret / "data.bin"),
                     "gltf-buffer-folder": "sub",
                     "gltf-buffer-device": "/dev/zero",
                     "gltf-buffer-fifo": "pipe.bin",
                     "glb-buffer-absolute": str(secret / "data.bin")}[kind]
        (home / "link.bin").symlink_to(secret / "data.bin")
        (home / "sub").mkdir()
        os.mkfifo(home / "pipe.bin")
        doc, _ = _gltf(reference)
        if kind.startswith("glb"):
            target = home / "head.glb"
            target.write_bytes(_glb(doc, b""))
        else:
            target.write_text(json.dumps(doc))
    elif kind.startswith(("gltf-image", "glb-image")):
        reference = str(secret / "red.png") if kind.endswith("absolute") else "../secret/red.png"
        doc, _ = _gltf(None if kind.startswith("glb") else "data.bin", image_uri=reference)
        (home / "data.bin").write_bytes(data)
        if kind.startswith("glb"):
            target = home / "head.glb"
            target.write_bytes(_glb(doc, data))
        else:
            target.write_text(json.dumps(doc))
    else:
        reference = {"obj-mtllib-dotdot": "../secret/skin.mtl",
                     "obj-mtllib-etc-passwd": "../../../../../../../../etc/passwd",
                     "obj-mtllib-absolute": str(secret / "skin.mtl"),
                     "obj-texture-dotdot": "skin.mtl"}[kind]
        if kind == "obj-texture-dotdot":
            (home / "skin.mtl").write_text("newmtl skin\nmap_Kd ../secret/red.png\n")
            reference = "../secret/red.png"
            (home / "head.obj").write_text(_obj("skin.mtl"))
        else:
            (home / "head.obj").write_text(_obj(reference))
        target = home / "head.obj"
    with pytest.raises(FaceModelError, match=message) as info:
        load_head_mesh(target)
    assert info.value.path == str(target)
    assert repr(reference) in info.value.message or reference in info.value.message


def test_referenced_files_are_bounded(folders: tuple[Path, Path],
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    home, _ = folders
    doc, data = _gltf("data.bin")
    (home / "data.bin").write_bytes(data + b"\0" * 1000)
    (home / "head.gltf").write_text(json.dumps(doc))
    from facelib.engine import mesh_files

    monkeypatch.setattr(mesh_files, "MAX_REFERENCE_BYTES", len(data) + 10)
    with pytest.raises(FaceModelError, match="larger than"):
        load_head_mesh(home / "head.gltf")


def test_the_mesh_itself_must_be_a_regular_file(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "head.obj")
    with pytest.raises(FaceModelError, match="not a regular file"):
        load_head_mesh(tmp_path / "head.obj")
    (tmp_path / "dir.obj").mkdir()
    with pytest.raises(FaceModelError, match="not a regular file"):
        load_head_mesh(tmp_path / "dir.obj")
