"""The default head's look (issue 14, item 4): occlusion, sclera, lights, anti-aliasing."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from facelib.errors import FaceModelError, ParameterError
from facelib.rendering.scene import FaceRenderer, downsample, load_look

pytestmark = pytest.mark.render

engine = pytest.importorskip("facelib.engine")


def _luminance(image: np.ndarray) -> np.ndarray:
    return image.astype(float) @ [0.2126, 0.7152, 0.0722]


def _sample(image: np.ndarray, pixels: np.ndarray) -> np.ndarray:
    cols, rows = np.round(pixels).astype(int).T
    inside = (rows >= 0) & (rows < image.shape[0]) & (cols >= 0) & (cols < image.shape[1])
    return image[rows[inside], cols[inside]]


def _socket_and_cheek(face) -> tuple[np.ndarray, np.ndarray]:
    """Skin vertices of a ring round the left eyeball (0-4 mm outside it, not behind it)
    and of a patch of the left cheekbone."""
    skin = face.parts["skin"].vertex_ids
    centre = face.pivots["eye_l"]
    radius = np.linalg.norm(face.vertices[face.parts["eye_l"].vertex_ids] - centre, axis=1).max()
    d = np.linalg.norm(face.vertices[skin] - centre, axis=1)
    ring = skin[(d > radius) & (d < radius + 0.004)
                & (face.vertices[skin, 2] > centre[2] - 0.005)]
    cheek_point = face.vertices[face.feature_points["5.3"]]
    cheek = skin[np.linalg.norm(face.vertices[skin] - cheek_point, axis=1) < 0.015]
    return ring, cheek


def test_the_default_head_has_baked_occlusion_dark_in_the_sockets(default_face):
    face = default_face
    assert face.vertex_ao is not None and face.vertex_ao.shape == (face.n_vertices,)
    assert face.vertex_ao.min() >= 0.0 and face.vertex_ao.max() <= 1.0
    ring, cheek = _socket_and_cheek(face)
    assert ring.size > 10 and cheek.size > 5
    assert np.median(face.vertex_ao[ring]) < np.median(face.vertex_ao[cheek]) - 0.25
    assert np.median(face.vertex_ao[cheek]) > 0.8


def test_occlusion_darkens_the_eye_sockets_not_the_cheeks(default_face):
    """Rendered with and without the baked occlusion: the eye opening and the ring of lids
    round it lose light, the cheekbone keeps its own (the eyes sit in sockets)."""
    face = default_face
    centre = face.pivots["eye_l"]
    radius = np.linalg.norm(face.vertices[face.parts["eye_l"].vertex_ids] - centre, axis=1).max()
    bare = dataclasses.replace(face, vertex_ao=None)
    images = {}
    for label, which in (("ao", face), ("bare", bare)):
        with FaceRenderer(which, width=320, height=240) as renderer:
            images[label] = _luminance(renderer.frame(face.vertices))
            cheekbone = face.vertices[face.feature_points["5.3"]]
            (cx, cy), (ex, _), (kx, ky) = renderer.project(
                np.vstack([centre, centre + np.array([radius, 0, 0]), cheekbone]))
    rows, cols = np.mgrid[:240, :320]
    r = abs(ex - cx)
    socket = np.hypot(cols - cx, rows - cy) < 1.3 * r
    cheek = np.hypot(cols - kx, rows - ky) < 0.5 * r
    ratio = {name: images["ao"][m].mean() / images["bare"][m].mean()
             for name, m in (("socket", socket), ("cheek", cheek))}
    assert ratio["socket"] < 0.95
    assert ratio["cheek"] > 0.99


def test_sclera_is_off_white_and_shaded_under_the_upper_lid(default_face):
    face = default_face
    fp = face.feature_points
    lid_points = face.vertices[[fp[k] for k in ("3.1", "3.3")]]
    side = np.array([0.013, 0.0, 0.0])
    around = np.vstack([lid_points + side, lid_points - side])
    with FaceRenderer(face, width=320, height=160, framing=around) as renderer:
        image = renderer.frame(face.vertices).astype(int)
        (_, top), (_, bottom) = renderer.project(lid_points)
    lum = _luminance(image)
    # bright grey pixels, less the catchlights of the key light on the cornea
    sclera = (image.min(2) > 90) & (np.ptp(image, axis=2) < 30) & (lum < 240)
    rows = np.nonzero(sclera)[0]
    assert rows.size > 300
    assert top < rows.min() and rows.max() < bottom  # between the lids
    assert np.percentile(lum[sclera], 90) < 235  # off-white, never paper white
    first, last = rows.min(), rows.max()
    upper = rows < first + 0.25 * (last - first)  # the band just under the upper lid
    middle = np.abs(rows - (first + last) / 2) < 0.2 * (last - first)
    assert upper.sum() > 20 and middle.sum() > 20
    assert lum[sclera][upper].mean() < 0.93 * lum[sclera][middle].mean()


def test_three_lights_come_from_three_directions(synthetic_face):
    """Each light alone on the synthetic (sphere) head: the key lights the upper image
    right, the fill the left, the rim only the rim."""
    look = load_look()
    lights = {light["name"]: light for light in look.lights}
    assert set(lights) == {"key", "fill", "rim"}
    centroids, rim_profile = {}, None
    for name, light in lights.items():
        alone = dataclasses.replace(look, lights=(light,), ambient=(0.0, 0.0, 0.0))
        with FaceRenderer(synthetic_face, width=200, height=200, framing="head",
                          look=alone) as renderer:
            lum = _luminance(renderer.frame(synthetic_face.vertices))
            centre = renderer.project(np.zeros((1, 3)))[0]
        lit = lum > np.percentile(lum, 97)
        rows, cols = np.nonzero(lit)
        centroids[name] = (cols.mean() - centre[0], rows.mean() - centre[1])
        if name == "rim":
            rim_profile = lum[int(centre[1]), :]
    assert centroids["key"][0] > 10 and centroids["key"][1] < -10  # right and up
    assert centroids["fill"][0] < -10  # left
    middle = rim_profile[90:110].mean()
    assert rim_profile.max() > middle + 40  # the rim light grazes the silhouette only


def _edge_error(image: np.ndarray, reference: np.ndarray) -> float:
    return float(np.abs(image.astype(int) - reference.astype(int)).mean())


def test_antialiasing_approaches_the_ideal_coverage(synthetic_face):
    """MSAA and supersampling both bring the silhouette nearer a 4x4 box-filtered
    reference than aliased pixels do, and give it intermediate colours."""
    face = synthetic_face
    images = {}
    for mode, size in (("off", 160), ("msaa", 160), ("supersample", 160), ("reference", 640)):
        with FaceRenderer(face, width=size, height=size, framing="head",
                          antialias="off" if mode == "reference" else mode) as renderer:
            assert renderer.antialias == ("off" if mode == "reference" else mode)
            images[mode] = renderer.frame(face.vertices)
    reference = downsample(images.pop("reference"), 4)
    errors = {mode: _edge_error(image, reference) for mode, image in images.items()}
    assert errors["msaa"] < 0.7 * errors["off"]
    assert errors["supersample"] < 0.7 * errors["off"]


def test_antialiasing_gives_the_silhouette_intermediate_values(synthetic_face):
    """An unlit white face on black: without anti-aliasing every pixel is 0 or 255 (a
    staircase); with it, most silhouette pixels take one of the partial-coverage values."""
    face = synthetic_face
    white = dataclasses.replace(load_look(), lights=(), ambient=(1.0, 1.0, 1.0))

    class Flat:
        vertices, triangles, parts = face.vertices, face.triangles, face.parts
        vertex_colors = np.ones_like(face.vertices)

    levels, counts = {}, {}
    for mode in ("off", "msaa", "supersample"):
        with FaceRenderer(Flat(), width=160, height=160, framing="head", look=white,
                          background=(0.0, 0.0, 0.0), antialias=mode) as renderer:
            grey = renderer.frame(face.vertices)[..., 1].astype(int)
        partial = (grey > 8) & (grey < 247)
        levels[mode] = len(np.unique(grey[partial] // 16))
        counts[mode] = int(partial.sum())
        if mode == "off":
            inside = grey > 127
            edge = (inside != np.roll(inside, 1, axis=0)) | (inside != np.roll(inside, 1, 1))
            perimeter = int(edge.sum())
    assert counts["off"] == 0 and perimeter > 100
    for mode in ("msaa", "supersample"):
        assert counts[mode] > 0.5 * perimeter
        assert levels[mode] >= 3


def test_downsample_averages_blocks_with_rounding():
    image = np.zeros((4, 6, 3), np.uint8)
    image[:2, :2] = [[[0, 10, 255], [1, 10, 255]], [[1, 10, 255], [1, 11, 255]]]
    out = downsample(image, 2)
    assert out.shape == (2, 3, 3) and out.dtype == np.uint8
    assert out[0, 0].tolist() == [1, 10, 255]  # 0.75 -> 1, 10.25 -> 10
    assert downsample(image, 1) is image


def test_bad_occlusion_and_antialias_arguments(synthetic_face):
    class Occluded:
        def __init__(self, face, ao):
            self.vertices, self.triangles = face.vertices, face.triangles
            self.vertex_colors, self.parts, self.vertex_ao = face.vertex_colors, face.parts, ao

    with pytest.raises(FaceModelError, match="vertex_ao must have shape"):
        FaceRenderer(Occluded(synthetic_face, np.ones(3)), width=32, height=32)
    with pytest.raises(ParameterError, match="antialias must be one of"):
        FaceRenderer(synthetic_face, width=32, height=32, antialias="fxaa")  # type: ignore[arg-type]


def test_occlusion_dims_the_highlights_and_a_part_may_set_its_strength(synthetic_face):
    """A black, glossy sphere shows only its highlights: the baked occlusion dims them by
    the same factor as the colour (no glints deep in the mouth), and a part's own
    occlusion_strength (the teeth's) replaces the look's."""
    class Painted:
        def __init__(self, face, ao):
            self.vertices, self.triangles, self.parts = face.vertices, face.triangles, face.parts
            self.vertex_colors = np.zeros_like(face.vertices)
            self.vertex_ao = np.full(len(face.vertices), ao, np.float32)

    glossy = {"roughness": 0.6, "metallic": 0.0, "occlusion_power": 1.0}
    look = dataclasses.replace(load_look(), ambient=(0.0, 0.0, 0.0), occlusion=0.5,
                               shading={"wrap": 0.0, "specular": 0.2})
    peaks = []
    for ao, strength in ((1.0, {}), (0.0, {}), (0.0, {"occlusion_strength": 1.0})):
        shiny = dataclasses.replace(look, parts={"default": {**glossy, **strength}})
        with FaceRenderer(Painted(synthetic_face, ao), width=120, height=120, framing="head",
                          look=shiny, background=(0.0, 0.0, 0.0)) as renderer:
            peaks.append(float(_luminance(renderer.frame(synthetic_face.vertices)).max()))
    assert 120 < peaks[0] < 250  # unsaturated
    # half the light: 0.5 ** (1 / 2.2) = 0.73 of the sRGB level
    assert peaks[1] == pytest.approx(0.73 * peaks[0], abs=8)
    assert peaks[2] < 3
