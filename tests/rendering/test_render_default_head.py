"""The issue's pixel checks on the real default head (skipped while the engine is absent)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.rendering.scene import FaceRenderer

pytestmark = pytest.mark.render

engine = pytest.importorskip("facelib.engine")
W, H = 200, 200


@pytest.fixture(scope="module")
def head(default_face):
    face = default_face
    with FaceRenderer(face, width=W, height=H) as renderer:
        yield face, renderer


def test_jaw_open_moves_mouth_pixels_not_forehead(head, fap_frame):
    face, renderer = head
    neutral = renderer.frame(face.deform_frame(fap_frame()))
    opened = renderer.frame(face.deform_frame(fap_frame(f3=600)))
    diff = np.abs(neutral.astype(int) - opened.astype(int)).sum(axis=2)
    chin_row = renderer.project(face.vertices[face.feature_points["2.1"]])[0, 1]
    eye_row = renderer.project(face.pivots["eye_l"])[0, 1]
    changed = np.flatnonzero(diff.max(axis=1) > 30)
    assert changed.size > 3
    assert changed.min() > eye_row  # forehead and eyes untouched
    assert np.abs(changed - chin_row).min() < 10  # the change is around the mouth and chin


def test_eyes_turned_left_move_the_iris_right_in_the_image(head, fap_frame):
    face, renderer = head
    centres = renderer.project(np.vstack([face.pivots["eye_l"], face.pivots["eye_r"]]))

    def iris_x(image: np.ndarray) -> float:
        xs = []
        for cx, cy in centres:
            r0, c0 = int(cy) - 6, int(cx) - 10
            patch = image[r0 : r0 + 12, c0 : c0 + 20].astype(int)
            # the blue iris (the lids' occlusion darkens the eye corners too, so darkness
            # alone no longer finds it)
            iris = patch[..., 2] > patch[..., 0] + 15
            xs.append(np.nonzero(iris)[1].mean() + c0)
        return float(np.mean(xs))

    x0 = iris_x(renderer.frame(face.deform_frame(fap_frame())))
    x_left = iris_x(renderer.frame(face.deform_frame(fap_frame(f23=40000, f24=40000))))
    x_right = iris_x(renderer.frame(face.deform_frame(fap_frame(f23=-40000, f24=-40000))))
    # FAP 23/24 positive turns the eyes to the face's own left, the image's right
    assert x_left > x0 + 1.5
    assert x_right < x0 - 1.5


def test_open_mouth_close_up_shows_a_dark_cavity_not_the_background(fap_frame):
    """Framing the mouth alone must not clip the cavity behind it (the far plane follows
    the whole head), and the cavity is painted dark."""
    face = engine.load_face(None)
    fp = face.feature_points
    mouth = face.vertices[[fp[k] for k in ("8.3", "8.4", "8.1", "2.1")]]
    with FaceRenderer(face, width=W, height=H, framing=mouth) as renderer:
        moved = face.deform_frame(fap_frame(f3=900))
        image = renderer.frame(moved).astype(int)
        background = np.asarray(renderer.look.background) * 255
        # the opening: between the lip midpoints, inward of the corners
        (_, uy), (_, ly) = renderer.project(moved[[fp["2.2"], fp["2.3"]]])
        (cl, _), (cr, _) = renderer.project(moved[[fp["2.4"], fp["2.5"]]])
    rows = slice(int(uy) + 2, int(ly) - 1)
    cols = slice(int(min(cl, cr)) + 4, int(max(cl, cr)) - 3)
    opening = image[rows, cols]
    assert opening.shape[0] > 3
    assert not np.any(np.abs(opening - background).sum(axis=2) < 12)
    assert np.percentile(opening.sum(axis=2), 25) < 250  # a dark cavity shows


def test_resting_and_bilabial_lips_hide_the_teeth():
    """Closed lips meet: no tooth shows through a slit (teeth painted green to find them)."""
    import dataclasses

    from facelib.visemes import viseme_targets
    from facelib.visemes.tables import viseme_id

    face = engine.load_face(None)
    colours = np.array(face.vertex_colors)
    for part in ("teeth_upper", "teeth_lower"):
        colours[face.parts[part].vertex_ids] = (0.0, 1.0, 0.0)
    painted = dataclasses.replace(face, vertex_colors=colours)
    fp = face.feature_points
    mouth = face.vertices[[fp[k] for k in ("8.3", "8.4", "8.1", "2.1")]]
    with FaceRenderer(painted, width=400, height=300, framing=mouth) as renderer:
        for values in (np.zeros(84, np.float32), viseme_targets()[viseme_id("PP")],
                       viseme_targets()[viseme_id("E")]):
            image = renderer.frame(face.deform_frame(values)).astype(int)
            teeth = ((image[..., 1] > image[..., 0] + 40)
                     & (image[..., 1] > image[..., 2] + 40)).sum()
            if values.any() and values[2] > 300:  # 'E' opens the mouth: the check sees teeth
                assert teeth > 500
            else:
                assert teeth < 60


def test_closed_lids_cover_the_whole_eye(fap_frame):
    """A blink hides the sclera right into the corners (white pixels of a close-up)."""
    face = engine.load_face(None)
    fp = face.feature_points
    lids = face.vertices[[fp[k] for k in ("3.1", "3.2", "3.3", "3.4")]]
    side = np.array([0.012, 0.0, 0.0])
    around = np.vstack([lids + side, lids - side])
    closed = fap_frame(f19=1024, f20=1024)
    with FaceRenderer(face, width=400, height=150, framing=around) as renderer:
        white = []
        for values in (fap_frame(), closed):
            image = renderer.frame(face.deform_frame(values)).astype(int)
            # sclera: bright and grey (off-white, and darker in the lids' occlusion)
            white.append(((image.min(2) > 140) & (np.ptp(image, axis=2) < 40)).sum())
    assert white[0] > 500
    assert white[1] < 0.03 * white[0]


def test_named_framings_and_the_default_face_close_up():
    """Issue 14: the default frames the face (brow to chin over half the frame height);
    'head' and 'bust' step back; an unknown name is an error."""
    from facelib.errors import ParameterError

    face = engine.load_face(None)
    fp = face.feature_points
    spans = {}
    for name in ("face", "head", "bust"):
        with FaceRenderer(face, width=320, height=240, framing=name) as renderer:
            (_, brow), (_, chin) = renderer.project(face.vertices[[fp["4.3"], fp["2.1"]]])
            spans[name] = (chin - brow) / 240
    with FaceRenderer(face, width=320, height=240) as renderer:
        (_, brow), (_, chin) = renderer.project(face.vertices[[fp["4.3"], fp["2.1"]]])
    assert (chin - brow) / 240 == pytest.approx(spans["face"])
    assert spans["face"] >= 0.5
    assert spans["face"] > spans["head"] > spans["bust"] > 0.15
    with pytest.raises(ParameterError, match="framing must be one of"):
        FaceRenderer(face, width=64, height=64, framing="shoulders")


def test_closed_lids_cover_the_cartoons_bigger_eyes(fap_frame):
    """Issue 15: on the cartoon head (eyes much taller than the default head's) the
    transferred upper lids close over the whole eye too."""
    from pathlib import Path

    from facelib.engine.setup import read_landmarks, setup_face

    heads = Path(__file__).resolve().parents[2] / "examples" / "heads"
    face = setup_face(heads / "cartoon_head.obj",
                      landmarks=read_landmarks(heads / "cartoon_landmarks.json"))
    fp = face.feature_points
    lids = face.vertices[[fp[k] for k in ("3.1", "3.2", "3.3", "3.4")]]
    side = np.array([0.014, 0.0, 0.0])
    with FaceRenderer(face, width=400, height=150, framing=np.vstack([lids + side,
                                                                      lids - side])) as renderer:
        white = []
        for values in (fap_frame(), fap_frame(f19=1024, f20=1024)):
            image = renderer.frame(face.deform_frame(values)).astype(int)
            white.append(((image.min(2) > 120) & (np.ptp(image, axis=2) < 40)).sum())
    assert white[0] > 1000
    assert white[1] < 0.01 * white[0]


def _without_lashes(face):  # type: ignore[no-untyped-def]
    """The same head with the lash triangles left out (for a before/after render)."""
    from types import SimpleNamespace

    lashes = set(face.parts["lashes"].vertex_ids.tolist())
    keep = ~np.isin(face.triangles, list(lashes)).any(axis=1)
    parts = {k: v for k, v in face.parts.items() if k != "lashes"}
    return SimpleNamespace(vertices=face.vertices, triangles=face.triangles[keep],
                           vertex_colors=face.vertex_colors, parts=parts,
                           vertex_ao=face.vertex_ao, feature_points=face.feature_points,
                           fapu=face.fapu)


@pytest.mark.parametrize("closure", [0.0, 1024.0])
def test_lashes_darken_the_lid_margin(closure, fap_frame):  # type: ignore[no-untyped-def]
    """Issue 14: in a close-up of the left eye, the band along the upper lid margin is
    clearly darker with the lashes than without, open and closed; the forehead is not."""
    face = engine.load_face(None)
    fp = face.feature_points
    centre = face.pivots["eye_l"]
    box = centre + np.array([[-0.02, -0.012, 0.0], [0.02, 0.012, 0.0]])
    values = fap_frame(close_t_l_eyelid=closure, close_t_r_eyelid=closure)
    moved = face.deform_frame(values)
    images = []
    for shown in (face, _without_lashes(face)):
        with FaceRenderer(shown, width=320, height=200, framing=box) as renderer:
            images.append(renderer.frame(moved).astype(float).mean(axis=2))
            (x, y), = renderer.project(moved[fp["3.1"]])
            (x_out, _), = renderer.project(moved[fp["3.1"]] + [0.009, 0.0, 0.0])
    x, y, span = int(x), int(y), int(abs(x_out - x))
    band = (slice(max(y - 12, 0), y + 12), slice(x - span, x + span))
    with_lashes, bare = images[0][band], images[1][band]
    darker = (bare - with_lashes) > 40
    assert bare.mean() - with_lashes.mean() > 20  # grey levels of 255
    assert darker.mean() > 0.12  # many dark strands, not a tint
    assert not darker.all(axis=1).any()  # skin between the strands: not a black band
    assert np.abs(images[0][:20] - images[1][:20]).max() < 1  # the brow area is untouched


@pytest.mark.parametrize("pose", ["surprise", "aa"])
def test_open_mouth_shows_teeth_a_dark_cavity_and_a_darker_tongue(pose):
    """Issue 14 (look): looking into the open mouth along its midline, from the upper lip
    down: the upper teeth (ivory, shaded, not paper white), a dark cavity band above the
    tongue, the tongue (red, clearly darker than the lips), the lower incisors' edges, then
    the lower lip."""
    from facelib.expressions import default_library
    from facelib.visemes import viseme_targets
    from facelib.visemes.tables import viseme_id

    face = engine.load_face(None)
    fp = face.feature_points
    values = (viseme_targets()[viseme_id("aa")] if pose == "aa"
              else default_library().get(pose).values)
    moved = face.deform_frame(values)
    mouth = face.vertices[[fp[k] for k in ("8.3", "8.4", "9.15", "2.1")]]
    with FaceRenderer(face, width=480, height=360, framing=mouth) as renderer:
        image = renderer.frame(moved).astype(int)
        (ux, uy), (lx, ly), (_, oy) = renderer.project(moved[[fp["2.2"], fp["2.3"], fp["8.2"]]])
    cx = int((ux + lx) / 2 + 0.5)
    column = image[int(uy) : int(ly) + 1, cx - 3 : cx + 4].mean(1)  # (rows, 3), top down
    lip = image[int((ly + oy) / 2) - 2 : int((ly + oy) / 2) + 3, cx - 3 : cx + 4]
    lip = lip.reshape(-1, 3).mean(0)
    red, green, blue = column.T
    teeth = (column.min(1) > 140) & (red - blue < 60)
    # the upper teeth are judged a little off the midline, on the left central incisor: the
    # midline holds the small notch between the two incisors' edges (tools/build_teeth.py)
    side = image[int(uy) : int(ly) + 1, cx + 9 : cx + 16].mean(1)
    upper = (side.min(1) > 140) & (side[:, 0] - side[:, 2] < 60)
    dark = column.max(1) < 60
    tongue = (red > green + 40) & (red < 170)
    rows = np.arange(len(column))
    upper_teeth = upper & (rows < np.flatnonzero(dark)[0])
    lower_teeth = teeth & (rows > np.flatnonzero(tongue)[0])
    # (the old head: a dark notch of a fifth of the opening over a wall of tongue, no
    # lower teeth, teeth at 251 grey levels, the tongue 160 levels from the lips)
    assert dark.sum() > 0.35 * len(column) and tongue.sum() >= 5
    # the dark cavity lies above the tongue, the lower incisors below it
    assert np.flatnonzero(dark)[-1] < np.flatnonzero(tongue)[0]
    assert lower_teeth.sum() >= 3
    # ivory with some shading, not a flat pure-white strip
    assert upper_teeth.sum() >= 3
    assert side[upper_teeth].max() < 245
    assert (side[:, 0] - side[:, 2])[upper_teeth].min() > 20
    # the tongue reads against the lips: darker, and far from their colour
    tongue_colour = column[tongue].mean(0)
    assert tongue_colour.sum() < lip.sum() - 180
    assert np.abs(tongue_colour - lip).sum() > 180
