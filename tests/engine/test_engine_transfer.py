"""Face set-up by transfer (third seed ch. 4): tests X-1..X-5 and D-3, D-4 of the transfer
reference (section C.4), on the default head, copies of it, and the SOMA test head."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from facelib.engine import default_face, load_face
from facelib.engine.face import ATTACHED_PARTS, PART_NAMES
from facelib.engine.quality import mean_roughness
from facelib.engine.setup import read_landmarks, setup_face
from facelib.engine.setup.headmesh import head_mesh, load_head_mesh
from facelib.engine.setup.tps import fit_tps
from facelib.engine.surface import closest_points, surface, vertex_normals
from facelib.engine.writer import write_face
from facelib.visemes.tables import viseme_targets

HEADS = Path(__file__).resolve().parents[2] / "examples" / "heads"
HELD_OUT = ("10.3", "2.1", "3.1", "3.4", "4.1", "4.2", "5.3", "8.5", "9.15", "9.3")


def _frames() -> dict[str, np.ndarray]:
    """The seven test frames of the reference (FAP k is column k - 1)."""
    f = {name: np.zeros(84, np.float32) for name in
         ("jaw", "smile", "brows", "blink", "pucker", "yaw", "all")}
    f["jaw"][2] = 600
    f["smile"][[11, 12]] = 300
    f["smile"][[5, 6]] = 150
    f["brows"][30:36] = 300
    f["blink"][18:22] = 1024
    f["pucker"][[15, 16]] = 300
    f["pucker"][[5, 6]] = -200
    f["yaw"][48] = 20000
    f["all"] = sum(f[k] for k in ("jaw", "smile", "brows", "blink", "pucker", "yaw"))
    return f


FRAMES = _frames()


@pytest.fixture(scope="module")
def source():  # type: ignore[no-untyped-def]
    return default_face()


def _own(face) -> int:  # type: ignore[no-untyped-def]
    """How many vertices are the head's own: the attached parts (bust, garment, hair) are
    appended after them, and a transfer does not carry them (they fit the source head)."""
    attached = [face.parts[p].vertex_ids.min() for p in ATTACHED_PARTS if p in face.parts]
    return int(min(attached, default=face.n_vertices))


def _mesh_of(face, vertices=None):  # type: ignore[no-untyped-def]
    """The head's own vertices (or ``vertices`` in their place) and triangles as a mesh."""
    n = _own(face)
    verts = face.vertices[:n] if vertices is None else vertices
    tris = face.triangles[face.triangles.max(axis=1) < n]
    return head_mesh(verts, tris, parts={p: face.parts[p].vertex_ids for p in PART_NAMES})


def _all_landmarks(face) -> dict[str, int]:  # type: ignore[no-untyped-def]
    return {k: int(v) for k, v in face.feature_points.items()}


def _deform(face, name: str) -> np.ndarray:  # type: ignore[no-untyped-def]
    return face.deform_frame(FRAMES[name]).astype(np.float64)


def test_x1_identity_is_exact(source) -> None:  # type: ignore[no-untyped-def]
    face = setup_face(_mesh_of(source), landmarks=_all_landmarks(source), source=source)
    assert dict(face.feature_points) == dict(source.feature_points)
    for mine, theirs in zip(face.regions, source.regions, strict=True):
        assert set(mine.vertices.tolist()) == set(theirs.vertices.tolist()), mine.name
        assert set(mine.anchors.tolist()) == set(theirs.anchors.tolist()), mine.name
        assert (mine.deformer, mine.group, dict(mine.params)) == (
            theirs.deformer, theirs.group, dict(theirs.params))
        if theirs.weights.size:
            order = np.argsort(theirs.vertices)
            np.testing.assert_allclose(mine.weights, theirs.weights[order], atol=1e-12)
    # (issue 14: the learned fields pass through the interpolation like weights: float noise)
    n = _own(source)
    assert face.n_vertices == n
    assert abs(face.operator - source.operator[:, : 3 * n]).max() <= 1e-12
    # the baked ambient occlusion travels with the colours (issue 14, look)
    assert face.vertex_ao is not None and source.vertex_ao is not None
    # (exact but for a few tongue vertices that the correspondence interpolates)
    diff = np.abs(face.vertex_ao - source.vertex_ao[:n])
    assert np.mean(diff < 1e-6) > 0.99 and diff.max() < 0.25
    for name in FRAMES:
        np.testing.assert_allclose(face.deform_frame(FRAMES[name]),
                                   source.deform_frame(FRAMES[name])[:n], atol=1e-9)


