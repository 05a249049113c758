"""``Face``: a head mesh with its face definition, compiled for deformation by FAPs.

Deformation of one frame ``f`` (84 FAP values):

1. every translational FAP moves its feature point by ``f_j * FAPU_j * direction_j``
   (eq. 4.6) and the regions controlled by that point carry the motion to their vertices
   (each region's deformer from :mod:`facelib.engine.deformers`: raised cosine, RBF,
   explicit weights, the second seed's interpolations); all of this is one sparse linear
   operator ``A (84, 3V)``, so ``positions = rest + f @ A``, plus the exact per-frame step of
   any frame-based region in ``mode="exact"``;
2. eyelids (FAP 19-22) rotate over the eyeball about the eye centre, by the angle that
   moves their feature point vertically by ``f_j * IRISD``, each vertex by its weight;
3. eyeballs rotate about their centres (FAP 23-26) and move forward (FAP 27-28);
4. lower teeth and tongue follow the jaw: a hinge rotation that moves the lower-lip point
   2.3 vertically as the skin operator moves it per unit of FAP 3 (so the lower teeth stay
   behind the lower lip, whatever deformer opens the jaw; with a plain jaw region that is the
   chin's drop of ``f_3 * MNS``) plus the thrust (FAP 14) and shift (FAP 15) translations;
5. the head rotates about its pivot (FAP 48-50), fading to nothing over the neck.

FAPs 1-2 (high-level visemes and expressions) are decoded into low-level FAPs by ``deform``
(:mod:`facelib.mpeg4.highlevel`); 29-30 (pupil
dilation) and 47 (tongue roll) do not move this mesh.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import MappingProxyType
from typing import Any

import numpy as np
import scipy.sparse as sp

from facelib.checks import check_count
from facelib.engine import fused, rigid
from facelib.engine.deformers import Deformer, FrameStep, RegionSetup, deformer
from facelib.engine.fapu import compute_fapu
from facelib.engine.riders import Riders, no_riders
from facelib.errors import FaceModelError, ParameterError
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import N_FAPS, fap, fap_table

__all__ = ["ATTACHED_PARTS", "OPTIONAL_PARTS", "PART_NAMES", "Face", "Part", "Region", "Riders"]

PART_NAMES = ("skin", "eye_l", "eye_r", "teeth_upper", "teeth_lower", "tongue")
OPTIONAL_PARTS = ("lashes",)
"""Parts a face may have besides ``PART_NAMES``; their vertices ride on the skin
(:class:`~facelib.engine.riders.Riders`)."""
ATTACHED_PARTS = ("bust", "garment", "hair")
"""Parts a face definition may attach to its head (:mod:`facelib.engine.attachments`): the
bust's skin and garment fade out of the head's rotation with the neck like the skin; the
hair turns rigidly with the head (``HEAD_RIGID_PARTS``), wherever it hangs."""
HEAD_RIGID_PARTS = ("hair",)
RIGID_DEFORMERS = ("eyelid",)
"""Deformers that are per-frame rigid steps of the face, not entries of the registry."""
# The rigid steps address FAPs by their names in the standard's table (facelib.mpeg4).
# Eyelid feature point -> the FAP that closes that lid (step 2).
_EYELID_FAPS = {"3.1": "close_t_l_eyelid", "3.2": "close_t_r_eyelid",
                "3.3": "close_b_l_eyelid", "3.4": "close_b_r_eyelid"}
# Eyeball part -> its yaw, pitch and thrust FAPs (step 3).
_EYES = (("eye_l", "yaw_l_eyeball", "pitch_l_eyeball", "thrust_l_eyeball"),
         ("eye_r", "yaw_r_eyeball", "pitch_r_eyeball", "thrust_r_eyeball"))
_EYE_THRUSTS = frozenset(thrust for *_, thrust in _EYES)
_JAW = ("open_jaw", "thrust_jaw", "shift_jaw")  # step 4; open_jaw moves point 2.1
_HEAD = ("head_pitch", "head_yaw", "head_roll")  # step 5
_BLOCK = 32  # frames deformed together
# Streams of at least this many vertex-frames (about 1,000 frames of the default head)
# deform through the compiled kernel where numba is installed: below it, loading numba and
# the cached kernel in a fresh process (about 0.3 s) costs more than the kernel saves.
_KERNEL_FROM = 40_000_000


def _column(name: str) -> int:
    """The 0-based column of the FAP called ``name`` in a frame of 84 values."""
    return fap(name).index


def _columns_of(names: tuple[str, str, str]) -> tuple[int, int, int]:
    a, b, c = (_column(name) for name in names)
    return a, b, c


def _readonly(array: np.ndarray, dtype: type) -> np.ndarray:
    out: np.ndarray = np.array(array, dtype=dtype, copy=True)
    out.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class Part:
    """A named piece of the mesh.

    name: one of ``PART_NAMES``.
    vertex_ids: (Vp,) int32 global vertex indices.
    triangles: (Fp, 3) int32 with global vertex indices.
    """

    name: str
    vertex_ids: np.ndarray
    triangles: np.ndarray


@dataclass(frozen=True, eq=False)
class Region:
    """An influence region of the face definition.

    name: unique name.
    deformer: a name of :mod:`facelib.engine.deformers` (``raised_cosine``, ``rbf``,
        ``weights``, ...) or ``"eyelid"`` (rotation over the eye).
    feature_points: ids of the controlling feature points.
    vertices: (Vr,) int32 member vertices (the ones that move).
    anchors: (A,) int32 static border vertices (RBF only; empty otherwise).
    weights: (Vr,) float32 (``weights`` and ``eyelid`` only; empty otherwise).
    pivot: pivot name (``eyelid`` only).
    params: the deformer's parameters as the definition (or an override) gives them.
    group: an optional group name (``"lips"``) that overrides may use instead of the name.
    custom: a :class:`~facelib.engine.deformers.Deformer` given directly instead of a name.
    displacements: (Vr, 3) float32 learned target displacements of the members (``field``
        regions, which name their FAP in ``params["fap"]``; empty otherwise).
    """

    name: str
    deformer: str
    feature_points: tuple[str, ...]
    vertices: np.ndarray
    anchors: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int32))
    weights: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))
    pivot: str = ""
    params: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    group: str = ""
    custom: Deformer | None = None
    displacements: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))

    @property
    def field_fap(self) -> str:
        """The FAP a ``field`` region drives alone ("" for other regions)."""
        return str(self.params.get("fap", "")) if self.deformer == "field" else ""

    @property
    def algorithm(self) -> Deformer:
        """The registered (or custom) deformer of this region; not for ``eyelid``."""
        return self.custom if self.custom is not None else deformer(self.deformer)


def _columns(ids: np.ndarray, axes: str = "xyz") -> np.ndarray:
    """Columns of the given vertices' coordinates in flattened ``(V, 3)`` positions.

    ``ids`` (K,) -> (K * len(axes),) int64, vertex-major. Gathers and scatters through
    these columns of ``(n, 3V)`` blocks are many times faster than indexing the vertex axis
    of ``(n, V, 3)`` arrays.
    """
    offsets = np.array(["xyz".index(a) for a in axes], np.int64)
    return (np.asarray(ids, np.int64)[:, None] * 3 + offsets).ravel()


@dataclass(frozen=True, eq=False)
class _Lids:
    """The eyelid regions merged into one rotation: rotations about one axis add, so a
    vertex turns by the weighted sum of its regions' hinge angles.

    hinges: per region (FAP index, vertical motion of its feature point per FAP unit, pivot
        (3,), feature point rest position (3,)).
    y, z: (K,) int64 columns (see :func:`_columns`) of the eyelid vertices.
    pivot_y, pivot_z: (K,) float32, each vertex's eye centre.
    weights: (R, K) float64, each region's weight of each vertex.
    """

    hinges: tuple[tuple[int, float, np.ndarray, np.ndarray], ...]
    y: np.ndarray
    z: np.ndarray
    pivot_y: np.ndarray
    pivot_z: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True, eq=False)
class _Rigid:
    """What steps 2-5 need, precomputed; vertex sets as columns (see :func:`_columns`)."""

    lids: _Lids
    # per eye: columns (3K,), rest shape about the centre (K, 3) float32, the centre
    # repeated (3K,) float32, 0-based FAP columns of yaw, pitch and thrust
    eyes: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, int, int, int], ...]
    jaw_x: np.ndarray
    jaw_y: np.ndarray
    jaw_z: np.ndarray
    jaw_pivot: np.ndarray
    chin: np.ndarray  # the point the hinge follows (2.3, the lower lip)
    chin_drop: float  # its downward motion per unit of FAP 3 in the skin operator
    head_pivot: np.ndarray
    head_tiled: np.ndarray  # (3V,) float32, the pivot repeated per vertex
    head_weights: np.ndarray  # (K,) float32 in (0, 1) for the neck vertices
    neck: np.ndarray  # (3K,) columns of the vertices the head turns in part (the neck)
    still: np.ndarray  # (3S,) columns of the vertices it leaves (the bust)


@dataclass(frozen=True, eq=False)
class Face:
    """A deformable head.

    Attributes
    ----------
    vertices: (V, 3) float32 neutral positions in the face's length unit (metres for the
        default head); +x the face's left, +y up, the face looks along +z.
    triangles: (F, 3) int32, counter-clockwise seen from outside.
    vertex_colors: (V, 3) float32 RGB in [0, 1].
    parts: part name -> :class:`Part` (``skin``, ``eye_l``, ``eye_r``, ``teeth_upper``,
        ``teeth_lower``, ``tongue`` and, where the face has them, ``lashes``).
    feature_points: feature point id (``"2.1"``) -> vertex index.
    fapu: ``IRISD``, ``ES``, ``ENS``, ``MNS``, ``MW`` in mesh units per FAP unit, ``AU`` in
        radians (eq. 4.1-4.5).
    regions: the influence regions.
    pivots: ``eye_l``, ``eye_r``, ``head``, ``jaw`` -> (3,) float64 positions.
    neck: ``(point (3,), unit normal (3,) into the head, blend distance)`` of the plane
        where head rotations fade out.
    operator: scipy CSR array (84, 3V) float32: vertex displacements (flattened ``(V, 3)``)
        per FAP unit, for every translational FAP that deforms linearly.
    vertex_ao: (V,) float32 baked ambient occlusion in [0, 1] (1 = open sky), which the
        renderer multiplies into the colours; None where the mesh file has none.
    riders: vertices that move with skin vertices under them (the lashes; see
        :mod:`facelib.engine.riders`); empty for a face without them.
    hair_uv: (V, 2) float32 hair card coordinates (across the card, root 0 to tip 1) of the
        ``hair`` part's vertices (zero elsewhere), which the renderer's strand highlight
        follows; None for a face without hair.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    vertex_colors: np.ndarray
    parts: Mapping[str, Part]
    feature_points: Mapping[str, int]
    fapu: Mapping[str, float]
    regions: tuple[Region, ...]
    pivots: Mapping[str, np.ndarray]
    neck: tuple[np.ndarray, np.ndarray, float]
    operator: sp.csr_array = field(repr=False)
    _spans: tuple[tuple[int, int, int, int], ...] = field(repr=False)
    _dense: np.ndarray = field(repr=False)
    _rigid: _Rigid = field(repr=False)
    _steps: tuple[_Step, ...] = field(repr=False, default=())
    vertex_ao: np.ndarray | None = field(repr=False, default=None)
    riders: Riders = field(repr=False, default_factory=no_riders)
    hair_uv: np.ndarray | None = field(repr=False, default=None)

    @classmethod
    def build(
        cls,
        *,
        vertices: np.ndarray,
        triangles: np.ndarray,
        vertex_colors: np.ndarray,
        parts: Mapping[str, np.ndarray],
        feature_points: Mapping[str, int],
        regions: tuple[Region, ...],
        pivots: Mapping[str, np.ndarray],
        neck: tuple[np.ndarray, np.ndarray, float],
        vertex_ao: np.ndarray | None = None,
        riders: Riders | None = None,
        hair_uv: np.ndarray | None = None,
    ) -> Face:
        """Compile a face from validated pieces (see :func:`facelib.engine.load_face`).

        ``parts`` maps part names to (Vp,) vertex ids; ``neck`` is a point, a unit normal
        (pointing into the head) and a blend distance of the plane where the neck ends;
        ``riders`` are vertices that follow blends of skin vertices (the lashes).
        """
        verts = _readonly(vertices, np.float32)
        tris = _readonly(triangles, np.int32)
        points = MappingProxyType(dict(feature_points))
        fapu = MappingProxyType(compute_fapu(verts, points))
        part_map = _parts(parts, tris, len(verts))
        pivot_map = {k: _readonly(v, np.float64) for k, v in pivots.items()}
        riders = no_riders() if riders is None else riders
        riders.check(len(verts), np.concatenate(
            [r.vertices for r in regions] + [np.zeros(0, np.int32)]))
        operator, steps = _compile(verts, tris, points, fapu, regions)
        operator = riders.operator(operator)
        _check_rigid_eyes(regions, part_map)
        spans = _spans(np.unique(operator.indices))
        dense = operator[:, np.concatenate([np.arange(a, b) for a, b, _, _ in spans]
                                           + [np.zeros(0, np.int64)])]
        dense = dense.toarray().astype(np.float32)
        rigid_parts = _rigid(verts, points, fapu, regions=_lids_with_riders(regions, riders),
                             parts=part_map, pivots=pivot_map, neck=neck, operator=operator)
        return cls(
            vertices=verts,
            triangles=tris,
            vertex_colors=_readonly(vertex_colors, np.float32),
            parts=MappingProxyType(part_map),
            feature_points=points,
            fapu=fapu,
            regions=tuple(regions),
            pivots=MappingProxyType(pivot_map),
            neck=(_readonly(neck[0], np.float64), _readonly(neck[1], np.float64),
                  float(neck[2])),
            operator=operator,
            _spans=spans,
            _dense=dense,
            _rigid=rigid_parts,
            _steps=steps,
            vertex_ao=None if vertex_ao is None else _readonly(vertex_ao, np.float32),
            riders=riders,
            hair_uv=None if hair_uv is None else _readonly(hair_uv, np.float32),
        )

    def __repr__(self) -> str:
        """One line: sizes and names, never the arrays."""
        return (f"Face(vertices={len(self.vertices)}, triangles={len(self.triangles)}, "
                f"parts=[{', '.join(self.parts)}], feature_points={len(self.feature_points)}, "
                f"regions={len(self.regions)})")

    @property
    def n_vertices(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def fap_deformers(self) -> Mapping[str, str]:
        """FAP name -> the deformer that moves its feature point's surroundings: ``"field"``
        where a learned field drives the FAP alone, else the deformers of the regions its
        feature point controls (joined by ``+``); FAPs that move no region are left out."""
        out: dict[str, str] = {}
        fields = {r.field_fap for r in self.regions if r.field_fap}
        for f in fap_table():
            if f.name in fields:
                out[f.name] = "field"
                continue
            if f.kind != "translation" or not f.feature_points:
                continue
            kinds = sorted({r.deformer for r in self.regions if r.deformer != "field"
                            and f.feature_points[0] in r.feature_points})
            if kinds:
                out[f.name] = "+".join(kinds)
        return MappingProxyType(out)

    def deform(self, stream: FapStream) -> np.ndarray:
        """Vertex positions for every frame of a stream: ``(n_frames, V, 3) float32``.

        High-level FAPs 1 and 2 (viseme and expression selects and blends) are decoded
        first (:func:`facelib.mpeg4.highlevel.apply_high_level`), as an MPEG-4 player does.
        Long streams (``_KERNEL_FROM`` vertex-frames, about 40 s at 25 fps on the default
        head) run through a compiled kernel where numba is installed (the ``fast`` extra;
        :mod:`facelib.engine.fused`), which equals the numpy path to float32 rounding.
        """
        if not isinstance(stream, FapStream):
            raise ParameterError(f"deform() takes a FapStream, not {type(stream).__name__}")
        stream = apply_high_level(stream)  # FAP 1/2 from other tools' files
        values = np.asarray(stream.values, dtype=np.float32)
        return self._deform(values, kernel=self._kernel_for(len(values)))

    def deform_chunks(
        self, stream: FapStream, *, frames: int = 256
    ) -> Iterator[tuple[int, np.ndarray]]:
        """:meth:`deform` in pieces: yields ``(first_frame, (n, V, 3) float32)`` for
        consecutive blocks of at most ``frames`` frames, so a long stream never needs all its
        vertices at once (memory: ``frames x V x 3`` floats). The whole stream takes one path
        (see :meth:`deform`). Through the compiled kernel the blocks, stacked, are
        ``deform(stream)`` bit for bit (it computes each frame on its own); through the numpy
        path they equal it to within a few float32 rounding steps (units in the last place)
        of the largest coordinate: the BLAS product may sum in another order for another
        block size (measured up to 7.5e-9 m on some machines, 1 ulp), bit for bit where it
        does not. Each block is the same for the same input and ``frames``."""
        if not isinstance(stream, FapStream):
            raise ParameterError(f"deform_chunks() takes a FapStream, not {type(stream).__name__}")
        frames = check_count("frames", frames, low=1)
        stream = apply_high_level(stream)  # FAP 1/2, as deform() does
        values = np.asarray(stream.values, dtype=np.float32)
        active = self._active(values)
        kernel = self._kernel_for(len(values))  # one path for the whole stream
        for first in range(0, values.shape[0], frames):
            yield first, self._deform(values[first:first + frames], active, kernel=kernel)

    def deform_frame(self, values: np.ndarray) -> np.ndarray:
        """Vertex positions for one frame of 84 FAP values: ``(84,) -> (V, 3) float32``."""
        try:
            values = np.asarray(values, dtype=np.float32)
        except (TypeError, ValueError):
            raise ParameterError(f"deform_frame() needs 84 FAP values, got {values!r:.60}"
                                 ) from None
        if values.shape != (N_FAPS,):
            raise ParameterError(f"deform_frame() needs 84 FAP values, got shape {values.shape}")
        if not np.all(np.isfinite(values)):
            raise ParameterError("deform_frame() got a non-finite FAP value")
        return self._deform(values[None, :], kernel=False)[0]

    @cached_property
    def _plan(self) -> fused.Plan:
        """The compiled kernel's constant inputs (:mod:`facelib.engine.fused`)."""
        return fused.make_plan(self.vertices, self.operator, self._rigid, self.fapu,
                               jaw=_columns_of(_JAW), head=_columns_of(_HEAD))

    def _active(self, f: np.ndarray) -> np.ndarray:
        """Indices of the FAPs that move a vertex and are non-zero somewhere in ``f``."""
        return np.flatnonzero(np.any(self._dense != 0, axis=1) & np.any(f != 0, axis=0))

    def _kernel_for(self, n_frames: int) -> bool:
        """Whether a stream of ``n_frames`` deforms through the compiled kernel: numba
        installed (and not turned off), no region with an exact per-frame step, and at least
        ``_KERNEL_FROM`` vertex-frames. The choice depends on the stream alone, so the same
        stream takes the same path in every process."""
        return (not self._steps and n_frames * self.n_vertices >= _KERNEL_FROM
                and fused.available())

    def _deform(self, f: np.ndarray, active: np.ndarray | None = None, *,
                kernel: bool) -> np.ndarray:
        """``f`` (n, 84) float32 -> (n, V, 3) float32: the compiled kernel
        (:mod:`facelib.engine.fused`) or :meth:`_deform_numpy`."""
        if kernel:
            return fused.deform(self._plan, f)
        return self._deform_numpy(f, active)

    def _deform_numpy(self, f: np.ndarray, active: np.ndarray | None = None) -> np.ndarray:
        """The numpy path (and the kernel's reference): blocks of frames, step by step."""
        n, nv = f.shape[0], self.n_vertices
        out = np.empty((n, nv, 3), np.float32)
        if active is None:
            active = self._active(f)
        # frames go through in small blocks so that every pass stays in the CPU cache
        # (BLAS writes into fresh pages many times slower than into these warm ones)
        buf, spare = np.empty((2, _BLOCK, nv, 3), np.float32)
        for a in range(0, n, _BLOCK):
            fb = f[a : a + _BLOCK]
            pos = buf[: len(fb)]
            flat = pos.reshape(len(fb), nv * 3)
            flat[:] = self.vertices.reshape(-1)
            if active.size:
                moved = fb[:, active] @ self._dense[active]
                for first, stop, i, j in self._spans:
                    flat[:, first:stop] += moved[:, i:j]
            f64 = fb.astype(np.float64)
            for step in self._steps:
                step.apply(flat, f64)
            self._move_lids(pos, f64)
            self._move_eyes(pos, f64)
            self._move_jaw(pos, f64)
            out[a : a + _BLOCK] = self._move_head(pos, f64, spare[: len(fb)])
        return out

    def _move_lids(self, pos: np.ndarray, f: np.ndarray) -> None:
        lids = self._rigid.lids
        angles = np.zeros((len(f), len(lids.hinges)))
        for k, (fap_index, dy_per_unit, pivot, rest) in enumerate(lids.hinges):
            if f[:, fap_index].any():
                angles[:, k] = rigid.hinge_angle(rest, pivot, f[:, fap_index] * dy_per_unit)
        if not angles.any():
            return
        flat = pos.reshape(len(f), -1)
        flat[:, lids.y], flat[:, lids.z] = rigid.rotate_about_x(
            flat[:, lids.y], flat[:, lids.z], lids.pivot_y, lids.pivot_z, angles @ lids.weights)

    def _move_eyes(self, pos: np.ndarray, f: np.ndarray) -> None:
        au = self.fapu["AU"]
        flat = pos.reshape(len(f), -1)
        for columns, local, tiled, yaw, pitch, thrust in self._rigid.eyes:
            y, p, t = f[:, yaw] * au, f[:, pitch] * au, f[:, thrust]
            if not (y.any() or p.any() or t.any()):
                continue
            rot = rigid.rotation_matrices(p, y, np.zeros_like(p)).astype(np.float32)
            # eyeballs are rigid (no region moves them), so start from the rest shape
            moved = np.matmul(local[None], rot.transpose(0, 2, 1))
            moved[..., 2] += (t * self.fapu["ES"]).astype(np.float32)[:, None]
            flat[:, columns] = moved.reshape(len(f), -1) + tiled

    def _move_jaw(self, pos: np.ndarray, f: np.ndarray) -> None:
        r = self._rigid
        open_, thrust, shift = (f[:, _column(name)] for name in _JAW)
        if not (open_.any() or thrust.any() or shift.any()):
            return
        flat = pos.reshape(len(f), -1)
        angle = rigid.hinge_angle(r.chin, r.jaw_pivot, -open_ * r.chin_drop)
        y, z = rigid.rotate_about_x(flat[:, r.jaw_y], flat[:, r.jaw_z], r.jaw_pivot[1],
                                    r.jaw_pivot[2], angle[:, None])
        flat[:, r.jaw_y] = y
        flat[:, r.jaw_z] = z + (thrust * self.fapu["MNS"]).astype(np.float32)[:, None]
        flat[:, r.jaw_x] -= (shift * self.fapu["MW"]).astype(np.float32)[:, None]

    def _move_head(self, pos: np.ndarray, f: np.ndarray, out: np.ndarray) -> np.ndarray:
        """The block ``pos`` rotated about the head pivot: ``out`` (same shape) filled, or
        ``pos`` itself where the head stays still."""
        r = self._rigid
        au = self.fapu["AU"]
        pitch, yaw, roll = (f[:, _column(name)] * au for name in _HEAD)
        if not (pitch.any() or yaw.any() or roll.any()):
            return pos
        nb = len(f)
        rot = rigid.rotation_matrices(pitch, yaw, roll)
        turned = np.ascontiguousarray(rot.transpose(0, 2, 1), dtype=np.float32)
        flat, out_flat = pos.reshape(nb, -1), out.reshape(nb, -1)
        neck = flat[:, r.neck].reshape(nb, -1, 3)
        still = flat[:, r.still]
        flat -= r.head_tiled
        for k in range(nb):  # one BLAS product per frame beats a stacked matmul here
            np.dot(pos[k], turned[k], out=out[k])
        out_flat += r.head_tiled
        out_flat[:, r.neck] = rigid.rotate_weighted(
            neck, r.head_pivot, rot, r.head_weights).reshape(nb, -1)
        out_flat[:, r.still] = still
        return out


def _spans(columns: np.ndarray, *, gap: int = 96) -> tuple[tuple[int, int, int, int], ...]:
    """The operator's non-zero columns as a few contiguous spans of the ``(3V,)`` axis.

    ``columns`` (C,) sorted unique ints. Runs closer than ``gap`` columns are joined (the
    columns between them carry zeros), so the product lands through slices rather than a
    fancy-indexed scatter. Returns ``(first, stop, i, j)`` per span: columns
    ``first:stop`` of a frame take columns ``i:j`` of the compacted product.
    """
    if columns.size == 0:
        return ()
    breaks = np.flatnonzero(np.diff(columns) > gap)
    firsts = columns[np.r_[0, breaks + 1]]
    stops = columns[np.r_[breaks, columns.size - 1]] + 1
    ends = np.cumsum(stops - firsts)
    return tuple((int(a), int(b), int(e - (b - a)), int(e))
                 for a, b, e in zip(firsts, stops, ends, strict=True))


def _check_rigid_eyes(regions: tuple[Region, ...], parts: Mapping[str, Part]) -> None:
    """Refuse a region that reaches into an eyeball (eyeballs move rigidly, FAP 23-28)."""
    for region in regions:
        for eye in ("eye_l", "eye_r"):
            if np.isin(region.vertices, parts[eye].vertex_ids).any():
                raise FaceModelError(
                    f"region {region.name!r} contains vertices of {eye}; eyeballs are "
                    "rigid and move only with FAP 23-28"
                )


def _lids_with_riders(regions: tuple[Region, ...], riders: Riders) -> tuple[Region, ...]:
    """``regions`` with each eyelid region extended by the riders on its vertices."""
    out = []
    for region in regions:
        if region.deformer in RIGID_DEFORMERS:
            vertices, weights = riders.weighted_region(region.vertices, region.weights)
            out.append(replace(region, vertices=vertices, weights=weights))
        else:
            out.append(region)
    return tuple(out)


def _fp_motion(fapu: Mapping[str, float]) -> dict[str, list[tuple[int, np.ndarray]]]:
    """Per feature point: (FAP column, displacement per FAP unit (3,)) of every translational
    FAP that moves it through the operator (eq. 4.6)."""
    out: dict[str, list[tuple[int, np.ndarray]]] = {}
    for f in fap_table():
        if f.kind != "translation" or f.fapu not in fapu or f.name in _EYELID_FAPS.values():
            continue
        if f.name in _EYE_THRUSTS:  # eyeball thrust moves the whole eye (rigid step)
            continue
        scale = fapu[f.fapu] * np.asarray(f.direction, dtype=np.float64)
        out.setdefault(f.feature_points[0], []).append((f.index, scale))
    return out


@dataclass(frozen=True, eq=False)
class _Step:
    """A non-linear region, corrected per frame: members += exact(dC) - linear(dC).

    columns: (3Vr,) int64 columns of the members; motion: (84, 3N) float64 control
    displacement per FAP unit; linear: (3N, 3Vr) float64 the region's operator block.
    """

    columns: np.ndarray
    motion: np.ndarray
    linear: np.ndarray
    step: FrameStep

    def apply(self, flat: np.ndarray, f: np.ndarray) -> None:
        dc = f @ self.motion
        if not dc.any():
            return
        n = len(f)
        exact = self.step.displace(dc.reshape(n, -1, 3)).reshape(n, -1)
        flat[:, self.columns] += (exact - dc @ self.linear).astype(np.float32)


def _jaw_drop(operator: sp.csr_array, point: int, mns: float) -> float:
    """How far the skin operator lowers vertex ``point`` per unit of FAP 3 (``MNS`` when
    nothing in the operator moves it, so the teeth still open with the FAP)."""
    dy = -float(operator[:, [point * 3 + 1]].toarray()[2, 0])
    return dy if dy > 0 else mns


def _region_weights(
    region: Region, pos: np.ndarray, triangles: np.ndarray, points: Mapping[str, int]
) -> tuple[np.ndarray, FrameStep | None]:
    """``(Vr, 3, N, 3)`` weights of one region and its exact step (None when linear)."""
    algo = region.algorithm
    setup = RegionSetup(
        name=region.name, members=region.vertices.astype(np.int64),
        controls=np.array([points[p] for p in region.feature_points], np.int64),
        anchors=region.anchors.astype(np.int64), vertices=pos, triangles=triangles,
        weights=region.weights.astype(np.float64),
        params=MappingProxyType(algo.resolve(region.params, region=region.name)),
        displacements=region.displacements.astype(np.float64))
    w = np.asarray(algo.weights(setup), dtype=np.float64)
    vr, n = setup.members.size, setup.controls.size
    if w.shape == (vr, n):
        w = w[:, None, :, None] * np.eye(3)[None, :, None, :]
    elif w.shape != (vr, 3, n, 3):
        raise FaceModelError(f"region {region.name!r}: deformer {algo.name!r} returned "
                             f"weights of shape {w.shape}, not ({vr}, {n}) or ({vr}, 3, {n}, 3)")
    exact = setup.params.get("mode") == "exact" and algo.step is not None
    return w, (algo.step(setup) if exact and algo.step is not None else None)


def _compile(
    verts: np.ndarray, triangles: np.ndarray, points: Mapping[str, int],
    fapu: Mapping[str, float], regions: tuple[Region, ...],
) -> tuple[sp.csr_array, tuple[_Step, ...]]:
    """The (84, 3V) operator: displacement of each vertex coordinate per unit of each FAP,
    and the per-frame steps of non-linear regions."""
    nv = len(verts)
    pos = verts.astype(np.float64)
    tris = triangles.astype(np.int64)
    motion = _fp_motion(fapu)
    # a FAP that a learned field drives moves that field's region and no other
    owned = {fap(r.field_fap).index for r in regions if r.field_fap}
    rows, cols, vals = [], [], []
    steps = []
    for region in regions:
        if region.deformer in RIGID_DEFORMERS:
            continue
        w, step = _region_weights(region, pos, tris, points)
        members = region.vertices.astype(np.int64)
        mine = {fap(region.field_fap).index} if region.field_fap else None
        # g: (84, N, 3) control displacement per FAP unit
        g = np.zeros((N_FAPS, len(region.feature_points), 3))
        for k, fp_id in enumerate(region.feature_points):
            for index, scale in motion.get(fp_id, ()):
                if (index in mine) if mine is not None else (index not in owned):
                    g[index, k] += scale
        block = np.einsum("vaib,fib->fva", w, g)  # (84, Vr, 3)
        fi, vi, ai = np.nonzero(block)
        rows.append(fi)
        cols.append(members[vi] * 3 + ai)
        vals.append(block[fi, vi, ai])
        if step is not None:
            steps.append(_Step(_columns(members), g.reshape(N_FAPS, -1),
                               w.reshape(members.size * 3, -1).T.copy(), step))
    if not rows:
        return sp.csr_array((N_FAPS, nv * 3), dtype=np.float32), ()
    coo = sp.coo_array(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(N_FAPS, nv * 3),
    )
    out = coo.tocsr().astype(np.float32)
    out.sum_duplicates()
    return out, tuple(steps)


def _lids(
    verts: np.ndarray, points: Mapping[str, int], fapu: Mapping[str, float],
    regions: tuple[Region, ...], pivots: Mapping[str, np.ndarray],
) -> _Lids:
    lid_regions = [r for r in regions if r.deformer == "eyelid"]
    ids = np.unique(np.concatenate([r.vertices for r in lid_regions] + [np.zeros(0, np.int32)]))
    weights = np.zeros((len(lid_regions), ids.size))
    pivot_of = np.full(ids.size, "", dtype=object)
    hinges = []
    for k, region in enumerate(lid_regions):
        fp_id = region.feature_points[0]
        if fp_id not in _EYELID_FAPS:
            raise FaceModelError(
                f"eyelid region {region.name!r} is controlled by {fp_id!r}; "
                f"eyelid regions take one of {', '.join(_EYELID_FAPS)}"
            )
        at = np.searchsorted(ids, region.vertices)
        clash = (pivot_of[at] != "") & (pivot_of[at] != region.pivot)
        if clash.any():
            raise FaceModelError(
                f"eyelid region {region.name!r} shares vertex {int(ids[at[clash][0]])} with "
                f"an eyelid region about another pivot than {region.pivot!r}"
            )
        pivot_of[at] = region.pivot
        weights[k, at] = region.weights
        f = fap(_EYELID_FAPS[fp_id])
        # the FAP prescribes the vertical motion of the lid point; sliding over the eye,
        # the rotation decides its depth
        hinges.append((f.index, fapu[f.fapu] * f.direction[1], pivots[region.pivot],
                       verts[points[fp_id]].astype(np.float64)))
    centres = np.array([pivots[name] for name in pivot_of], np.float32).reshape(-1, 3)
    return _Lids(tuple(hinges), _columns(ids, "y"), _columns(ids, "z"), centres[:, 1],
                 centres[:, 2], weights)


def _parts(parts: Mapping[str, np.ndarray], tris: np.ndarray, n_vertices: int
           ) -> dict[str, Part]:
    """Each part's vertex ids ``(Vp,) int32`` and the triangles ``(Fp, 3)`` all inside it; an
    attached part (appended after the head) also takes the triangles that join it to the
    head, those whose last vertex is its own."""
    out = {}
    for name, part_ids in parts.items():
        ids = _readonly(part_ids, np.int32)
        inside = np.zeros(n_vertices, bool)
        inside[ids] = True
        mine = inside[tris.max(1)] if name in ATTACHED_PARTS else inside[tris].all(1)
        out[name] = Part(name, ids, _readonly(tris[mine], np.int32))
    return out


def _rigid(verts: np.ndarray, points: Mapping[str, int], fapu: Mapping[str, float], *,
           regions: tuple[Region, ...], parts: Mapping[str, Part],
           pivots: Mapping[str, np.ndarray], neck: tuple[np.ndarray, np.ndarray, float],
           operator: sp.csr_array) -> _Rigid:
    """The rigid steps' precomputed columns, offsets and weights (eyes, lids, jaw, head)."""
    head = pivots["head"]
    point, normal, blend = neck
    height = (verts.astype(np.float64) - point) @ normal
    t = np.clip(height / blend, 0.0, 1.0)
    head_w = t * t * (3 - 2 * t)
    for name in HEAD_RIGID_PARTS:
        if name in parts:
            head_w[parts[name].vertex_ids] = 1.0
    jaw_ids = np.concatenate(
        [parts["teeth_lower"].vertex_ids, parts["tongue"].vertex_ids])
    return _Rigid(
        lids=_lids(verts, points, fapu, regions, pivots),
        eyes=tuple(
            (_columns(parts[name].vertex_ids),
             (verts[parts[name].vertex_ids] - pivots[name]).astype(np.float32),
             np.tile(pivots[name].astype(np.float32), parts[name].vertex_ids.size),
             _column(yaw), _column(pitch), _column(thrust))
            for name, yaw, pitch, thrust in _EYES
        ),
        jaw_x=_columns(jaw_ids, "x"),
        jaw_y=_columns(jaw_ids, "y"),
        jaw_z=_columns(jaw_ids, "z"),
        jaw_pivot=pivots["jaw"],
        chin=verts[points["2.3"]].astype(np.float64),
        chin_drop=_jaw_drop(operator, points["2.3"], fapu["MNS"]),
        head_pivot=head,
        head_tiled=np.tile(head.astype(np.float32), len(verts)),
        head_weights=head_w[(head_w > 0.0) & (head_w < 1.0)].astype(np.float32),
        neck=_columns(np.flatnonzero((head_w > 0.0) & (head_w < 1.0))),
        still=_columns(np.flatnonzero(head_w <= 0.0)),
    )
