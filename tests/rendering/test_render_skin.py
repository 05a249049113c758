"""Skin, wrinkles and eyes of the default head (issue 32 item 2, issue 33 item 3).

Wrinkles are shading driven by the FAPs (facelib/rendering/skin_map.py): the same geometry
drawn with and without its FAPs differs only where the regions those FAPs drive lie.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.ndimage import binary_dilation

from facelib.expressions import default_library
from facelib.mpeg4.tables import fap
from facelib.rendering.skin_map import skin_layout, wrinkle_activation, wrinkle_drivers

engine = pytest.importorskip("facelib.engine")


def _expression(name: str, intensity: float = 0.6) -> np.ndarray:
    expression = default_library().get(name)
    return (expression.share(intensity) * expression.values).astype(np.float32)


def _faps(**values: float) -> np.ndarray:
    out = np.zeros(84, np.float32)
    for name, value in values.items():
        out[fap(name).index] = value
    return out


def _brow_raise() -> np.ndarray:
    return _faps(**{f"raise_{s}_{p}_eyebrow": 160.0 for s in "lr" for p in "imo"})


def _region(name: str) -> int:
    return wrinkle_drivers().names.index(name)


# -- drivers and layout (no OpenGL) ------------------------------------------------------


def test_neutral_activates_no_wrinkle_and_each_region_follows_its_faps():
    assert not wrinkle_activation(np.zeros(84)).any()
    brows = wrinkle_activation(_brow_raise())
    assert brows[_region("forehead")] > 0.5
    others = np.delete(brows, _region("forehead"))
    assert not others.any()
    smile = wrinkle_activation(_expression("joy"))
    for name in ("nasolabial_l", "nasolabial_r", "crows_feet_l", "crows_feet_r"):
        assert smile[_region(name)] > 0.5, name
    assert smile[_region("forehead")] == 0 and smile[_region("glabella")] == 0
    assert wrinkle_activation(_expression("anger"))[_region("glabella")] > 0.5
    assert wrinkle_activation(_expression("disgust"))[_region("nose")] > 0.5
    # the left furrow follows the left lip corner only
    left = wrinkle_activation(_faps(raise_l_cornerlip=600.0))
    assert left[_region("nasolabial_l")] > 0.5 and left[_region("nasolabial_r")] == 0


def test_wrinkle_activation_stays_in_zero_one():
    rng = np.random.default_rng(3)
    activation = wrinkle_activation(rng.normal(0, 2000, 84))
    assert activation.min() >= 0 and activation.max() <= 1


def _rest_normals(face) -> np.ndarray:
    from facelib.rendering.normals import vertex_normals

    return vertex_normals(np.asarray(face.vertices, np.float32), face.triangles)


def test_the_layout_follows_the_feature_points_to_another_head(default_face):
    """The same head scaled by 1.3 and moved: the layout (phases and weights) is the same,
    because it is placed by the feature points and measured in eye separations."""
    skin = default_face.parts["skin"].vertex_ids
    normals = _rest_normals(default_face)[skin]
    layout = skin_layout(default_face, skin, normals)
    other = SimpleNamespace(
        vertices=np.asarray(default_face.vertices, np.float64) * 1.3 + [0.01, -0.2, 0.05],
        feature_points=default_face.feature_points,
        fapu={k: v * 1.3 for k, v in default_face.fapu.items()})
    moved = skin_layout(other, skin, normals)
    assert layout is not None and moved is not None
    shown = layout.weights.max(axis=2).T > 1e-3  # (V, 2): where a phase is drawn
    np.testing.assert_allclose(moved.phase[shown], layout.phase[shown], atol=1e-3)
    np.testing.assert_allclose(moved.weights, layout.weights, atol=1e-4)
    # every region covers some skin, the forehead well above the brows
    covered = layout.weights.max(axis=0)
    assert (covered > 0.5).sum(axis=0).min() >= 3
    forehead = skin[layout.weights[0, :, _region("forehead")] > 0.5]
    brow_y = default_face.vertices[default_face.feature_points["4.1"], 1]
    assert (default_face.vertices[forehead, 1] > brow_y).all()


def test_a_face_without_feature_points_keeps_smooth_skin(default_face):
    bare = SimpleNamespace(vertices=default_face.vertices, feature_points={}, fapu={})
    skin = default_face.parts["skin"].vertex_ids
    assert skin_layout(bare, skin, _rest_normals(default_face)[skin]) is None


# -- rendered ----------------------------------------------------------------------------


def _luminance(image: np.ndarray) -> np.ndarray:
    return image.astype(float) @ [0.2126, 0.7152, 0.0722]


def _pixels(renderer, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    cols, rows = np.round(renderer.project(points)).astype(int).T
    inside = (rows >= 0) & (rows < renderer.height) & (cols >= 0) & (cols < renderer.width)
    return rows[inside], cols[inside]


@pytest.fixture(scope="module")
def face_renderer(default_face):
    from facelib.rendering.scene import FaceRenderer

    with FaceRenderer(default_face, width=320, height=320) as renderer:
        yield renderer


def _region_pixels(face, renderer, name: str, vertices: np.ndarray, *,
                   inside: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Pixels of the box round the skin vertices where wrinkle region ``name`` weighs more
    than ``inside`` (posed ``vertices``)."""
    skin = face.parts["skin"].vertex_ids
    layout = skin_layout(face, skin, _rest_normals(face)[skin])
    assert layout is not None
    inner = skin[layout.weights[:, :, _region(name)].max(axis=0) > inside]
    rows, cols = _pixels(renderer, np.asarray(vertices)[inner])
    box = np.mgrid[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    return box[0].ravel(), box[1].ravel()


@pytest.mark.render
@pytest.mark.parametrize(("region", "pose"), [
    ("forehead", "brows"), ("glabella", "anger"), ("nose", "disgust"),
    ("nasolabial_l", "joy"), ("nasolabial_r", "joy"), ("crows_feet_l", "joy"),
])
def test_wrinkles_show_where_their_faps_drive_them(default_face, face_renderer, region, pose):
    """The posed face with its FAPs against the same geometry with smooth skin: lines
    (darker valleys) raise the luminance spread in the region, and leave a region that the
    pose does not drive as it was."""
    faps = _brow_raise() if pose == "brows" else _expression(pose)
    vertices = default_face.deform_frame(faps)
    smooth = _luminance(face_renderer.frame(vertices, faps=np.zeros(84)))
    lined = _luminance(face_renderer.frame(vertices, faps=faps))
    rows, cols = _region_pixels(default_face, face_renderer, region, vertices)
    assert rows.size > 30
    change = lined[rows, cols] - smooth[rows, cols]
    assert (change < -4).mean() > 0.05, np.percentile(change, [5, 50, 95])  # darker valleys
    assert change.std() > 2.0
    # the pixels of the regions the pose leaves alone, outside the boxes of those it drives
    activation = wrinkle_activation(faps)
    driven = np.zeros(lined.shape, bool)
    for name in wrinkle_drivers().names:
        if activation[_region(name)] > 0:
            driven[_region_pixels(default_face, face_renderer, name, vertices,
                                  inside=0.0)] = True
    untouched = np.zeros(lined.shape, bool)
    for name in wrinkle_drivers().names:
        if activation[_region(name)] == 0:
            untouched[_region_pixels(default_face, face_renderer, name, vertices)] = True
    # a triangle with one corner in a region carries its depth a triangle's width further
    untouched &= ~binary_dilation(driven, iterations=12)
    assert untouched.sum() > 100
    np.testing.assert_array_equal(lined[untouched], smooth[untouched])


@pytest.mark.render
def test_the_neutral_face_has_no_wrinkles(default_face, face_renderer):
    rest = np.asarray(default_face.vertices, np.float32)
    face_renderer.set_faps(_expression("surprise"))
    face_renderer.frame(rest)
    without = face_renderer.frame(rest, faps=np.zeros(84))
    face_renderer.set_faps(None)
    np.testing.assert_array_equal(face_renderer.frame(rest), without)


@pytest.mark.render
def test_the_forehead_lines_deepen_with_the_brow_raise(default_face, face_renderer):
    """The luminance the lines take from the forehead spreads wider as the brows rise, and
    not at all in the neutral face."""
    spreads = []
    for share in (0.0, 0.5, 1.0):
        faps = _brow_raise() * share
        vertices = default_face.deform_frame(faps)
        smooth = _luminance(face_renderer.frame(vertices, faps=np.zeros(84)))
        lined = _luminance(face_renderer.frame(vertices, faps=faps))
        rows, cols = _region_pixels(default_face, face_renderer, "forehead", vertices)
        spreads.append(float((lined[rows, cols] - smooth[rows, cols]).std()))
    assert spreads[0] == 0 and spreads[1] > 1.0 and spreads[2] > 1.5 * spreads[1], spreads


@pytest.mark.render
def test_a_closed_lid_reads_as_skin_not_a_dark_seam(default_face, face_renderer):
    closed = _faps(close_t_l_eyelid=1024.0, close_t_r_eyelid=1024.0)
    image = _luminance(face_renderer.frame(default_face.deform_frame(closed), faps=closed))
    fp = default_face.feature_points
    rest = np.asarray(default_face.vertices)
    lid = (rest[fp["3.1"]] + rest[fp["3.3"]]) / 2
    # a square of the closed lid around the pupil's line of sight, a third of the eye wide
    (col, row), = face_renderer.project(lid[None]).round().astype(int)
    half = max(2, int(0.15 * abs(face_renderer.project(rest[[fp["3.5"]]])[0, 0]
                                  - face_renderer.project(rest[[fp["4.5"]]])[0, 0])))
    patch = image[row - half : row + half + 1, col - half : col + half + 1]
    cheek = image[tuple(np.round(face_renderer.project(rest[[fp["5.3"]]])[0, ::-1]).astype(int))]
    assert np.median(patch) > 0.5 * cheek, (np.median(patch), cheek)
    assert np.percentile(patch, 10) > 40


@pytest.mark.render
def test_the_eye_shows_a_cornea_highlight_brighter_than_the_sclera(default_face):
    from facelib.rendering.scene import FaceRenderer

    face = default_face
    fp = face.feature_points
    rest = np.asarray(face.vertices)
    around = rest[[fp["4.3"], fp["4.5"], fp["3.3"], fp["4.1"]]]
    with FaceRenderer(face, width=320, height=320, framing=around) as renderer:
        image = _luminance(renderer.frame())
        eye = face.parts["eye_l"].vertex_ids
        centre = face.pivots["eye_l"]
        pupil = rest[fp["3.5"]]
        axis = (pupil - centre) / np.linalg.norm(pupil - centre)
        offaxis = np.linalg.norm(np.cross(rest[eye] - centre, axis), axis=1)
        front = (rest[eye] - centre) @ axis > 0
        iris_radius = 0.5 * 1024 * face.fapu["IRISD"]
        sclera = eye[front & (offaxis > 1.4 * iris_radius)
                     & (np.abs(rest[eye, 1] - centre[1]) < 0.3 * iris_radius)]
        cornea = eye[front & (offaxis < iris_radius)]
        sclera_lum = image[_pixels(renderer, rest[sclera])]
        cornea_lum = image[_pixels(renderer, rest[cornea])]
        (col, row), = np.round(renderer.project(pupil[None])).astype(int)
        radius = int(np.ptp(renderer.project(rest[cornea])[:, 0]) / 2)
        disc = image[row - radius : row + radius + 1, col - radius : col + radius + 1]
    assert sclera_lum.size > 5 and cornea_lum.size > 5
    assert disc.max() > np.median(sclera_lum) + 15, (disc.max(), np.median(sclera_lum))
