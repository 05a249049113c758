"""The default head and its deformation: FAPU, eq. 4.6 displacements, rotations, lips, lids."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import ATTACHED_PARTS, OPTIONAL_PARTS, PART_NAMES, Face
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap, fap_table

EYELID_FAPS = (19, 20, 21, 22)


@pytest.fixture(scope="module")
def face(default_face: Face) -> Face:
    return default_face


def test_mesh_arrays_and_parts(face: Face) -> None:
    v, t, c = face.vertices, face.triangles, face.vertex_colors
    assert v.dtype == np.float32 and v.shape[1] == 3
    assert t.dtype == np.int32 and t.shape[1] == 3 and t.max() < len(v)
    assert c.shape == v.shape and c.min() >= 0 and c.max() <= 1
    assert not v.flags.writeable
    assert tuple(face.parts) == (*PART_NAMES, *OPTIONAL_PARTS, *ATTACHED_PARTS)
    covered = sum(len(p.triangles) for p in face.parts.values())
    assert covered == len(t)
    ids = np.concatenate([p.vertex_ids for p in face.parts.values()])
    assert np.array_equal(np.sort(ids), np.arange(len(v)))
    # a head about 25 cm tall (skin), looking along +z, symmetric about x = 0; the bust and
    # hair are appended after every head vertex
    assert face.parts["bust"].vertex_ids.min() == face.parts["lashes"].vertex_ids.max() + 1
    skin = face.parts["skin"].vertex_ids
    extent = v[skin].max(0) - v[skin].min(0)
    assert 0.18 < extent[1] < 0.32 and 0.12 < extent[0] < 0.2
    assert v[face.feature_points["9.3"], 2] == pytest.approx(v[:, 2].max(), abs=0.005)
    assert v[face.feature_points["3.5"], 0] > 0 > v[face.feature_points["3.6"], 0]


def test_eyes_have_pupil_iris_and_sclera(face: Face) -> None:
    for name in ("eye_l", "eye_r"):
        ids = face.parts[name].vertex_ids
        lum = face.vertex_colors[ids].mean(1)
        assert lum.min() < 0.05  # black pupil
        assert lum.max() > 0.9  # white sclera
        assert np.any((lum > 0.2) & (lum < 0.6))  # iris
        pupil = face.feature_points["3.5" if name == "eye_l" else "3.6"]
        assert face.vertex_colors[pupil].max() < 0.05


def neck_border(face: Face) -> np.ndarray:
    skin = face.parts["skin"].triangles
    edges = np.sort(np.concatenate([skin[:, [0, 1]], skin[:, [1, 2]], skin[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    return np.unique(uniq[counts == 1])


def test_neck_cut_is_one_planar_edge(face: Face) -> None:
    border = neck_border(face)
    assert border.size > 20
    pts = face.vertices[border].astype(np.float64)
    centred = pts - pts.mean(0)
    # all border vertices lie on one plane (the smallest singular value is ~0)
    assert np.linalg.svd(centred, compute_uv=False)[-1] < 1e-5


def test_fapu_positive_and_in_proportion(face: Face) -> None:
    u = {k: v * 1024 for k, v in face.fapu.items() if k != "AU"}
    assert all(v > 0 for v in u.values())
    assert face.fapu["AU"] == 1e-5
    assert 0.05 < u["ES"] < 0.075  # eye separation of an adult, metres
    assert 0.6 < u["MW"] / u["ES"] < 1.0
    assert 0.7 < u["ENS"] / u["ES"] < 1.1
    assert 0.1 < u["MNS"] / u["ENS"] < 0.45
    assert 0.1 < u["IRISD"] / u["ES"] < 0.25


def _translational():
    return [f for f in fap_table() if f.kind == "translation"]


@pytest.mark.parametrize("fap_id", [f.id for f in _translational()])
def test_translation_fap_moves_its_point(face: Face, fap_id: int, fap_frame) -> None:
    f = fap(fap_id)
    value = 200.0
    p = face.feature_points[f.feature_points[0]]
    moved = face.deform_frame(fap_frame(**{f.name: value})).astype(np.float64)
    rest = face.vertices.astype(np.float64)
    delta = moved[p] - rest[p]
    expected = value * face.fapu[f.fapu] * np.asarray(f.direction, dtype=np.float64)
    if fap_id in EYELID_FAPS:  # lids slide over the eye: the vertical motion is prescribed
        assert delta[1] == pytest.approx(expected[1], rel=0.01)
        centre = face.pivots["eye_l" if fap_id in (19, 21) else "eye_r"]
        assert np.linalg.norm(moved[p] - centre) == pytest.approx(
            np.linalg.norm(rest[p] - centre), rel=1e-5)
    elif face.fap_deformers.get(f.name) == "field":
        # eq. 4.6 exactly along the FAP's direction; the learned field decides the rest
        direction = np.asarray(f.direction, dtype=np.float64)
        assert delta @ direction == pytest.approx(expected @ direction, rel=1e-4)
    else:
        assert delta == pytest.approx(expected, rel=0.01, abs=1e-3 * np.abs(expected).max())
    # far from the feature point nothing moves (but the jaw carries teeth and tongue)
    far = np.linalg.norm(rest - rest[p], axis=1) > 0.09
    if fap_id in (3, 14, 15):
        far[face.parts["teeth_lower"].vertex_ids] = far[face.parts["tongue"].vertex_ids] = False
    # a learned field may reach further (a brow lowerer folds the forehead), but fades there
    limit = 0.2 * np.linalg.norm(delta) if face.fap_deformers.get(f.name) == "field" else 1e-7
    assert np.abs(moved[far] - rest[far]).max() < limit


def test_deformation_is_linear_in_translation_faps(face: Face, fap_frame) -> None:
    a = fap_frame(raise_b_midlip=150, stretch_l_cornerlip=-80, raise_l_i_eyebrow=100)
    b = fap_frame(lower_t_midlip=-60, puff_r_cheek=200, raise_nose=50)
    rest = face.vertices
    da, db = face.deform_frame(a) - rest, face.deform_frame(b) - rest
    dab = face.deform_frame(a + b) - rest
    np.testing.assert_allclose(dab, da + db, atol=1e-6)
    assert face.operator.shape == (84, 3 * len(rest))


def _angle(u: np.ndarray, v: np.ndarray) -> float:
    return float(np.arccos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1)))


@pytest.mark.parametrize(("name", "pupil", "pivot", "axis", "sign"), [
    ("yaw_l_eyeball", "3.5", "eye_l", 0, 1.0),
    ("yaw_r_eyeball", "3.6", "eye_r", 0, 1.0),
    ("pitch_l_eyeball", "3.5", "eye_l", 1, -1.0),
    ("pitch_r_eyeball", "3.6", "eye_r", 1, -1.0),
])
def test_eyeball_rotates_by_the_angle(
    face: Face, name, pupil, pivot, *, axis, sign, fap_frame
) -> None:
    p = face.feature_points[pupil]
    c = face.pivots[pivot]
    moved = face.deform_frame(fap_frame(**{name: 20000}))
    before = face.vertices[p] - c
    after = moved[p] - c
    assert _angle(before, after) == pytest.approx(0.2, rel=1e-3)
    assert sign * (after[axis] - before[axis]) > 0  # left = +x, down = -y
    # the whole eye turns rigidly: its vertices keep their distance to the centre
    ids = face.parts[pivot].vertex_ids
    r0 = np.linalg.norm(face.vertices[ids] - c, axis=1)
    r1 = np.linalg.norm(moved[ids] - c, axis=1)
    np.testing.assert_allclose(r1, r0, rtol=1e-5)


@pytest.mark.parametrize(("name", "plane", "sign_axis"), [
    ("head_yaw", (0, 2), 0),
    ("head_pitch", (1, 2), 1),
])
def test_head_rotates_about_its_pivot(face: Face, name, plane, sign_axis, fap_frame) -> None:
    tip = face.feature_points["9.3"]
    h = face.pivots["head"]
    moved = face.deform_frame(fap_frame(**{name: 15000}))
    before, after = (face.vertices[tip] - h)[list(plane)], (moved[tip] - h)[list(plane)]
    assert _angle(before, after) == pytest.approx(0.15, rel=1e-3)
    direction = 1.0 if name == "head_yaw" else -1.0  # yaw left (+x), pitch down (-y)
    assert direction * (moved[tip] - face.vertices[tip])[sign_axis] > 0
    # the bust's bottom stays where it is; the neck between blends (the head's old cut,
    # now the seam to the bust, turns part of the way)
    bust = face.parts["bust"].vertex_ids
    low = bust[face.vertices[bust, 1] < face.vertices[bust, 1].min() + 0.05]
    np.testing.assert_allclose(moved[low], face.vertices[low], atol=1e-6)
    seam = neck_border(face)
    turned = np.linalg.norm(moved[seam] - face.vertices[seam], axis=1)
    assert 0 < turned.max() < np.linalg.norm(moved[tip] - face.vertices[tip])


def test_head_roll_tips_the_top_to_the_right(face: Face, fap_frame) -> None:
    top = int(np.argmax(face.vertices[:, 1]))
    moved = face.deform_frame(fap_frame(head_roll=10000))
    assert moved[top, 0] < face.vertices[top, 0] - 0.005


def test_lips_part_by_the_jaw_displacement(face: Face, fap_frame) -> None:
    value = 600.0
    drop = value * face.fapu["MNS"]
    moved = face.deform_frame(fap_frame(open_jaw=value))
    up, lo = face.feature_points["2.2"], face.feature_points["2.3"]
    gap0 = face.vertices[up, 1] - face.vertices[lo, 1]
    gap1 = moved[up, 1] - moved[lo, 1]
    if face.fap_deformers["open_jaw"] == "field":
        # the jaw swings: the chin point drops by the FAP, the lower lip (further from the
        # hinge's axis in depth) drops further, as the ARKit jawOpen target says
        assert drop < gap1 - gap0 < 2.0 * drop
        # and the lower teeth stay behind the lower lip: the hinge follows the lip's drop
        teeth = face.parts["teeth_lower"].vertex_ids
        incisor = teeth[np.argmax(face.vertices[teeth, 1] + face.vertices[teeth, 2])]
        lip_drop = face.vertices[lo, 1] - moved[lo, 1]
        assert face.vertices[incisor, 1] - moved[incisor, 1] == pytest.approx(lip_drop, rel=0.15)
    else:
        assert gap1 - gap0 == pytest.approx(drop, rel=0.05)
    # the upper lip stays: no vertex of the upper lip follows the lower one (at the corners
    # and inside the mouth the shared lining stretches with the jaw)
    upper = next(r for r in face.regions if r.name == "upper_lip").vertices
    corner = face.vertices[face.feature_points["2.4"]]
    upper = upper[(np.abs(face.vertices[upper, 0]) < abs(corner[0]) - 0.002)
                  & (face.vertices[upper, 2] > corner[2])]
    assert upper.size > 100
    # (the jawOpen field stretches the lip lining next to the corners a little)
    field = face.fap_deformers["open_jaw"] == "field"
    assert np.abs(moved[upper] - face.vertices[upper]).max() < (0.5 if field else 0.05) * drop
    assert abs(moved[up, 1] - face.vertices[up, 1]) < 0.05 * drop  # the upper midlip stays
    # lower teeth and tongue ride with the jaw, upper teeth stay
    for part, moves in (("teeth_lower", True), ("tongue", True), ("teeth_upper", False)):
        ids = face.parts[part].vertex_ids
        dy = (moved[ids, 1] - face.vertices[ids, 1]).mean()
        assert (dy < -0.3 * drop) if moves else dy == 0


def _incisal_edges(face: Face, moved: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(y, z) of the upper and the lower front teeth's edges (|x| < 4 mm)."""
    out = []
    for part, edge in (("teeth_upper", np.argmin), ("teeth_lower", np.argmax)):
        ids = face.parts[part].vertex_ids
        ids = ids[np.abs(moved[ids, 0]) < 0.004]
        out.append(moved[ids[edge(moved[ids, 1])], 1:])
    return out[0], out[1]


