"""VRM 1.0 export: the file read back with a reader written here from the GLB container
layout (glTF 2.0 section "Binary glTF Layout") and the VRMC_vrm-1.0 specification (json and
struct only, no glTF library): presets bind existing morph targets, ``aa`` opens the jaw and
lips as the viseme does on the head, the humanoid has the bones VRM requires in the order it
requires, and the glTF-Validator finds no error."""

import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

from facelib import FapStream, ParameterError
from facelib.engine import default_face
from facelib.export import export_vrm
from facelib.mpeg4.visemes import viseme_id
from facelib.visemes.tables import viseme_targets

WEB = Path(__file__).parents[2] / "facelib" / "export" / "web"
PRESETS = ("aa", "ih", "ou", "ee", "oh", "blink", "blinkLeft", "blinkRight", "happy", "angry",
           "sad", "relaxed", "surprised", "lookUp", "lookDown", "lookLeft", "lookRight")
# VRMC_vrm-1.0 humanoid.md: required bones and each bone's parent bone
PARENT = {"spine": "hips", "chest": "spine", "neck": "chest", "head": "neck", "leftEye": "head",
          "rightEye": "head", "jaw": "head", "leftUpperLeg": "hips",
          "leftLowerLeg": "leftUpperLeg", "leftFoot": "leftLowerLeg", "rightUpperLeg": "hips",
          "rightLowerLeg": "rightUpperLeg", "rightFoot": "rightLowerLeg",
          "leftUpperArm": "chest", "leftLowerArm": "leftUpperArm", "leftHand": "leftLowerArm",
          "rightUpperArm": "chest", "rightLowerArm": "rightUpperArm",
          "rightHand": "rightLowerArm"}
REQUIRED = {"hips", "spine", "head", "leftUpperLeg", "leftLowerLeg", "leftFoot",
            "rightUpperLeg", "rightLowerLeg", "rightFoot", "leftUpperArm", "leftLowerArm",
            "leftHand", "rightUpperArm", "rightLowerArm", "rightHand"}


class Glb:
    """A ``.glb``: the JSON chunk and the BIN chunk, accessors read with numpy."""

    def __init__(self, path: Path):
        raw = path.read_bytes()
        magic, version, length = struct.unpack_from("<4sII", raw, 0)
        assert magic == b"glTF" and version == 2 and length == len(raw)
        size, kind = struct.unpack_from("<II", raw, 12)
        assert kind == 0x4E4F534A  # "JSON"
        self.doc = json.loads(raw[20:20 + size])
        bin_size, bin_kind = struct.unpack_from("<II", raw, 20 + size)
        assert bin_kind == 0x004E4942  # "BIN\0"
        self.bin = raw[28 + size:28 + size + bin_size]

    def _view(self, index: int, dtype: str, count: int, offset: int = 0) -> np.ndarray:
        view = self.doc["bufferViews"][index]
        start = view.get("byteOffset", 0) + offset
        return np.frombuffer(self.bin, dtype, count, start)

    def accessor(self, index: int) -> np.ndarray:
        acc = self.doc["accessors"][index]
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[acc["type"]]
        dtype = {5126: "<f4", 5123: "<u2", 5125: "<u4"}[acc["componentType"]]
        if "bufferView" in acc:
            out = self._view(acc["bufferView"], dtype, acc["count"] * width,
                             acc.get("byteOffset", 0)).reshape(acc["count"], width).copy()
        else:
            out = np.zeros((acc["count"], width), dtype)
        if "sparse" in acc:
            sp = acc["sparse"]
            ids = self._view(sp["indices"]["bufferView"],
                             {5123: "<u2", 5125: "<u4"}[sp["indices"]["componentType"]],
                             sp["count"])
            out[ids] = self._view(sp["values"]["bufferView"], dtype,
                                  sp["count"] * width).reshape(-1, width)
        return out


@pytest.fixture(scope="module")
def vrm(tmp_path_factory):
    out = tmp_path_factory.mktemp("vrm") / "head.vrm"
    result = export_vrm(FapStream.zeros(2, fps=25), out)
    return result, Glb(out)


