"""glTF export: the file validates, and its morph targets and skin evaluated per the glTF
specification reproduce ``Face.deform`` within 0.1 mm."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from gltf_eval import Gltf, busy_stream
from scipy.spatial.transform import Rotation

from facelib.data import json_data
from facelib.engine import default_face
from facelib.export import export_gltf
from facelib.export.gltf import primitive_vertex_ids
from facelib.mpeg4 import fap

WEB = Path(__file__).parents[2] / "facelib" / "export" / "web"


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("gltf") / "busy.glb"
    return export_gltf(busy_stream(), out), busy_stream()


def test_evaluated_gltf_matches_deform_within_a_tenth_of_a_millimetre(exported):
    result, stream = exported
    face = default_face()
    want = face.deform(stream)
    gltf = Gltf(result.path)
    worst = 0.0
    for frame in (0, 3, 6, 9, 11):
        got = gltf.evaluate(frame)
        for part, positions in zip(face.parts.values(), got, strict=True):
            ids = primitive_vertex_ids(part)
            worst = max(worst, float(np.abs(positions - want[frame][ids]).max()))
    assert worst < 1e-4, f"{worst * 1000:.4f} mm"
    print(f"worst {worst * 1000:.5f} mm")
    # the deformation is real: frame 6 moves the face by centimetres
    assert np.abs(want[6] - face.vertices).max() > 0.01


def test_each_primitive_indexes_its_own_vertices_the_bust_copies_the_neck_loop(exported):
    """A primitive's indices name only its own vertices: the bust's triangles that join it to
    the head's neck loop get copies of those skin vertices (same place, same normal), so
    the seam stays closed and shaded alike."""
    result, _ = exported
    face = default_face()
    gltf = Gltf(result.path)
    prims = {m.name: m.primitives[0] for m in gltf.g.meshes}
    assert list(prims) == list(face.parts)
    for name, prim in prims.items():
        positions = gltf.accessor(prim.attributes.POSITION)
        tris = gltf.accessor(prim.indices).reshape(-1, 3)
        ids = primitive_vertex_ids(face.parts[name])
        assert tris.max() < len(positions) == len(ids), name
        assert len(tris) == len(face.parts[name].triangles), name
        np.testing.assert_allclose(positions, face.vertices[ids], atol=1e-6)
    bust = face.parts["bust"]
    borrowed = primitive_vertex_ids(bust)[bust.vertex_ids.size:]
    assert len(borrowed) > 20 and np.isin(borrowed, face.parts["skin"].vertex_ids).all()
    normals = [gltf.accessor(prims[n].attributes.NORMAL) for n in ("skin", "bust")]
    at_skin = np.searchsorted(np.sort(face.parts["skin"].vertex_ids), borrowed)
    np.testing.assert_allclose(normals[1][bust.vertex_ids.size:], normals[0][at_skin])


def test_each_part_is_its_own_mesh_and_node_all_on_one_skin(exported):
    """Issue 36: one mesh and one node per part, named for it, so that Blender, Unity and
    three.js show each as its own object; every part has the same targets (names and
    count) and its own weights channel, all channels reading one sampler; one skin."""
    result, _ = exported
    face = default_face()
    g = Gltf(result.path).g
    assert result.parts == tuple(face.parts)
    assert [m.name for m in g.meshes] == list(face.parts)
    mesh_nodes = [i for i, n in enumerate(g.nodes) if n.mesh is not None]
    assert [g.nodes[i].name for i in mesh_nodes] == list(face.parts)
    assert [g.nodes[i].mesh for i in mesh_nodes] == list(range(len(face.parts)))
    assert all(g.nodes[i].skin == 0 for i in mesh_nodes) and len(g.skins) == 1
    assert all(len(m.primitives) == 1 for m in g.meshes)
    # scene roots (the validator warns of a skinned mesh under a parent), after the node
    # above the skeleton (so that Blender names its objects for the parts); names unique
    assert g.scenes[0].nodes == [0, *mesh_nodes] and g.nodes[0].children == [g.skins[0].joints[0]]
    assert len({n.name for n in g.nodes}) == len(g.nodes)
    for m in g.meshes:
        assert m.extras["targetNames"] == list(result.names)
        assert len(m.primitives[0].targets) == len(m.weights) == len(result.names)
    channels = [c for c in g.animations[0].channels if c.target.path == "weights"]
    assert sorted(c.target.node for c in channels) == mesh_nodes
    assert len({c.sampler for c in channels}) == 1
    # the eyes, lower teeth and tongue are still skinned to their joints
    joints = [g.nodes[j].name for j in g.skins[0].joints]
    gltf = Gltf(result.path)
    for part, joint in (("eye_l", "eyeball_l"), ("eye_r", "eyeball_r"), ("teeth_lower", "jaw"),
                        ("tongue", "jaw")):
        prim = g.meshes[list(face.parts).index(part)].primitives[0]
        used = np.unique(gltf.accessor(prim.attributes.JOINTS_0)[:, 0])
        assert [joints[k] for k in used] == [joint], part


def test_vertex_colours_carry_the_baked_occlusion(exported):
    """COLOR_0 is the linear colour darkened by the ambient occlusion as the renderer does
    it: deep in the mouth far darker than the colour alone, the open cheek unchanged."""
    result, _ = exported
    face = default_face()
    gltf = Gltf(result.path)
    skin = face.parts["skin"]
    prim = next(m.primitives[0] for m in gltf.g.meshes if m.name == "skin")
    colours = gltf.accessor(prim.attributes.COLOR_0)[:, :3]
    ids = primitive_vertex_ids(skin)  # the skin's vertices, then its UV seam copies
    rgb = np.clip(face.vertex_colors[ids], 0, 1)
    linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    ao = face.vertex_ao[ids]
    spec = json_data("render_look.json")["occlusion"]  # the skin has no power of its own
    factor = 1 - spec["strength"] * (1 - ao ** spec["power"])
    np.testing.assert_allclose(colours, linear * factor[:, None], atol=1e-5)
    assert (colours[ao < 0.1] < 0.5 * linear[ao < 0.1] + 1e-6).all()


def test_targets_are_sparse_and_only_what_the_stream_uses(exported):
    result, _ = exported
    g = Gltf(result.path).g
    assert 3 in result.targets and 19 not in result.targets  # lids are joints, not targets
    assert 48 not in result.targets and 1 not in result.targets
    names = g.meshes[0].extras["targetNames"]
    assert len(names) == len(result.targets) == len(g.meshes[0].primitives[0].targets)
    assert all(g.accessors[t["POSITION"]].bufferView is None
               and g.accessors[t["NORMAL"]].bufferView is None
               for m in g.meshes for p in m.primitives for t in p.targets)
    skin = g.meshes[0].primitives[0]
    moved = [g.accessors[t["POSITION"]].sparse for t in skin.targets]
    # sparse: each target moves a part of the skin (the learned jaw field of issue 14, the
    # widest, moves about half of it)
    assert all(s is not None and 0 < s.count < 0.6 * g.accessors[skin.attributes.POSITION].count
               for s in moved)
    # 6 parts, lashes, and the attached bust, garment and hair
    assert [p.material for m in g.meshes for p in m.primitives] == list(range(10))
    extras = g.asset.extras["facelib"]
    assert extras["n_frames"] == 12 and extras["fps"] == 25


def test_speech_audio_is_copied_beside_and_named(tmp_path):
    audio = Path(__file__).parents[2] / "examples" / "hello" / "hello.flac"
    result = export_gltf(busy_stream(), tmp_path / "a.glb", audio=audio)
    assert result.audio == tmp_path / "a.flac"
    assert result.audio.read_bytes() == audio.read_bytes()
    assert Gltf(result.path).g.asset.extras["facelib"]["audio"] == "a.flac"


@pytest.mark.skipif(shutil.which("node") is None or not (WEB / "node_modules").exists(),
                    reason="needs node and the npm packages (make setup)")
def test_gltf_validator_reports_no_issue(exported):
    result, _ = exported
    run = subprocess.run(["node", str(WEB / "tools" / "validate.mjs"), str(result.path)],
                         capture_output=True, text=True, check=False)
    report = json.loads(run.stdout)
    assert report["numErrors"] == 0 and report["numWarnings"] == 0, report["messages"][:5]


def test_still_and_empty_streams(tmp_path):
    from facelib import FapStream, ParameterError

    result = export_gltf(FapStream.zeros(3, fps=25), tmp_path / "still.glb")
    g = Gltf(result.path).g
    assert result.targets == () and g.animations == [] and len(g.skins) == 1
    with pytest.raises(ParameterError, match="no frames"):
        export_gltf(FapStream.zeros(0, fps=25), tmp_path / "empty.glb")
    with pytest.raises(ParameterError, match=r"\.glb"):
        export_gltf(FapStream.zeros(3, fps=25), tmp_path / "x.gltf")


def test_exports_are_lazy_names_of_facelib():
    import facelib
    import facelib.export as ex

    assert facelib.export_gltf is ex.export_gltf and facelib.import_arkit is ex.import_arkit
    assert {"export_gltf", "export_html", "export_arkit", "import_arkit"} <= set(facelib.__all__)


def test_no_negative_morph_weights_a_signed_fap_is_two_targets(tmp_path):
    """Blender's importer clamps morph weights to [0, 1] (issue 36): every weight the file
    animates is in [0, 1]; a FAP with values of both signs is two targets, one per sign, and
    their weighted sum is the FAP's displacement."""
    from facelib import FapStream

    n = 9
    values = np.zeros((n, 84), np.float32)
    values[:, fap("raise_b_midlip").index] = np.linspace(-300, 200, n)  # both signs
    values[:, fap("open_jaw").index] = np.linspace(0, 400, n)  # positive only
    values[:, fap("stretch_l_cornerlip").index] = np.linspace(0, -150, n)  # negative only
    stream = FapStream(25, values, np.ones((n, 84), bool))
    result = export_gltf(stream, tmp_path / "signs.glb")
    gltf = Gltf(result.path)
    gltf.local_matrices(0)
    animated = np.stack([(gltf.local_matrices(i), gltf.weights)[1] for i in range(n)])
    assert animated.min() >= 0 and animated.max() <= 1 + 1e-6
    lip, jaw, corner = (fap(k).id for k in ("raise_b_midlip", "open_jaw",
                                                "stretch_l_cornerlip"))
    assert result.targets.count(lip) == 2 and result.targets.count(jaw) == 1
    assert result.targets.count(corner) == 1
    scales = dict(zip(result.targets, result.scales, strict=True))
    assert scales[corner] < 0 and scales[jaw] > 0
    face = default_face()
    want = face.deform(stream)
    for frame in (0, 4, 8):
        got = gltf.evaluate(frame)
        for part, positions in zip(face.parts.values(), got, strict=True):
            ids = primitive_vertex_ids(part)
            np.testing.assert_allclose(positions, want[frame][ids], atol=1e-4)