def test_x2_similarity_copy_scales_everything(source) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(7)
    n = _own(source)
    perm = np.arange(n)
    for p in PART_NAMES:  # vertices shuffled within each part
        ids = source.parts[p].vertex_ids
        perm[ids] = rng.permutation(ids)
    shift = np.array([0.1, -0.2, 0.05])
    verts = np.empty((n, 3))
    verts[perm] = source.vertices[:n].astype(np.float64) * 1.3 + shift  # new id perm[i] is old i
    tris = perm[source.triangles[source.triangles.max(axis=1) < n]]
    mesh = head_mesh(verts, tris, parts={p: perm[source.parts[p].vertex_ids] for p in PART_NAMES})
    marks = {k: int(perm[v]) for k, v in source.feature_points.items()}
    result = setup_face(mesh, landmarks=marks, source=source, report=True)
    face = result.face
    assert result.unit == "m"
    for unit in ("IRISD", "ES", "ENS", "MNS", "MW"):
        assert face.fapu[unit] / source.fapu[unit] == pytest.approx(1.3, abs=1e-6)
    new_of_old = _new_ids(face, verts, perm)
    for name in FRAMES:
        expected = _deform(source, name)[:n] * 1.3 + shift
        assert np.abs(_deform(face, name)[new_of_old] - expected).max() <= 1e-6, name