def test_extension_header_meta_and_presets_bind_existing_targets(vrm):
    result, glb = vrm
    ext = glb.doc["extensions"]["VRMC_vrm"]
    assert "VRMC_vrm" in glb.doc["extensionsUsed"] and ext["specVersion"] == "1.0"
    meta = ext["meta"]
    assert meta["name"] and any(meta["authors"])
    assert meta["licenseUrl"] == "https://vrm.dev/licenses/1.0/"
    assert meta["avatarPermission"] in ("onlyAuthor", "onlySeparatelyLicensedPerson", "everyone")
    assert "MIT" in meta["copyrightInformation"] and meta["otherLicenseUrl"]
    preset = ext["expressions"]["preset"]
    assert set(preset) == set(PRESETS) and result.presets == tuple(preset)
    # one mesh node per part, named for it; every preset binds its target on each of them
    face = default_face()
    mesh_nodes = [i for i, n in enumerate(glb.doc["nodes"]) if "mesh" in n]
    assert [glb.doc["nodes"][i]["name"] for i in mesh_nodes] == list(face.parts)
    assert result.parts == tuple(face.parts)
    names = None
    for name, expression in preset.items():
        binds = expression["morphTargetBinds"]
        assert [b["node"] for b in binds] == mesh_nodes, name
        assert len({b["index"] for b in binds}) == 1, name
        for bind in binds:
            node = glb.doc["nodes"][bind["node"]]
            mesh = glb.doc["meshes"][node["mesh"]]
            names = mesh["extras"]["targetNames"]
            assert all(0 <= bind["index"] < len(p["targets"]) for p in mesh["primitives"])
            assert names[bind["index"]] == name and 0 < bind["weight"] <= 1
    assert names is not None and "animations" not in glb.doc  # VRM uses no animations


def _skin_primitive(glb):
    node = next(n for n in glb.doc["nodes"] if n.get("name") == "skin" and "mesh" in n)
    (prim,) = glb.doc["meshes"][node["mesh"]]["primitives"]
    skin = next(i for i, m in enumerate(glb.doc["materials"]) if m["name"] == "skin")
    assert prim["material"] == skin
    return prim


def _nearest(positions, point):
    return int(np.argmin(np.linalg.norm(positions - point, axis=1)))


def test_aa_opens_the_jaw_and_lips_as_the_viseme_does(vrm):
    """Weight 1 of ``aa`` moves the skin as ``Face.deform`` of viseme aa does: the lower lip
    (feature point 8.2) and the chin (2.1) drop by millimetres, the upper lip (8.1) far less."""
    _, glb = vrm
    face = default_face()
    prim = _skin_primitive(glb)
    index = glb.doc["extensions"]["VRMC_vrm"]["expressions"]["preset"]["aa"][
        "morphTargetBinds"][0]["index"]
    rest = glb.accessor(prim["attributes"]["POSITION"])
    moved = glb.accessor(prim["targets"][index]["POSITION"])
    want = face.deform_frame(viseme_targets()[viseme_id("aa")]) - face.vertices
    drop = {}
    for point in ("8.1", "8.2", "2.1"):
        vid = face.feature_points[point]
        k = _nearest(rest, face.vertices[vid])
        np.testing.assert_allclose(moved[k], want[vid], atol=1e-6)
        drop[point] = -float(moved[k, 1])
    print({k: f"{1000 * v:.2f} mm" for k, v in drop.items()})
    assert drop["8.2"] > 0.004 and drop["2.1"] > 0.004 and drop["8.1"] < 0.5 * drop["8.2"]