def test_each_eyelid_joint_chain_moves_the_lid_it_is_named_for(exported):
    """Turn the joints of each ``lid_<upper|lower>_<l|r>_*`` chain alone and look at the
    vertices that follow: the face's left is +x (feature point 3.5, the left pupil, has x > 0
    in the face definition); the upper lid lies above the eye centre, the lower below."""
    result, _ = exported
    face = default_face()
    assert face.vertices[face.feature_points["3.5"], 0] > 0  # left pupil: +x
    gltf = Gltf(result.path)
    names = [n.name for n in gltf.g.nodes]
    rest = gltf.rest_matrices()
    still = gltf.pose(rest)
    skin_ids = primitive_vertex_ids(face.parts["skin"])  # with the UV seam copies
    skin_index = list(face.parts).index("skin")
    for side, sign in (("l", 1), ("r", -1)):
        centre = face.pivots[f"eye_{side}"]
        for lid in ("upper", "lower"):
            local = [m.copy() for m in rest]
            for j in range(1, 9):
                joint = names.index(f"lid_{lid}_{side}_{j}")
                local[joint][:3, :3] = local[joint][:3, :3] @ Rotation.from_rotvec(
                    [0.3, 0, 0]).as_matrix()
            moved = np.linalg.norm(gltf.pose(local)[skin_index] - still[skin_index], axis=1)
            follow = face.vertices[skin_ids[moved > 1e-5]]
            assert len(follow) > 10, (lid, side)
            assert np.all(np.sign(follow[:, 0]) == sign), f"lid_{lid}_{side}: wrong side"
            above = float((follow[:, 1] > centre[1]).mean())
            print(f"lid_{lid}_{side}: {len(follow)} vertices, {above:.2f} above the eye centre")
            assert above > 0.75 if lid == "upper" else above < 0.25, \
                f"lid_{lid}_{side}: {above:.2f} of its vertices above the eye centre"
