"""VRM animation export: the preset fit recovers known mixes (a closed loop), the file's
layout follows VRMC_vrm_animation-1.0 (read with pygltflib, not facelib), the glTF-Validator
finds nothing wrong, and @pixiv/three-vrm with @pixiv/three-vrm-animation in headless
Chromium plays it on facelib's VRM avatar with the weights, head turn and look-at written."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from gltf_eval import Gltf
from scipy.spatial.transform import Rotation

from facelib import FapStream, ParameterError
from facelib.engine import default_face
from facelib.export import export_vrm, export_vrma
from facelib.export.vrm_presets import preset_names, preset_recipes
from facelib.export.vrma import animated_presets, preset_weights
from facelib.mpeg4 import fap

WEB = Path(__file__).parents[2] / "facelib" / "export" / "web"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
NEEDS_NODE = pytest.mark.skipif(shutil.which("node") is None or not (WEB / "node_modules").exists(),
                                reason="needs node and the npm packages (make setup)")
FITTED = ("aa", "ih", "ou", "ee", "oh", "happy", "angry", "sad", "relaxed", "surprised")


def _recipe(name: str) -> np.ndarray:
    return preset_recipes()[preset_names().index(name)].astype(np.float64)


@pytest.mark.parametrize("name", FITTED)
def test_a_presets_own_recipe_comes_back_as_that_preset(name):
    order = animated_presets()
    w = preset_weights(0.6 * _recipe(name)[None])[0]
    assert w[order.index(name)] == pytest.approx(0.6, abs=0.02)
    others = dict(zip(order, w, strict=True))
    others.pop(name)
    assert max(others.values()) < 0.05, others


def test_a_mix_of_a_viseme_and_an_emotion_comes_back_as_the_mix():
    order = animated_presets()
    w = preset_weights((0.7 * _recipe("oh") + 0.4 * _recipe("sad"))[None])[0]
    assert w[order.index("oh")] == pytest.approx(0.7, abs=0.03)
    assert w[order.index("sad")] == pytest.approx(0.4, abs=0.03)


def test_blinks_are_the_shared_closure_and_each_lids_rest():
    values = np.zeros((3, 84))
    left, right = fap("close_t_l_eyelid").index, fap("close_t_r_eyelid").index
    values[0, [left, right]] = 1024
    values[1, left] = 1024
    values[2, [left, right]] = 512, 1024
    w = dict(zip(animated_presets(), preset_weights(values).T, strict=True))
    np.testing.assert_allclose(w["blink"], [1, 0, 0.5])
    np.testing.assert_allclose(w["blinkLeft"], [0, 1, 0])
    np.testing.assert_allclose(w["blinkRight"], [0, 0, 0.5])


def _stream() -> FapStream:
    """2 s at 25 fps: an "aa" rising to full, a smile, a head turn, eyes looking left-down."""
    n = 50
    ramp = np.linspace(0, 1, n)[:, None]
    values = ramp * _recipe("aa") + ramp[::-1] * 0.8 * _recipe("happy")
    au = float(default_face().fapu["AU"])
    values[:, fap("head_yaw").index] = np.radians(20) * ramp[:, 0] / au
    values[:, fap("head_pitch").index] = np.radians(-8) * ramp[:, 0] / au
    for eye in ("l", "r"):
        values[:, fap(f"yaw_{eye}_eyeball").index] = np.radians(15) * ramp[:, 0] / au
        values[:, fap(f"pitch_{eye}_eyeball").index] = np.radians(10) * ramp[:, 0] / au
    return FapStream(25.0, values.astype(np.float32), np.ones_like(values, bool))


@pytest.fixture(scope="module")
def motion(tmp_path_factory):
    root = tmp_path_factory.mktemp("vrma")
    stream = _stream()
    return stream, export_vrma(stream, root / "clip.vrma"), export_vrm(stream, root / "head.vrm")


def test_layout_is_a_vrm_animation(motion):
    stream, result, _ = motion
    g = Gltf(result.path)
    ext = g.g.extensions["VRMC_vrm_animation"]
    assert g.g.extensionsUsed == ["VRMC_vrm_animation"] and ext["specVersion"] == "1.0"
    bones = ext["humanoid"]["humanBones"]
    assert {"hips", "spine", "head", "leftUpperArm", "rightFoot"} <= set(bones)
    assert "leftEye" not in bones and "rightEye" not in bones  # the look-at's (the spec)
    assert set(ext["expressions"]["preset"]) == set(animated_presets())
    assert not set(ext["expressions"]["preset"]) & {"lookUp", "lookDown", "lookLeft", "lookRight"}
    nodes = g.g.nodes
    assert all(n.rotation is None and n.scale is None for n in nodes)  # T-pose: no rest turns
    assert nodes[bones["hips"]["node"]].translation[1] > 0.5  # above the floor
    animation = g.g.animations[0]
    by_target = {(c.target.node, c.target.path): animation.samplers[c.sampler]
                 for c in animation.channels}
    times = g.accessor(animation.samplers[0].input)[:, 0]
    np.testing.assert_allclose(times, np.arange(stream.n_frames) / 25, atol=1e-6)
    for k, name in enumerate(result.presets):
        node = ext["expressions"]["preset"][name]["node"]
        shift = g.accessor(by_target[(node, "translation")].output)
        np.testing.assert_allclose(shift[:, 0], result.weights[:, k])
        assert not shift[:, 1:].any()
    head = g.accessor(by_target[(bones["head"]["node"], "rotation")].output)
    yaw, pitch, _ = Rotation.from_quat(head[-1]).as_euler("YXZ")
    assert np.degrees(yaw) == pytest.approx(20, abs=0.05)
    assert np.degrees(pitch) == pytest.approx(-8, abs=0.05)
    look = g.accessor(by_target[(ext["lookAt"]["node"], "rotation")].output)
    yaw, pitch, _ = Rotation.from_quat(look[-1]).as_euler("YXZ")
    assert (np.degrees(yaw), np.degrees(pitch)) == pytest.approx((15, 10), abs=0.05)


def test_refuses_other_suffixes(tmp_path):
    with pytest.raises(ParameterError, match=r"\.vrma"):
        export_vrma(FapStream.zeros(1, fps=25), tmp_path / "a.glb")


@NEEDS_NODE
def test_gltf_validator_reports_no_error_or_warning(motion):
    _, result, _ = motion
    run = subprocess.run(["node", str(WEB / "tools" / "validate.mjs"), str(result.path)],
                         capture_output=True, text=True, check=False)
    report = json.loads(run.stdout)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"][:5]
    assert {m["code"] for m in report["messages"]} <= {"UNSUPPORTED_EXTENSION", "NODE_EMPTY"}


@NEEDS_NODE
@pytest.mark.browser
@pytest.mark.skipif(CHROMIUM is None, reason="needs chromium")
def test_three_vrm_plays_the_animation_on_facelibs_avatar(motion, tmp_path):
    stream, result, avatar = motion
    frames = (0, 20, 49)
    job = {"vrm": str(avatar.path), "vrma": str(result.path), "chromium": CHROMIUM,
           "times": [i / stream.fps for i in frames]}
    (tmp_path / "job.json").write_text(json.dumps(job))
    run = subprocess.run(["node", str(WEB / "tools" / "vrm_check.mjs"), str(tmp_path / "job.json")],
                         capture_output=True, text=True, timeout=180, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads(run.stdout.strip().splitlines()[-1])
    assert "error" not in report, report.get("error")
    assert report["meta"] == "1" and set(report["expressions"]) == set(preset_names())
    assert {"Normalized_head.quaternion", "VRMLookAtQuaternionProxy.quaternion",
            "VRMExpression_aa.weight"} <= set(report["tracks"])
    # one mesh per part, named for it (three.js keeps the glTF node names)
    assert sorted(report["frames"][0]["influences"]) == sorted(avatar.parts)
    for i, shown in zip(frames, report["frames"], strict=True):
        for k, name in enumerate(result.presets):
            assert shown["weights"][name] == pytest.approx(result.weights[i, k], abs=1e-5), name
            # facelib's avatar binds preset k to morph target k of every part at weight 1
            for part, influences in shown["influences"].items():
                assert influences[preset_names().index(name)] == pytest.approx(
                    result.weights[i, k], abs=1e-5), (part, name)
        yaw, pitch, _ = Rotation.from_quat(shown["head"]).as_euler("YXZ", degrees=True)
        assert (yaw, pitch) == pytest.approx((20 * i / 49, -8 * i / 49), abs=0.05)
        assert shown["look"] == pytest.approx([15 * i / 49, 10 * i / 49], abs=0.05)
    last = dict(zip(result.presets, result.weights[-1], strict=True))
    assert last["aa"] > 0.9 and last["happy"] < 0.05  # the clip's end: mouth open, no smile
