"""The face scene: per-part meshes, materials, three-point lights, auto-framed camera.

:class:`FaceRenderer` owns one offscreen OpenGL context and renders ``(V, 3)`` vertex arrays
of one face to ``(H, W, 3) uint8`` images. pyrender uploads a primitive's vertex buffer once
(upstream issue #43), so changing ``Primitive.positions`` after the first render shows
nothing; :class:`FaceRenderer` instead rewrites the interleaved vertex buffer of each part
in place with ``glBufferSubData`` (positions and the per-frame smooth normals), which is the
cheapest correct update measured in ``benchmarks/render_mesh_update.py``. Swapping in new
mesh nodes (``mesh_update="swap"``) is also correct but re-creates every buffer per frame.

Everything that is a matter of taste (materials per part, lights, shading, ambient
occlusion strength, anti-aliasing, camera field of view, background) lives in
``facelib/data/render_look.json``. Faces are shaded by facelib's own shader
(``facelib/data/shaders/face.vert``/``face.frag``: wrap diffuse plus normalised Blinn-Phong
under the look's directional lights), which replaces pyrender's PBR shader for mesh
primitives: it reads the same uniforms and costs about a third as much on llvmpipe.

Anti-aliasing: pyrender renders into a 4x multisampled framebuffer only where its platform
says it has framebuffers (EGL); its OSMesa platform says no, although Mesa's OSMesa contexts
have them. :class:`FaceRenderer` turns that path on where ``GL_MAX_SAMPLES`` allows 4
samples (``"msaa"``), and otherwise renders ``k`` times larger and averages ``k x k``
blocks (``"supersample"``, ``k`` from the look).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from facelib import data
from facelib.engine.colours import occlusion_factor, srgb_to_linear
from facelib.errors import FaceModelError, ParameterError, RenderError
from facelib.rendering.gl_state import install_uniform_cache
from facelib.rendering.normals import normal_operator, vertex_normals
from facelib.rendering.platform import INSTALL_HINT, import_pyrender
from facelib.rendering.protocols import Deformable
from facelib.rendering.readback import install_colour_readback
from facelib.rendering.rigid_pieces import RigidGroup, rigid_groups, rigid_pose
from facelib.rendering.skin_map import (
    SkinLayout,
    skin_layout,
    tint_factors,
    wrinkle_activation,
    wrinkle_drivers,
)

__all__ = [
    "ANTIALIAS",
    "FRAMINGS",
    "FaceRenderer",
    "Look",
    "PartMesh",
    "downsample",
    "frame_camera",
    "framing_points",
    "install_program_cache",
    "load_look",
    "split_parts",
    "vertex_normals",
]


# -- look (data) -------------------------------------------------------------------------


@dataclass(frozen=True)
class Look:
    """Materials, lights, shading, occlusion, anti-aliasing and camera settings (see
    ``facelib/data/render_look.json``).

    ``shading``: ``wrap`` and ``specular`` of the face shader; ``occlusion`` and
    ``occlusion_power``: how the baked ambient occlusion darkens colours (a part's material
    may set its own ``occlusion_strength`` and ``occlusion_power``); ``supersample``: the
    factor of the fallback anti-aliasing; ``skin_tint``: the skin's colour and shine
    variation by region (:func:`facelib.rendering.skin_map.tint_factors`).
    """

    parts: Mapping[str, Mapping[str, float]]
    lights: tuple[Mapping[str, Any], ...]
    ambient: tuple[float, float, float]
    background: tuple[float, float, float]
    yfov_deg: float
    margin: float
    framings: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    shading: Mapping[str, float] = field(default_factory=lambda: {"wrap": 0.0,
                                                                  "specular": 0.04})
    occlusion: float = 1.0
    occlusion_power: float = 1.0
    supersample: int = 2
    skin_tint: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)

    def material(self, part: str) -> Mapping[str, float]:
        return self.parts.get(part, self.parts["default"])


@lru_cache(maxsize=1)
def load_look() -> Look:
    """The default :class:`Look` from ``facelib/data/render_look.json``."""
    raw = data.json_data("render_look.json")
    return Look(
        parts=raw["parts"],
        lights=tuple(raw["lights"]),
        ambient=tuple(raw["ambient"]),
        background=tuple(raw["background"]),
        yfov_deg=float(raw["camera"]["yfov_deg"]),
        margin=float(raw["camera"]["margin"]),
        framings=MappingProxyType(raw.get("framings", {})),
        shading=MappingProxyType({k: float(v) for k, v in raw["shading"].items()
                                  if not k.startswith("_")}),
        occlusion=float(raw["occlusion"]["strength"]),
        occlusion_power=float(raw["occlusion"]["power"]),
        supersample=int(raw["antialias"]["supersample"]),
        skin_tint=MappingProxyType(raw.get("skin_tint", {})),
    )


FRAMINGS = ("face", "head", "bust")
"""Named framings of :class:`FaceRenderer` (defined in ``render_look.json``)."""

ANTIALIAS = ("auto", "msaa", "supersample", "off")
"""Anti-aliasing modes of :class:`FaceRenderer`: ``"auto"`` takes 4x MSAA where the context
has it and supersampling otherwise."""


def framing_points(face: Any, name: str, *, look: Look | None = None) -> np.ndarray:
    """``(K, 3) float32`` points whose bounding box the camera frames for framing ``name``.

    ``face`` needs ``vertices``; ``"face"`` also needs ``feature_points`` (id -> vertex) with
    the look's points, and falls back to the whole mesh (``"head"``) when it lacks them; a
    framing's ``exclude_parts`` leaves those parts of ``face.parts`` out of the box.
    """
    look = look or load_look()
    if name not in look.framings:
        raise ParameterError(f"framing must be one of {tuple(look.framings)} or an (N, 3) "
                             f"array, got {name!r}")
    spec = look.framings[name]
    vertices = np.asarray(face.vertices, np.float32)
    fps = getattr(face, "feature_points", {}) or {}
    wanted = spec.get("feature_points", [])
    if spec.get("all_vertices") or not all(k in fps for k in wanted):
        box = vertices
        parts = getattr(face, "parts", {}) or {}
        left_out = [parts[p].vertex_ids for p in spec.get("exclude_parts", ()) if p in parts]
        if left_out:
            keep = np.ones(len(vertices), bool)
            keep[np.concatenate(left_out)] = False
            box = vertices[keep]
    else:
        box = vertices[[fps[k] for k in wanted]]
    lo, hi = box.min(axis=0), box.max(axis=0)
    height = float(hi[1] - lo[1])
    top = np.array([(lo[0] + hi[0]) / 2, hi[1] + float(spec.get("above", 0.0)) * height,
                    (lo[2] + hi[2]) / 2], np.float32)
    bottom = top.copy()
    bottom[1] = lo[1] - float(spec.get("below", 0.0)) * height
    return np.vstack([box, top, bottom]).astype(np.float32)


# -- geometry (pure numpy) ---------------------------------------------------------------


@dataclass(frozen=True)
class PartMesh:
    """One rendered piece of a face.

    Attributes
    ----------
    name: the face part name (``skin``, ``eye_l``, ...; ``rest`` for triangles of no part).
    vertex_ids: ``(Vp,) int64`` global vertex ids used by this piece, sorted.
    triangles: ``(Fp, 3) uint32`` indices into ``vertex_ids``, wound counter-clockwise seen
        from outside.
    double_sided: whether both faces are drawn; None: as the part's material says.
    """

    name: str
    vertex_ids: np.ndarray
    triangles: np.ndarray
    double_sided: bool | None = None


def _orient_outward(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """``triangles`` with winding flipped if most of their area faces the part's centre."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    outward = (a + b + c) / 3.0 - vertices[np.unique(triangles)].mean(axis=0)
    if np.einsum("ij,ij->", cross, outward) < 0:
        return triangles[:, ::-1].copy()
    return triangles


