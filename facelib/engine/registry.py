"""The deformer registry: which algorithm carries feature-point motion to a region's vertices.

A deformer takes a region (:class:`RegionSetup`: members, controls, anchors, the rest mesh
and the parameters the face definition gives) and returns its weights, which compile into
the face's one sparse operator:

- ``(Vr, N)``: member ``v`` moves by ``sum_i M[v, i] dC_i`` (the same for x, y and z);
- ``(Vr, 3, N, 3)``: member ``v`` moves along axis ``a`` by ``sum_{i,b} T[v, a, i, b] dC_i[b]``
  (frame-based deformers mix the axes).

``dC (N, 3)`` are the displacements of the region's feature points (eq. 4.6). A deformer
that is not linear in ``dC`` also gives a per-frame ``step`` (:class:`FrameStep`): the exact
map, applied after the operator as a correction of its linearisation.

The registry is an immutable table built from :data:`BUILTIN`; a face definition names a
deformer per region, and ``load_face(..., deformers={...})`` overrides it. A
:class:`Deformer` object (not only a name) may be given there, so applications add their own
without changing global state.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib.engine import deformers as _today
from facelib.engine import rbf as rbf_solver
from facelib.errors import FaceModelError

__all__ = ["BUILTIN", "Deformer", "FrameStep", "RegionSetup", "deformer", "deformer_names",
           "registry"]


@dataclass(frozen=True, eq=False)
class RegionSetup:
    """What a deformer sees of one region (all positions at rest, mesh units).

    name: the region's name (for messages).
    members: (Vr,) int64 ids of the vertices that move.
    controls: (N,) int64 vertex ids of its feature points, in the definition's order.
    anchors: (A,) int64 ids of static border vertices (may be empty).
    vertices: (V, 3) float64 rest positions of the whole mesh.
    triangles: (F, 3) int64 triangles of the skin (the surface the region lies on).
    weights: (Vr,) float64 explicit weights (``weights`` deformer; empty otherwise).
    params: the region's deformer parameters, defaults filled in.
    """

    name: str
    members: np.ndarray
    controls: np.ndarray
    anchors: np.ndarray
    vertices: np.ndarray
    triangles: np.ndarray
    weights: np.ndarray
    params: Mapping[str, Any]

    def fail(self, message: str) -> FaceModelError:
        return FaceModelError(f"region {self.name!r}: {message}")


@dataclass(frozen=True, eq=False)
class FrameStep:
    """The exact, non-linear map of a frame-based deformer.

    displace: ``dC (n, N, 3) -> (n, Vr, 3)`` member displacements for control displacements
        (anchors, when the deformer uses them, stay still).
    """

    displace: Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True, eq=False)
class Deformer:
    """A registered deformer.

    name: the name face definitions use.
    weights: ``RegionSetup -> (Vr, N) or (Vr, 3, N, 3) float64`` (see the module docstring).
    defaults: every parameter it accepts with its default value.
    summary: one line for listings and error messages.
    source: where the algorithm comes from (seed and equation numbers).
    step: for non-linear deformers, ``RegionSetup -> FrameStep``; None for linear ones.
    interpolating: whether a control's own vertex follows it exactly (``M[fp, fp] = 1``).
    """

    name: str
    weights: Callable[[RegionSetup], np.ndarray]
    defaults: Mapping[str, Any] = field(default_factory=dict)
    summary: str = ""
    source: str = ""
    step: Callable[[RegionSetup], FrameStep] | None = None
    interpolating: bool = True

    def resolve(self, params: Mapping[str, Any], *, region: str) -> dict[str, Any]:
        """Defaults overlaid with ``params``; an unknown key raises ``FaceModelError``."""
        unknown = sorted(set(params) - set(self.defaults))
        if unknown:
            known = ", ".join(self.defaults) or "none"
            raise FaceModelError(f"region {region!r}: deformer {self.name!r} has no parameter "
                                 f"{unknown[0]!r} (parameters: {known})")
        return {**self.defaults, **params}


def _raised_cosine(setup: RegionSetup) -> np.ndarray:
    pos = setup.vertices
    members = pos[setup.members]
    controls = pos[setup.controls]
    radius = setup.params["radius"]
    if radius == "edge":
        edge = pos[_edge(setup.members, setup.triangles, len(pos))]
        return _today.raised_cosine_weights(members, controls, edge=edge)
    if radius == "farthest":
        return _today.raised_cosine_weights(members, controls)
    raise setup.fail(f"raised_cosine radius must be 'edge' or 'farthest', got {radius!r}")


def _edge(members: np.ndarray, triangles: np.ndarray, n_vertices: int) -> np.ndarray:
    """Ids of the members that share a triangle with a vertex outside ``members``."""
    inside = np.zeros(n_vertices, bool)
    inside[members] = True
    mixed = triangles[inside[triangles].any(1) & ~inside[triangles].all(1)]
    return np.unique(mixed[inside[mixed]])


def _rbf(setup: RegionSetup) -> np.ndarray:
    p = setup.params
    pos = setup.vertices
    sources = pos[np.concatenate([setup.controls, setup.anchors])]
    kernel = str(p["kernel"])
    degree = p["polynomial"]
    if degree is None:
        degree = -1 if kernel == "multiquadric_eck" else 1
    try:
        w = rbf_solver.interpolation_weights(sources, pos[setup.members], kernel=kernel,
                                       degree=int(degree), smoothing=float(p["smoothing"]),
                                       epsilon=p["epsilon"])
    except FaceModelError as exc:
        raise setup.fail(exc.message) from exc
    # anchors stay still: only the control columns carry motion
    return w[:, : setup.controls.size]


def _explicit(setup: RegionSetup) -> np.ndarray:
    return _today.explicit_weights(setup.weights)


def _builtin() -> tuple[Deformer, ...]:
    # imported here: the frame-based and interpolation modules import this one
    from facelib.engine import frame_deformers, interpolation

    return (
        Deformer(
            "raised_cosine", _raised_cosine, {"radius": "edge"},
            "raised-cosine falloff around each feature point, averaged over them",
            "first seed eq. 4.7; radius 'farthest' is the thesis's d_max, 'edge' the nearest "
            "region-edge vertex"),
        Deformer(
            "rbf", _rbf,
            {"kernel": "multiquadric_eck", "polynomial": None, "smoothing": 0.0,
             "epsilon": None},
            "radial basis functions through controls and static anchors",
            "second seed eq. 2.17-2.21; first seed eq. 4.8-4.10 (kernel multiquadric_eck)"),
        Deformer("weights", _explicit, {}, "explicit per-vertex weights of one feature point",
                 "face definition"),
        *interpolation.DEFORMERS,
        *frame_deformers.DEFORMERS,
    )


BUILTIN: tuple[Deformer, ...] = ()
"""Filled below: the deformers facelib ships."""

ALIASES = MappingProxyType({"cosine": "raised_cosine"})
"""Older names still accepted in face definitions."""


def registry() -> Mapping[str, Deformer]:
    """Name -> :class:`Deformer` of every built-in deformer."""
    return _REGISTRY


def deformer_names() -> tuple[str, ...]:
    """Names of the built-in deformers, in registry order."""
    return tuple(_REGISTRY)


def deformer(name: str | Deformer) -> Deformer:
    """The deformer called ``name`` (or ``name`` itself when it is a :class:`Deformer`)."""
    if isinstance(name, Deformer):
        return name
    key = ALIASES.get(name, name) if isinstance(name, str) else name
    if not isinstance(key, str) or key not in _REGISTRY:
        raise FaceModelError(f"unknown deformer {name!r}; known: {', '.join(_REGISTRY)}")
    return _REGISTRY[key]


def _freeze(items: tuple[Deformer, ...]) -> Mapping[str, Deformer]:
    names = [d.name for d in items]
    if len(set(names)) != len(names):  # pragma: no cover - a packaging mistake
        raise FaceModelError(f"deformer names repeat: {names}")
    return MappingProxyType({d.name: d for d in items})


BUILTIN = _builtin()
_REGISTRY = _freeze(BUILTIN)