def _new_ids(face, mesh_vertices: np.ndarray, perm: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Output vertex id of each source vertex (the output keeps the mesh's positions)."""
    from scipy.spatial import cKDTree

    dist, hit = cKDTree(face.vertices.astype(np.float64)).query(mesh_vertices[perm])
    assert dist.max() <= 1e-6
    return hit


def test_x2_rotated_copy_is_turned_upright(source) -> None:  # type: ignore[no-untyped-def]
    angle = np.radians(30)
    rot = np.array([[np.cos(angle), 0, np.sin(angle)], [0, 1, 0],
                    [-np.sin(angle), 0, np.cos(angle)]])
    n = _own(source)
    verts = source.vertices[:n].astype(np.float64) @ rot.T * 1.3
    result = setup_face(_mesh_of(source, verts), landmarks=_all_landmarks(source),
                        source=source, report=True)
    np.testing.assert_allclose(result.rotation, rot.T, atol=1e-9)
    face = result.face
    for name in ("jaw", "smile", "yaw"):
        assert np.abs(_deform(face, name) - _deform(source, name)[:n] * 1.3).max() <= 1e-6


def _subdivided(source):  # type: ignore[no-untyped-def]
    """The source with its skin split 1-to-4 at edge midpoints (other parts unchanged)."""
    skin = source.parts["skin"]
    verts = source.vertices.astype(np.float64)
    tris = skin.triangles
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mids = verts[unique].mean(axis=1)
    n_skin = skin.vertex_ids.size  # skin vertices are 0..n_skin-1; midpoints follow them
    mid_ids = n_skin + np.arange(len(unique))
    m = mid_ids[inverse.reshape(3, -1).T]  # (F, 3): midpoints of edges 01, 12, 20
    a, b, c = tris.T
    new_tris = np.concatenate([np.c_[a, m[:, 0], m[:, 2]], np.c_[m[:, 0], b, m[:, 1]],
                               np.c_[m[:, 2], m[:, 1], c], np.c_[m[:, 0], m[:, 1], m[:, 2]]])
    others = np.arange(n_skin, _own(source))
    offset = len(unique)
    other_tris = np.concatenate([source.parts[p].triangles for p in PART_NAMES[1:]]) + offset
    all_verts = np.vstack([verts[:n_skin], mids, verts[others]])
    parts = {p: source.parts[p].vertex_ids + offset for p in PART_NAMES[1:]}
    parts["skin"] = np.arange(n_skin + offset)
    return head_mesh(all_verts, np.vstack([new_tris, other_tris]), parts=parts), unique


@pytest.mark.slow
def test_x3_subdivided_skin(source) -> None:  # type: ignore[no-untyped-def]
    mesh, edges = _subdivided(source)
    n_skin = source.parts["skin"].vertex_ids.size
    marks = {k: v if v < n_skin else v + len(edges) for k, v in _all_landmarks(source).items()}
    face = setup_face(mesh, landmarks=marks, source=source)
    assert face.n_vertices == mesh.vertices.shape[0]
    for name in FRAMES:
        moved = _deform(face, name) - face.vertices
        before = _deform(source, name) - source.vertices
        assert np.abs(moved[:n_skin] - before[:n_skin]).max() <= 1e-6, name
        mids = moved[n_skin : n_skin + len(edges)]
        gap = np.linalg.norm(mids - before[edges].mean(axis=1), axis=1)
        # the reference's 1 mm in every frame, "all" included (measured p99 0.86 mm: the
        # brows' RBF and the lids' rotation are not linear along an edge)
        assert np.percentile(gap, 99) <= 1e-3, name


def _noisy(source, sigma: float, seed: int):  # type: ignore[no-untyped-def]
    verts = source.vertices[: _own(source)].astype(np.float64)
    skin = source.parts["skin"].vertex_ids
    fps = np.array(list(source.feature_points.values()))
    noise = np.random.default_rng(seed).normal(scale=sigma, size=(skin.size, 3))
    noise[np.isin(skin, fps)] = 0  # the landmarks stay where they are
    verts[skin] += noise
    return verts


def test_x4_d3_noise_on_the_target(source) -> None:  # type: ignore[no-untyped-def]
    verts = _noisy(source, 1e-4, seed=8)
    face = setup_face(_mesh_of(source, verts), landmarks=_all_landmarks(source), source=source)
    assert dict(face.feature_points) == dict(source.feature_points)
    changes = sum(len(set(a.vertices.tolist()) ^ set(b.vertices.tolist()))
                  for a, b in zip(face.regions, source.regions, strict=True))
    assert changes <= 2
    for name in FRAMES:
        diff = np.linalg.norm((_deform(face, name) - face.vertices)
                              - (_deform(source, name) - source.vertices)[:_own(source)],
                              axis=1)
        assert np.percentile(diff, 99) <= 1e-3, name
        assert diff.max() <= 2e-3, name


@pytest.fixture(scope="module")
def soma(source, tmp_path_factory):  # type: ignore[no-untyped-def]
    marks = read_landmarks(HEADS / "soma_landmarks.json")
    given = {k: v for k, v in marks.items() if k not in HELD_OUT}
    result = setup_face(HEADS / "soma_head.ply", landmarks=given, source=source, report=True)
    path = write_face(result.face, tmp_path_factory.mktemp("soma") / "face.json")
    return result, load_face(path), marks


def test_x5_soma_head_loads_and_places_held_out_points(soma, source) -> None:  # type: ignore[no-untyped-def]
    result, face, marks = soma
    assert result.carried == (*PART_NAMES[1:], "lashes")
    assert len(result.landmarks) == 24
    assert np.array_equal(face.vertices, result.face.vertices)
    err = np.array([np.linalg.norm(face.vertices[face.feature_points[k]] - marks[k])
                    for k in HELD_OUT])
    assert np.median(err) <= 2.5e-3
    assert err.max() <= 6e-3
    for unit in ("IRISD", "ES", "ENS", "MNS", "MW"):
        assert 0.8 <= face.fapu[unit] / source.fapu[unit] <= 1.25, unit


def _flipped(face, name: str) -> int:  # type: ignore[no-untyped-def]
    tris = face.parts["skin"].triangles
    rest = np.cross(*(face.vertices[tris[:, k]] - face.vertices[tris[:, 0]] for k in (1, 2)))
    moved = _deform(face, name)
    now = np.cross(*(moved[tris[:, k]] - moved[tris[:, 0]] for k in (1, 2)))
    return int(np.sum(np.einsum("fc,fc->f", rest, now) < 0))


def test_x5_soma_head_deforms_like_the_source(soma, source) -> None:  # type: ignore[no-untyped-def]
    _, face, _ = soma
    for name in FRAMES:
        assert _flipped(face, name) <= _flipped(source, name) + 20, name
    pairs = [("8.1", "8.2"), ("2.1", "9.15"), ("4.1", "3.1"), ("4.2", "3.2"), ("3.1", "3.3")]
    for name in ("jaw", "brows", "blink"):
        for a, b in pairs:
            strain = []
            for f in (source, face):
                pos = _deform(f, name)
                rest = np.linalg.norm(f.vertices[f.feature_points[a]]
                                      - f.vertices[f.feature_points[b]])
                now = np.linalg.norm(pos[f.feature_points[a]] - pos[f.feature_points[b]])
                strain.append(((now - rest) / rest, rest))
            (eps_s, l0_s), (eps_t, l0_t) = strain
            if min(l0_s, l0_t) >= 0.01 and abs(eps_s) >= 0.02:
                # 0.2 since the jaw is the learned jawOpen field (issue 14): its swing carries
                # over a little less faithfully to another head than the old jaw weights
                assert abs(eps_t - eps_s) <= 0.2, (name, a, b, eps_s, eps_t)


def _lips(face) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.concatenate([r.vertices for r in face.regions
                           if r.name in ("upper_lip", "lower_lip")])


def test_x5_soma_lip_roughness_per_viseme(soma, source) -> None:  # type: ignore[no-untyped-def]
    _, face, _ = soma
    for k, values in enumerate(viseme_targets()):
        rough = [mean_roughness(f.deform_frame(values), f.parts["skin"].triangles,
                                vertex_ids=_lips(f)) for f in (source, face)]
        assert rough[1] <= 1.2 * rough[0], (k, rough)


def test_d4_dense_correspondence_against_ground_truth(source) -> None:  # type: ignore[no-untyped-def]
    mesh = load_head_mesh(HEADS / "soma_head.ply")
    marks = read_landmarks(HEADS / "soma_landmarks.json")
    with np.load(HEADS / "soma_truth.npz") as data:
        ids, truth = data["ids"], data["positions"].astype(np.float64)
    warp = fit_tps(source.vertices[[source.feature_points[k] for k in marks]],
                   np.array(list(marks.values())))
    skin = source.parts["skin"]
    local = np.full(source.n_vertices, -1)
    local[skin.vertex_ids] = np.arange(skin.vertex_ids.size)
    warped = warp(source.vertices[skin.vertex_ids].astype(np.float64))
    guide = closest_points(surface(mesh.vertices, mesh.part_triangles("skin")), warped,
                           normals=vertex_normals(warped, local[skin.triangles])).points
    err = np.linalg.norm(guide[local[ids]] - truth, axis=1)
    assert np.median(err) <= 2.5e-3
    assert np.percentile(err, 95) <= 9.5e-3
    # (the learned fields of issue 14 cover most of the skin: the regions meant here are the
    # hand-built ones)
    in_regions = np.isin(ids, np.concatenate([r.vertices for r in source.regions
                                              if r.deformer != "field"]))
    assert np.median(err[in_regions]) <= 2.0e-3
    assert err[in_regions].max() <= 10e-3


def test_written_definition_round_trips(source, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    path = write_face(source, tmp_path / "copy" / "face.json", name="copy")
    again = load_face(path)
    assert np.array_equal(again.vertices, source.vertices)
    assert dict(again.feature_points) == dict(source.feature_points)
    assert abs(again.operator - source.operator).max() == 0
    assert again.vertex_ao is not None and source.vertex_ao is not None
    assert np.abs(again.vertex_ao - source.vertex_ao).max() <= 0.5 / 255 + 1e-6  # uint8
    doc = json.loads(path.read_text())
    assert doc["mesh"] == "face.npz" and doc["name"] == "copy"
    original = json.loads((Path(__file__).resolve().parents[2] / "facelib" / "data" / "head"
                           / "default_head.json").read_text())
    assert [(r["name"], r.get("group", "")) for r in doc["regions"]] == [
        (r["name"], r.get("group", "")) for r in original["regions"]]
    assert [r.deformer for r in again.regions] == [r.deformer for r in source.regions]
    assert sorted(p.name for p in path.parent.iterdir()) == ["face.json", "face.npz"]