def split_parts(
    vertices: np.ndarray, triangles: np.ndarray, parts: Mapping[str, Any] | None
) -> list[PartMesh]:
    """Split a face into renderable pieces, one per part plus ``rest`` for unclaimed triangles.

    ``vertices`` ``(V, 3)``, ``triangles`` ``(F, 3)`` global ids; ``parts`` maps names to
    objects with ``triangles (Fp, 3)`` global ids (``Face.parts``). Windings are made to face
    outward per piece so back-face culling never hides the front of a part.
    """
    vertices = np.asarray(vertices, np.float64)
    triangles = np.asarray(triangles, np.int64)
    n_vertices = len(vertices)
    if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
        raise FaceModelError(f"face triangles must have shape (F, 3), F > 0; got {triangles.shape}")
    if triangles.min() < 0 or triangles.max() >= n_vertices:
        raise FaceModelError(
            f"face triangles index vertex {int(triangles.max())} but there are {n_vertices}"
        )

    def keys(tris: np.ndarray) -> np.ndarray:
        s = np.sort(tris, axis=1)
        return (s[:, 0] * n_vertices + s[:, 1]) * n_vertices + s[:, 2]

    pieces: list[tuple[str, np.ndarray]] = []
    claimed = np.zeros(len(triangles), bool)
    all_keys = keys(triangles)
    for name, part in (parts or {}).items():
        tris = np.asarray(part.triangles, np.int64).reshape(-1, 3)
        if len(tris) == 0:
            continue
        if tris.min() < 0 or tris.max() >= n_vertices:
            raise FaceModelError(
                f"part {name!r} triangles index vertex {int(tris.max())} but there are "
                f"{n_vertices}"
            )
        claimed |= np.isin(all_keys, keys(tris))
        pieces.append((name, tris))
    if not claimed.all():
        pieces.append(("rest", triangles[~claimed]))
    out = []
    for name, tris in pieces:
        ids = np.unique(tris)
        local = np.searchsorted(ids, tris)
        local = _orient_outward(vertices[ids], local)
        out.append(PartMesh(name, ids, local.astype(np.uint32)))
    return out