def test_tongue_rests_low_and_th_puts_its_tip_between_the_teeth(face: Face) -> None:
    from facelib.visemes import viseme_targets
    from facelib.visemes.tables import viseme_id

    tip = face.feature_points["6.1"]
    upper, lower = _incisal_edges(face, face.vertices)
    tongue = face.parts["tongue"].vertex_ids
    # at rest the tongue lies behind the front teeth, its top below the upper teeth's edge
    assert face.vertices[tongue, 2].max() < lower[1] - 0.005
    front = tongue[face.vertices[tongue, 2] > lower[1] - 0.015]
    assert face.vertices[front, 1].max() < upper[0] - 0.002
    # 'th': the tip comes forward past the lower teeth, between the two rows' edges
    moved = face.deform_frame(viseme_targets()[viseme_id("TH")])
    upper, lower = _incisal_edges(face, moved)
    assert moved[tip, 2] > lower[1]
    assert lower[0] - 0.003 < moved[tip, 1] < upper[0]


def test_mouth_cavity_is_dark(face: Face) -> None:
    skin = face.parts["skin"].vertex_ids
    v, corner = face.vertices, face.vertices[face.feature_points["8.3"]]
    mouth_y = (v[face.feature_points["2.2"], 1] + v[face.feature_points["2.3"], 1]) / 2
    deep = skin[(v[skin, 2] < corner[2] - 0.01) & (v[skin, 2] > corner[2] - 0.05)
                & (np.abs(v[skin, 0]) < 0.02) & (np.abs(v[skin, 1] - mouth_y) < 0.03)]
    assert deep.size > 10
    # the baked ambient occlusion darkens the cavity's one flat colour with depth
    assert face.vertex_ao is not None
    assert (face.vertex_colors[deep] * face.vertex_ao[deep, None]).max() < 0.3
    assert np.median(face.vertex_ao[deep]) < 0.2