def test_blink_left_closes_only_the_left_lid(vrm):
    _, glb = vrm
    prim = _skin_primitive(glb)
    preset = glb.doc["extensions"]["VRMC_vrm"]["expressions"]["preset"]
    rest = glb.accessor(prim["attributes"]["POSITION"])
    for name, sign in (("blinkLeft", 1), ("blinkRight", -1)):
        moved = glb.accessor(prim["targets"][preset[name]["morphTargetBinds"][0]["index"]][
            "POSITION"])
        big = np.linalg.norm(moved, axis=1) > 1e-3
        assert big.sum() > 20 and np.all(np.sign(rest[big, 0]) == sign), name
        assert moved[big, 1].mean() < 0  # the upper lid comes down


def _world(glb, index, parents):
    t = np.zeros(3)
    while index is not None:
        node = glb.doc["nodes"][index]
        assert node.get("rotation", [0, 0, 0, 1]) == [0, 0, 0, 1] and "scale" not in node
        t = t + np.asarray(node.get("translation", [0, 0, 0]))
        index = parents.get(index)
    return t


def test_humanoid_has_the_required_bones_in_the_required_order(vrm):
    _, glb = vrm
    face = default_face()
    bones = {b: v["node"] for b, v in
             glb.doc["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"].items()}
    assert set(bones) >= REQUIRED and len(set(bones.values())) == len(bones)
    parents = {c: i for i, n in enumerate(glb.doc["nodes"]) for c in n.get("children", [])}
    by_node = {v: k for k, v in bones.items()}
    for bone, node in bones.items():
        up = parents.get(node)
        while up is not None and up not in by_node:  # non-humanoid nodes may sit between
            up = parents.get(up)
        assert (by_node[up] if up is not None else None) == PARENT.get(bone), bone
    # the scene root is not a bone; hips hang below it; the body stands under the head
    root = glb.doc["scenes"][0]["nodes"]
    assert parents.get(bones["hips"]) in root and bones["hips"] not in root
    np.testing.assert_allclose(_world(glb, bones["head"], parents), face.pivots["head"],
                               atol=1e-6)
    np.testing.assert_allclose(_world(glb, bones["leftEye"], parents), face.pivots["eye_l"],
                               atol=1e-6)
    assert _world(glb, bones["leftFoot"], parents)[1] < -1.2
    assert _world(glb, bones["leftHand"], parents)[0] > 0.5  # the model's left is +x
    look = glb.doc["extensions"]["VRMC_vrm"]["lookAt"]
    assert look["type"] == "bone" and look["offsetFromHeadBone"][2] > 0.05
    first = glb.doc["extensions"]["VRMC_vrm"]["firstPerson"]["meshAnnotations"]
    mesh_nodes = [i for i, n in enumerate(glb.doc["nodes"]) if "mesh" in n]
    assert first == [{"node": i, "type": "auto"} for i in mesh_nodes]
    assert len(mesh_nodes) == len(face.parts)


def test_refuses_other_suffixes_and_meta_without_author(tmp_path):
    with pytest.raises(ParameterError, match=r"\.vrm"):
        export_vrm(FapStream.zeros(1, fps=25), tmp_path / "a.glb")
    with pytest.raises(ParameterError, match="author"):
        export_vrm(FapStream.zeros(1, fps=25), tmp_path / "a.vrm", meta={"authors": [""]})


@pytest.mark.skipif(shutil.which("node") is None or not (WEB / "node_modules").exists(),
                    reason="needs node and the npm packages (make setup)")
def test_gltf_validator_reports_no_error_or_warning(vrm):
    """The Khronos validator does not know VRMC_vrm (an info); the glTF under it is clean
    but for the skin's texture coordinates, which no texture of the file uses (an info: they
    are there for the user's own texture)."""
    result, _ = vrm
    run = subprocess.run(["node", str(WEB / "tools" / "validate.mjs"), str(result.path)],
                         capture_output=True, text=True, check=False)
    report = json.loads(run.stdout)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"][:5]
    codes = {m["code"] for m in report["messages"]
             if not (m["code"] == "UNUSED_OBJECT" and m["pointer"].endswith("/TEXCOORD_0"))}
    assert codes <= {"UNSUPPORTED_EXTENSION", "NODE_EMPTY"}, codes