def frame_camera(
    vertices: np.ndarray, *, aspect: float, yfov: float, margin: float,
    scene_vertices: np.ndarray | None = None,
) -> tuple[np.ndarray, float, float]:
    """Camera pose looking along -z at the face's bounding box, filling the frame.

    Returns ``(pose (4, 4) float64, znear, zfar)``; lengths in the face's units. The camera
    sits on the +z side (the face looks along +z), centred on the box of ``vertices``
    ``(N, 3)``, far enough that the box times ``margin`` fits both the vertical field of
    view ``yfov`` (radians) and the horizontal one given by ``aspect`` = width / height.
    The clipping planes enclose the bounding sphere of ``scene_vertices`` (default:
    ``vertices``) with room to spare for head motion, so framing a close-up (the mouth)
    never clips what lies behind it (the mouth cavity).
    """
    lo, hi = np.min(vertices, axis=0), np.max(vertices, axis=0)
    centre = (lo + hi) / 2.0
    half = (hi - lo) / 2.0 * margin
    tan_y = np.tan(yfov / 2.0)
    distance = max(half[1] / tan_y, half[0] / (tan_y * aspect), 1e-6) + half[2]
    pose = np.eye(4)
    pose[:3, 3] = (centre[0], centre[1], centre[2] + distance)
    everything = vertices if scene_vertices is None else scene_vertices
    s_lo, s_hi = np.min(everything, axis=0), np.max(everything, axis=0)
    radius = max(float(np.linalg.norm(s_hi - s_lo)) / 2.0, 1e-6)
    reach = float(np.linalg.norm(pose[:3, 3] - (s_lo + s_hi) / 2.0))
    znear = max(reach - 1.5 * radius, reach * 0.01)
    zfar = reach + 1.5 * radius
    return pose, float(znear), float(zfar)