def test_eyelids_close_over_the_eye_without_cutting_it(face: Face, fap_frame) -> None:
    moved = face.deform_frame(fap_frame(close_t_l_eyelid=1024, close_t_r_eyelid=1024))
    for top, bottom, eye in (("3.1", "3.3", "eye_l"), ("3.2", "3.4", "eye_r")):
        t, b = face.feature_points[top], face.feature_points[bottom]
        assert moved[t, 1] == pytest.approx(face.vertices[b, 1], abs=2e-4)
        c = face.pivots[eye]
        ids = face.parts[eye].vertex_ids
        radius = np.linalg.norm(face.vertices[ids] - c, axis=1).max()
        lid = next(r for r in face.regions if r.name == f"upper_lid_{eye[-1]}").vertices
        outside = np.linalg.norm(face.vertices[lid] - c, axis=1) > radius
        assert np.all(np.linalg.norm(moved[lid][outside] - c, axis=1) > radius)


def test_deform_stream_matches_frames(face: Face, rng: np.random.Generator) -> None:
    values = np.zeros((5, 84), np.float32)
    values[:, 2:68] = rng.uniform(-150, 150, (5, 66))
    values[:, 2] = np.abs(values[:, 2])
    values[:, [0, 1, 28, 29, 46]] = 0
    stream = FapStream(25.0, values, np.ones((5, 84), bool))
    out = face.deform(stream)
    assert out.shape == (5, len(face.vertices), 3) and out.dtype == np.float32
    for i in range(5):
        np.testing.assert_allclose(out[i], face.deform_frame(values[i]), atol=1e-6)
    assert np.all(np.isfinite(out))


def test_bad_frames_are_rejected(face: Face) -> None:
    with pytest.raises(ParameterError, match="84"):
        face.deform_frame(np.zeros(68))
    with pytest.raises(ParameterError, match="non-finite"):
        face.deform_frame(np.full(84, np.nan))
    with pytest.raises(ParameterError, match="FapStream"):
        face.deform(np.zeros((3, 84)))  # type: ignore[arg-type]
