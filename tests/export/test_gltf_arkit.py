"""``export_gltf(..., targets="arkit")`` / ``facelib export --targets arkit``: the 52
ARKit-named morph targets of the head (the default head and an own head from face set-up),
weighted by the stream's ARKit curves."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from gltf_eval import Gltf, busy_stream

from facelib import FapStream
from facelib.engine import default_face
from facelib.errors import ParameterError
from facelib.export import export_gltf, from_arkit, to_arkit
from facelib.export.arkit_targets import arkit_recipes, arkit_target_names
from facelib.export.gltf import primitive_vertex_ids
from facelib.mpeg4 import fap

WEB = Path(__file__).parents[2] / "facelib" / "export" / "web"
pytestmark = pytest.mark.slow  # 52 targets on two heads, one set up: about 40 s
HEADS = Path(__file__).parents[2] / "examples" / "heads"
needs_node = pytest.mark.skipif(shutil.which("node") is None or not (WEB / "node_modules").exists(),
                                reason="needs node and the npm packages (make setup)")


def _stream() -> FapStream:
    """busy_stream (jaw, lids, eyes, head) with lips of both signs."""
    busy = busy_stream()
    values = busy.values.copy()
    t = np.linspace(0, 1, busy.n_frames)
    values[:, fap("raise_b_midlip").index] = 300 * np.cos(np.pi * t)
    values[:, fap("raise_l_cornerlip").index] = 400 * np.sin(np.pi * t)
    return FapStream(busy.fps, values, busy.mask, busy.viseme, busy.expression)


@pytest.fixture(scope="module")
def cartoon():
    from facelib.engine.setup import read_landmarks, setup_face

    return setup_face(HEADS / "cartoon_head.obj",
                      landmarks=read_landmarks(HEADS / "cartoon_landmarks.json"))


@pytest.fixture(scope="module")
def exported(tmp_path_factory, cartoon):
    folder = tmp_path_factory.mktemp("arkit_glb")
    return {name: export_gltf(_stream(), folder / f"{name}.glb", face=face, targets="arkit")
            for name, face in (("default", None), ("cartoon", cartoon))}


def _animated_weights(gltf: Gltf, n: int) -> np.ndarray:
    return np.stack([(gltf.local_matrices(i), gltf.weights)[1] for i in range(n)])


def test_52_arkit_named_targets_weighted_by_the_arkit_curves(exported):
    result = exported["default"]
    names = arkit_target_names()
    assert len(names) == 52 and names[0] == "eyeBlinkLeft" and names[17] == "jawOpen"
    assert result.names == names and result.targets == ()
    gltf = Gltf(result.path)
    assert gltf.g.meshes[0].extras["targetNames"] == list(names)
    assert gltf.g.asset.extras["facelib"]["targets"] == "arkit"
    curves = to_arkit(_stream())
    got = _animated_weights(gltf, result.n_frames)
    np.testing.assert_allclose(got, curves.weights, atol=1e-6)
    assert got.min() >= 0 and got.max() <= 1 and got[:, names.index("jawOpen")].max() > 0.1


def test_the_file_plays_what_the_arkit_round_trip_plays(exported):
    """Evaluated as glTF specifies, each frame is ``Face.deform`` of
    ``from_arkit(to_arkit(stream))``: exact but for the rotations inside the targets (jaw,
    lids, eyes), which a morph target follows along the chord."""
    face = default_face()
    want = face.deform(from_arkit(to_arkit(_stream())))
    gltf = Gltf(exported["default"].path)
    worst = {}
    for frame in (0, 3, 6, 9, 11):
        for name, got in zip(face.parts, gltf.evaluate(frame), strict=True):
            ids = primitive_vertex_ids(face.parts[name])
            worst[name] = max(worst.get(name, 0.0), float(np.abs(got - want[frame][ids]).max()))
    print({k: f"{1000 * v:.2f} mm" for k, v in worst.items()})
    assert worst["skin"] < 2e-3 and worst["teeth_upper"] < 1e-5
    assert max(worst.values()) < 3e-3
    # the animation is real: frame 6 moves the skin by millimetres
    assert np.abs(want[6] - face.vertices).max() > 0.005


def test_own_heads_targets_move_their_own_parts(exported, cartoon):
    """The cartoon's eyeBlinkLeft closes its left upper lid, jawOpen drops its chin,
    eyeLookOutLeft turns its left eyeball toward +x."""
    result = exported["cartoon"]
    names = arkit_target_names()
    assert result.names == names
    gltf = Gltf(result.path)
    face = cartoon
    rest = face.vertices
    recipes = arkit_recipes()
    fp = face.feature_points
    for name, point, axis, sign in (("eyeBlinkLeft", "3.1", 1, -1), ("jawOpen", "2.1", 1, -1),
                                    ("eyeLookOutLeft", "3.5", 0, 1)):
        moved = face.deform_frame(recipes[names.index(name)])
        assert sign * (moved[fp[point], axis] - rest[fp[point], axis]) > 1e-3, name
    skin = list(face.parts).index("skin")
    prim = gltf.g.meshes[skin].primitives[0]
    blink = gltf.accessor(prim.targets[names.index("eyeBlinkLeft")]["POSITION"])
    ids = np.sort(face.parts["skin"].vertex_ids)
    lid = int(np.searchsorted(ids, fp["3.1"]))
    assert blink[lid, 1] < -1e-3  # the file's target holds the same drop


@needs_node
@pytest.mark.parametrize("name", ["default", "cartoon"])
def test_gltf_validator_reports_no_issue(exported, name):
    run = subprocess.run(["node", str(WEB / "tools" / "validate.mjs"),
                          str(exported[name].path)], capture_output=True, text=True, check=False)
    report = json.loads(run.stdout)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"][:5]


def test_cli_and_bad_kind(tmp_path):
    from facelib.cli import main
    from facelib.mpeg4.fapfile import write_fap_complete

    fap_path = tmp_path / "s.fap"
    write_fap_complete(_stream(), fap_path)
    out = tmp_path / "s.glb"
    assert main(["export", str(fap_path), "-o", str(out), "--targets", "arkit"]) == 0
    assert Gltf(out).g.meshes[0].extras["targetNames"] == list(arkit_target_names())
    with pytest.raises(ParameterError, match="targets"):
        export_gltf(_stream(), tmp_path / "x.glb", targets="visemes")