def _light_pose(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Pose whose -z axis points from the light (at the given direction) toward the origin."""
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    towards_light = np.array([np.sin(az) * np.cos(el), np.sin(el), np.cos(az) * np.cos(el)])
    z = towards_light / np.linalg.norm(towards_light)
    up = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.99 else np.array([0.0, 0.0, 1.0])
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2] = x, np.cross(z, x), z
    return pose


def _part_occlusion(look: Look, pieces: Sequence[Any], n: int) -> tuple[np.ndarray, np.ndarray]:
    """``(n,)`` occlusion strength and power of each vertex: the look's, or its part's own
    (``occlusion_strength``, ``occlusion_power`` in the part's material)."""
    strength = np.full(n, look.occlusion, np.float32)
    power = np.full(n, look.occlusion_power, np.float32)
    for piece in pieces:
        spec = look.material(piece.name)
        strength[piece.vertex_ids] = float(spec.get("occlusion_strength", look.occlusion))
        power[piece.vertex_ids] = float(spec.get("occlusion_power", look.occlusion_power))
    return strength, power


def _occlusion_factor(n: int, occlusion: Any, strength: np.ndarray | float,
                      power: np.ndarray | float = 1.0) -> np.ndarray:
    """``(n,) float32`` how much light baked ambient occlusion lets through to each vertex.

    ``occlusion`` is ``(n,)`` in [0, 1] (1 = open sky, ``Face.vertex_ao``) or None (all
    1); the factor is ``1 - strength * (1 - occlusion ** power)`` (``strength`` and
    ``power`` numbers or ``(n,)``).
    """
    if occlusion is None:
        return np.ones(n, np.float32)
    occlusion = np.asarray(occlusion, np.float32)
    if occlusion.shape != (n,):
        raise FaceModelError(f"face vertex_ao must have shape ({n},), got {occlusion.shape}")
    return occlusion_factor(occlusion, strength=strength, power=power)


def _sub_piece(piece: PartMesh, local: np.ndarray, *, double_sided: bool) -> PartMesh:
    """The part of ``piece`` that triangles ``local`` ``(F, 3)`` (indices into its
    ``vertex_ids``) use, re-indexed to its own vertices."""
    used = np.unique(local)
    return PartMesh(piece.name, piece.vertex_ids[used],
                    np.searchsorted(used, local).astype(np.uint32), double_sided)


def _cull_hidden_sides(pieces: list[PartMesh], vertices: np.ndarray, triangles: np.ndarray,
                       face: Any, look: Look) -> list[PartMesh]:
    """``pieces`` with each part whose material sets ``single_sided_within_es`` cut by
    :func:`facelib.rendering.hair.split_hair` into a single-sided piece (the triangles
    within that many eye separations of the other parts) and a double-sided rest. A face
    without FAPU (``face.fapu["ES"]``) keeps its pieces."""
    from facelib.rendering.hair import split_hair

    es = (getattr(face, "fapu", None) or {}).get("ES")
    wanted = [p for p in pieces if look.material(p.name).get("single_sided_within_es")]
    if es is None or not wanted:
        return pieces
    normals = vertex_normals(vertices, triangles)
    out: list[PartMesh] = []
    for piece in pieces:
        within = float(look.material(piece.name).get("single_sided_within_es", 0.0))
        if piece not in wanted:
            out.append(piece)
            continue
        others = np.ones(len(vertices), bool)
        others[piece.vertex_ids] = False
        single, double = split_hair(vertices[piece.vertex_ids], piece.triangles,
                                    vertices[others], normals[others],
                                    within=within * 1024.0 * float(es))
        out += [_sub_piece(piece, tris, double_sided=sides)
                for tris, sides in ((single, False), (double, True)) if len(tris)]
    return out


def _piece_uv(pieces: Sequence[PartMesh], hair_uv: Any) -> list[np.ndarray | None]:
    """Per piece, the hair card coordinates ``(Vp, 2) float32`` of the ``hair`` piece (the
    face shader draws strands with them) and None for every other piece."""
    if hair_uv is None:
        return [None] * len(pieces)
    hair_uv = np.asarray(hair_uv, np.float32)
    return [hair_uv[p.vertex_ids] if p.name == "hair" else None for p in pieces]


def _face_arrays(face: Deformable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    try:
        vertices = np.asarray(face.vertices, np.float32)
        triangles = np.asarray(face.triangles, np.int64)
    except AttributeError as exc:
        raise FaceModelError(f"{type(face).__name__} has no vertices/triangles: {exc}") from exc
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) == 0:
        raise FaceModelError(f"face vertices must have shape (V, 3), got {vertices.shape}")
    colors = getattr(face, "vertex_colors", None)
    colors = np.full_like(vertices, 0.8) if colors is None else np.asarray(colors, np.float32)
    if colors.shape != vertices.shape:
        raise FaceModelError(
            f"face vertex_colors shape {colors.shape} differs from vertices {vertices.shape}"
        )
    return vertices, triangles, colors


def _shader_file(name: str) -> str:
    """Path of one of facelib's shaders (``facelib/data/shaders``)."""
    return str(data.path(f"shaders/{name}"))


def install_program_cache(pr: Any, renderer: Any, look: Look, *,
                          shaders: str | None = None) -> None:
    """Give pyrender's ``renderer`` (a ``pyrender.Renderer``) facelib's program cache
    (``shaders``: a folder with other ``face.vert`` and ``face.frag`` to draw with, for
    benchmarks; None: facelib's).

    It does two things. It serves facelib's face shader wherever pyrender asks for its
    mesh shader, with the look's ``shading`` numbers as ``#define``s (upper-cased names).
    And it keys compiled programs by shaders and defines only: pyrender keys its cache by
    ``OpenGL.contextdata.getContext()``, which on OSMesa is a fresh ctypes pointer object
    each call, so every frame missed the cache, recompiled every shader and leaked the old
    programs (about 40% of the frame time at 640x480). A renderer has exactly one context.
    Its programs set their uniforms through
    :func:`facelib.rendering.gl_state.install_uniform_cache`.
    """
    base = pr.shader_program.ShaderProgramCache
    old = getattr(renderer, "_program_cache", None)
    if not isinstance(old, base):
        return
    # a look made before the skin's shading numbers existed draws smooth, unscattered skin
    shading: dict[str, float | int] = {"WRINKLE_BUMP": 0.0, "WRINKLE_CREASE": 0.0,
                                       "SKIN_SCATTER": 0.0}
    shading.update({name.upper(): float(value) for name, value in look.shading.items()})
    # the face shader loops over the look's lights (as many as pyrender binds at most)
    shading["LOOK_LIGHTS"] = min(len(look.lights), int(pr.constants.MAX_N_LIGHTS))

    class _FaceProgramCache(base):  # type: ignore[valid-type,misc]  # pyrender is untyped
        def __init__(self, shader_dir: str | None = None):
            super().__init__(shader_dir=shader_dir)
            self._by_source: dict[tuple, Any] = {}

        def get_program(self, vertex_shader: str, fragment_shader: str,
                        geometry_shader: str | None = None,
                        defines: dict | None = None) -> Any:
            defines = dict(defines or {})
            if (vertex_shader, fragment_shader, geometry_shader) == ("mesh.vert", "mesh.frag",
                                                                     None):
                if shaders is None:
                    vertex_shader, fragment_shader = (_shader_file("face.vert"),
                                                      _shader_file("face.frag"))
                else:
                    vertex_shader = str(Path(shaders) / "face.vert")
                    fragment_shader = str(Path(shaders) / "face.frag")
                defines.update(shading)
            key = (vertex_shader, fragment_shader, geometry_shader,
                   tuple(sorted(defines.items())))
            program = self._by_source.get(key)
            if program is None:
                program = super().get_program(vertex_shader, fragment_shader,
                                              geometry_shader, defines)
                install_uniform_cache(program)
                self._by_source[key] = program
            return program

        def clear(self) -> None:
            super().clear()
            self._by_source = {}

    renderer._program_cache = _FaceProgramCache(shader_dir=old.shader_dir)


def downsample(image: np.ndarray, factor: int) -> np.ndarray:
    """Average ``factor x factor`` pixel blocks: ``(H*k, W*k, C) uint8`` -> ``(H, W, C) uint8``.

    A box filter on the 8-bit sRGB values (rounded to nearest), the cheap resolve of a
    supersampled frame.
    """
    if factor == 1:
        return image
    h, w = image.shape[0] // factor, image.shape[1] // factor
    blocks = image[: h * factor, : w * factor].reshape(h, factor, w, factor, -1)
    total = blocks.sum(axis=(1, 3), dtype=np.uint32)
    return ((total + factor * factor // 2) // (factor * factor)).astype(np.uint8)


def _max_samples() -> int:
    """``GL_MAX_SAMPLES`` of the current context (0 where the query fails)."""
    from OpenGL import GL

    try:
        return int(GL.glGetIntegerv(GL.GL_MAX_SAMPLES))
    except Exception:  # noqa: BLE001  # a context without the query has no MSAA
        return 0


# -- the renderer ------------------------------------------------------------------------


class FaceRenderer:
    """Offscreen renderer of one face at one image size (holds an OpenGL context).

    Use as a context manager or call :meth:`close`. :meth:`frame` takes ``(V, 3)`` vertices
    (``Face.deform_frame`` output, same vertex order as ``face.vertices``) and returns
    ``(height, width, 3) uint8`` RGB.

    Parameters
    ----------
    face: object with ``vertices (V, 3)``, ``triangles (F, 3)``, ``vertex_colors (V, 3)`` sRGB
        in [0, 1] and ``parts`` (name -> object with ``triangles``), e.g. ``facelib`` ``Face``.
    width, height: image size in pixels.
    background: sRGB colour behind the face; None takes the look's.
    framing: a named framing (``"face"``, the default: brow to chin fills over half the
        frame height; ``"head"``; ``"bust"``) or ``(N, 3)`` points to frame the camera on.
    mesh_update: ``"buffers"`` rewrites vertex buffers in place (fast), ``"swap"`` replaces the
        mesh nodes each frame.
    antialias: ``"auto"`` (4x MSAA where the context has it, else supersampling),
        ``"msaa"``, ``"supersample"`` (render ``look.supersample`` times larger and average
        blocks) or ``"off"``. pyrender always multisamples on EGL, whatever this says.
        :attr:`antialias` tells the mode in use.
    rigid_pieces: move pieces that moved rigidly by their node's pose instead of uploading
        their vertices (``mesh_update="buffers"`` only; the images differ by float
        rounding at most).
    """

    def __init__(
        self,
        face: Deformable,
        *,
        width: int = 640,
        height: int = 480,
        background: Sequence[float] | None = None,
        framing: np.ndarray | str | None = "face",
        look: Look | None = None,
        mesh_update: Literal["buffers", "swap"] = "buffers",
        offscreen: bool = True,
        antialias: Literal["auto", "msaa", "supersample", "off"] = "auto",
        rigid_pieces: bool = True,
    ):
        for label, value in (("width", width), ("height", height)):
            if not isinstance(value, (int, np.integer)) or not 8 <= value <= 8192:
                raise ParameterError(f"{label} must be an integer in [8, 8192], got {value!r}")
        if mesh_update not in ("buffers", "swap"):
            raise ParameterError(f"mesh_update must be 'buffers' or 'swap', got {mesh_update!r}")
        if antialias not in ANTIALIAS:
            raise ParameterError(f"antialias must be one of {ANTIALIAS}, got {antialias!r}")
        self.width, self.height = int(width), int(height)
        self.mesh_update = mesh_update
        self.look = look or load_look()
        self._pr = import_pyrender(offscreen=offscreen)
        vertices, triangles, colors = _face_arrays(face)
        self.n_vertices = len(vertices)
        self._triangles = triangles
        self._normal_op = normal_operator(self.n_vertices, triangles)
        self._pieces = _cull_hidden_sides(
            split_parts(vertices, triangles, getattr(face, "parts", None)), vertices,
            triangles, face, self.look)
        self._skin_maps(face, vertices)
        self._buffers(face, colors)
        if framing is None:
            framing = "head"
        if isinstance(framing, str):
            framing = framing_points(face, framing, look=self.look)
        self.scene = self._build_scene(vertices, background, framing)
        self._renderer: Any = None
        self._scale = 1
        self.antialias = "off"
        self._primitives: list[Any] = []
        self.rigid_pieces = rigid_pieces
        self._groups = rigid_groups([p.vertex_ids for p in self._pieces], vertices, triangles)
        self._at_rest = [False] * len(self._groups)
        self._nodes: list[Any] = []
        self.set_vertices(vertices)
        if offscreen:
            self._open(antialias)

    def _skin_maps(self, face: Deformable, vertices: np.ndarray) -> None:
        """Cut each skin piece in two: the triangles that a wrinkle region reaches, which the
        face shader creases, and the rest, spared that work (llvmpipe runs every branch of
        a shader for every pixel). Per piece then: the wrinkle layout (None elsewhere, and
        where the face lacks the feature points it needs), the skin's tint and surface
        (shine, roughness) factors, and no wrinkle activation yet (see :meth:`set_faps`)."""
        normals = vertex_normals(vertices, self._triangles, self._normal_op)
        self._drivers = wrinkle_drivers()
        self._activation = np.zeros(len(self._drivers.names), np.float32)
        pieces: list[PartMesh] = []
        for piece in self._pieces:
            layout = (skin_layout(face, piece.vertex_ids, normals[piece.vertex_ids],
                                  self._drivers) if piece.name == "skin" else None)
            if layout is None:
                pieces.append(piece)
                continue
            reached = layout.weights.max(axis=(0, 2))[piece.triangles].max(axis=1) > 0
            for part in (piece.triangles[reached], piece.triangles[~reached]):
                if len(part):
                    used = np.unique(part)
                    pieces.append(PartMesh(piece.name, piece.vertex_ids[used],
                                           np.searchsorted(used, part).astype(np.uint32),
                                           piece.double_sided))
        self._pieces = pieces
        self._layouts: list[SkinLayout | None] = [None] * len(pieces)
        for k, piece in enumerate(pieces):
            if piece.name == "skin":
                layout = skin_layout(face, piece.vertex_ids, normals[piece.vertex_ids],
                                     self._drivers)
                if layout is not None and layout.weights.any():
                    self._layouts[k] = layout
        tints = [tint_factors(face, p.vertex_ids, normals[p.vertex_ids], self.look.skin_tint)
                 if p.name == "skin" else None for p in pieces]
        self._tints = [None if t is None else t[0] for t in tints]
        self._surface = [None if t is None else t[1] for t in tints]

    def set_faps(self, faps: np.ndarray | None) -> None:
        """Deepen the skin's wrinkles as ``faps`` ``(84,)`` (one frame's FAP values, FAP
        units; None: smooth skin) asks, from the next frame drawn on."""
        if faps is None:
            activation = np.zeros_like(self._activation)
        else:
            activation = wrinkle_activation(faps, self._drivers)
        if np.array_equal(activation, self._activation):
            return
        self._activation = activation
        for k, group in enumerate(self._groups):
            if any(self._layouts[piece] is not None for piece in group.pieces):
                self._at_rest[k] = False  # re-upload: its depths changed
        for piece, layout in enumerate(self._layouts):
            if layout is not None:
                self._write_wrinkles(piece)

    def _write_wrinkles(self, piece: int) -> None:
        """Put the current wrinkle depths of ``piece`` into its vertex buffer."""
        layout = self._layouts[piece]
        if layout is not None:
            depth = layout.amplitudes(self._activation)
            buf = self._interleaved[piece]
            buf[:, 7] = depth[:, 0]
            buf[:, 9] = depth[:, 1]

    def _buffers(self, face: Deformable, colors: np.ndarray) -> None:
        """Per piece: linear colours with the occlusion factor in alpha, materials, hair
        card coordinates and the interleaved vertex buffer they fill."""
        strength, power = _part_occlusion(self.look, self._pieces, len(colors))
        # the occlusion darkens the albedo, and rides in the colour's alpha for the face
        # shader to dim the highlights too (no gloss deep in the mouth); pyrender blends
        # nothing with it (its blend function is ONE, ZERO for opaque materials)
        factor = _occlusion_factor(len(colors), getattr(face, "vertex_ao", None),
                                   strength, power)
        linear = srgb_to_linear(colors) * factor[:, None]
        self._colors = [np.hstack([linear[p.vertex_ids] * (1.0 if tint is None else tint),
                                   factor[p.vertex_ids, None]]).astype(np.float32)
                        for p, tint in zip(self._pieces, self._tints, strict=True)]
        self._materials = [self._material(p) for p in self._pieces]
        self._uv = _piece_uv(self._pieces, getattr(face, "hair_uv", None))
        # pyrender interleaves position, normal, then tangent (skin that wrinkles: phase and
        # depth of channels 0 and 1), texcoord_0 (hair: card coordinates), texcoord_1 (skin:
        # shine and roughness factors) and colour
        self._interleaved = []
        for k, (color, uv, layout) in enumerate(zip(self._colors, self._uv, self._layouts,
                                                   strict=True)):
            surface = self._surface[k]
            width = (10 + (0 if uv is None else 2) + (0 if layout is None else 4)
                     + (0 if surface is None else 2))
            buf = np.zeros((len(color), width), np.float32)
            buf[:, -4:] = color
            if uv is not None:
                buf[:, 6:8] = uv
            if layout is not None:
                buf[:, 6] = layout.phase[:, 0]
                buf[:, 8] = layout.phase[:, 1]
            if surface is not None:
                buf[:, width - 6 : width - 4] = surface
            self._interleaved.append(buf)

    def _context(self, scale: int) -> Any:
        try:
            renderer = self._pr.OffscreenRenderer(scale * self.width, scale * self.height)
        except Exception as exc:
            raise RenderError(
                f"could not create a {scale * self.width}x{scale * self.height} offscreen "
                f"OpenGL context ({type(exc).__name__}: {exc}); {INSTALL_HINT}"
            ) from exc
        install_program_cache(self._pr, renderer._renderer, self.look)
        install_colour_readback(renderer)
        return renderer

    def _open(self, antialias: str) -> None:
        """Create the offscreen context with the anti-aliasing ``antialias`` asks for."""
        self._renderer = self._context(1)
        platform = self._renderer._platform
        platform.make_current()
        # pyrender multisamples (4x) whenever its platform renders into framebuffers
        has_msaa = platform.supports_framebuffers() or _max_samples() >= 4
        mode = ("msaa" if has_msaa else "supersample") if antialias == "auto" else antialias
        if mode == "msaa" and not has_msaa:
            self.close()
            raise RenderError("this OpenGL context has no 4x multisampling "
                              "(GL_MAX_SAMPLES < 4); use antialias='supersample'")
        if mode == "msaa" and not platform.supports_framebuffers():
            # OSMesa: Mesa's contexts have framebuffer objects; pyrender's class says not
            platform.supports_framebuffers = lambda: True
        if mode == "supersample" and self.look.supersample > 1:
            self._renderer.delete()
            self._scale = self.look.supersample
            self._renderer = self._context(self._scale)
        self.antialias = mode

    # -- scene construction -----------------------------------------------------------

    def _material(self, piece: PartMesh) -> Any:
        spec = self.look.material(piece.name)
        sides = piece.double_sided
        return self._pr.MetallicRoughnessMaterial(
            baseColorFactor=(1.0, 1.0, 1.0, 1.0),
            metallicFactor=float(spec.get("metallic", 0.0)),
            roughnessFactor=float(spec.get("roughness", 0.6)),
            doubleSided=bool(spec.get("double_sided", False)) if sides is None else sides,
        )

    def _build_scene(
        self, vertices: np.ndarray, background: Sequence[float] | None, framing: Any
    ) -> Any:
        pr = self._pr
        bg = self.look.background if background is None else tuple(background)
        if len(bg) not in (3, 4) or not all(0.0 <= float(c) <= 1.0 for c in bg):
            raise ParameterError(f"background must be RGB in [0, 1], got {background!r}")
        scene = pr.Scene(bg_color=(*bg[:3], 1.0), ambient_light=self.look.ambient)
        yfov = np.radians(self.look.yfov_deg)
        frame_on = vertices if framing is None else np.asarray(framing, np.float32)
        pose, znear, zfar = frame_camera(
            frame_on, aspect=self.width / self.height, yfov=yfov, margin=self.look.margin,
            scene_vertices=vertices,
        )
        camera = pr.PerspectiveCamera(
            yfov=yfov, aspectRatio=self.width / self.height, znear=znear, zfar=zfar
        )
        scene.add(camera, pose=pose)
        self.camera_pose = pose
        for light in self.look.lights:
            scene.add(
                pr.DirectionalLight(color=light["color"], intensity=float(light["intensity"])),
                pose=_light_pose(light["azimuth_deg"], light["elevation_deg"]),
                name=light["name"],
            )
        return scene

    def _new_meshes(self, vertices: np.ndarray, normals: np.ndarray) -> list[Any]:
        pr = self._pr
        meshes = []
        for k, (piece, color, material, uv) in enumerate(zip(
                self._pieces, self._colors, self._materials, self._uv, strict=True)):
            wrinkled = self._layouts[k] is not None
            buf = self._interleaved[k]
            surface = buf[:, -6:-4] if self._surface[k] is not None else None
            self._write_wrinkles(k)
            primitive = pr.Primitive(
                positions=vertices[piece.vertex_ids],
                normals=normals[piece.vertex_ids],
                tangents=buf[:, 6:10] if wrinkled else None,
                texcoord_0=uv,
                texcoord_1=surface,
                color_0=color,
                indices=piece.triangles,
                material=material,
            )
            meshes.append(pr.Mesh([primitive], name=piece.name))
        return meshes

    # -- per-frame update ----------------------------------------------------------------

    def set_vertices(self, vertices: np.ndarray) -> None:
        """Move the face to ``vertices`` ``(V, 3)`` (recomputing smooth normals).

        With ``mesh_update="buffers"``, a group of pieces that moved rigidly from its rest
        shape (hair, eyeballs, teeth; see :mod:`facelib.rendering.rigid_pieces`) is moved
        by its nodes' pose instead, its buffers keeping the rest shape.
        """
        vertices = np.asarray(vertices, np.float32)
        if vertices.shape != (self.n_vertices, 3):
            raise ParameterError(
                f"vertices must have shape ({self.n_vertices}, 3), got {vertices.shape}"
            )
        if not np.isfinite(vertices).all():
            raise ParameterError("vertices must be finite")
        uploaded = self._primitives and all(p._vaid is not None for p in self._primitives)
        if self.mesh_update == "buffers" and uploaded and self._renderer is not None:
            self._renderer._platform.make_current()
            for k, group in enumerate(self._groups):
                self._move_group(k, group, vertices)
            from OpenGL import GL

            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
            return
        normals = vertex_normals(vertices, self._triangles, self._normal_op)
        for node in self._nodes:
            self.scene.remove_node(node)
        meshes = self._new_meshes(vertices, normals)
        self._primitives = [m.primitives[0] for m in meshes]
        self._nodes = [self.scene.add(m) for m in meshes]
        self._at_rest = [False] * len(self._groups)

    def _move_group(self, k: int, group: RigidGroup, vertices: np.ndarray) -> None:
        """Pose group ``k`` rigidly where it moved so, else upload its vertices."""
        pose = rigid_pose(group, vertices) if self.rigid_pieces else None
        if pose is not None:
            if not self._at_rest[k]:
                rest = group.rest.astype(np.float32)
                normals = vertex_normals(rest, group.triangles, group.operator)
                self._upload(group, rest, normals)
                self._at_rest[k] = True
            for piece in group.pieces:
                self.scene.set_pose(self._nodes[piece], pose)
            return
        mine = vertices[group.vertex_ids]
        self._upload(group, mine, vertex_normals(mine, group.triangles, group.operator))
        if self._at_rest[k]:
            for piece in group.pieces:
                self.scene.set_pose(self._nodes[piece], np.eye(4))
            self._at_rest[k] = False

    def _upload(self, group: RigidGroup, vertices: np.ndarray, normals: np.ndarray) -> None:
        """Rewrite the vertex buffers of ``group``'s pieces: ``vertices`` and ``normals``
        ``(Vg, 3)`` in the rows of ``group.vertex_ids``."""
        from OpenGL import GL

        for piece, rows in zip(group.pieces, group.rows, strict=True):
            prim, buf = self._primitives[piece], self._interleaved[piece]
            self._write_wrinkles(piece)
            buf[:, 0:3] = vertices[rows]
            buf[:, 3:6] = normals[rows]
            # keep the primitive's own arrays (bounds, shadows) true to what is drawn
            prim._positions = buf[:, 0:3]
            prim._normals = buf[:, 3:6]
            prim._bounds = None
            GL.glBindBuffer(GL.GL_ARRAY_BUFFER, prim._buffers[0])
            GL.glBufferSubData(GL.GL_ARRAY_BUFFER, 0, buf.nbytes, buf)

    def frame(self, vertices: np.ndarray | None = None, *,
              faps: np.ndarray | None = None) -> np.ndarray:
        """Render ``vertices`` ``(V, 3)`` (or the current pose) to ``(H, W, 3) uint8`` RGB;
        ``faps`` ``(84,)``: the frame's FAP values, which deepen the skin's wrinkles (see
        :meth:`set_faps`; None keeps the last ones)."""
        if self._renderer is None:
            raise RenderError("this FaceRenderer is closed or was made for a window")
        if faps is not None:
            self.set_faps(faps)
        if vertices is not None:
            self.set_vertices(vertices)
        try:
            color, _ = self._renderer.render(self.scene)
        except Exception as exc:
            raise RenderError(f"OpenGL rendering failed ({type(exc).__name__}: {exc})") from exc
        return np.ascontiguousarray(downsample(color[:, :, :3], self._scale), dtype=np.uint8)

    def set_camera(self, pose: np.ndarray, *, znear: float, zfar: float) -> None:
        """Move the camera to ``pose`` ``(4, 4)`` (camera to face coordinates) with these
        clipping distances (storyboard camera cues; see :mod:`facelib.rendering.camera`)."""
        node = self.scene.main_camera_node
        node.camera.znear, node.camera.zfar = float(znear), float(zfar)
        self.camera_pose = np.asarray(pose, np.float64)
        self.scene.set_pose(node, self.camera_pose)

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates ``(N, 2) float64`` (column, row; origin top-left) of ``(N, 3)``
        points in face coordinates, as this renderer's camera sees them."""
        points = np.asarray(points, np.float64).reshape(-1, 3)
        camera = self.scene.main_camera_node.camera
        proj = camera.get_projection_matrix(self.width, self.height)
        view = np.linalg.inv(self.camera_pose)
        homo = np.hstack([points, np.ones((len(points), 1))]) @ (proj @ view).T
        ndc = homo[:, :2] / homo[:, 3:4]
        return np.stack(
            [(ndc[:, 0] + 1) / 2 * self.width, (1 - ndc[:, 1]) / 2 * self.height], axis=1
        )

    def close(self) -> None:
        """Release the OpenGL context (idempotent)."""
        if self._renderer is not None:
            self._renderer.delete()
            self._renderer = None

    def __enter__(self) -> FaceRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
