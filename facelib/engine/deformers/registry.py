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

from collections.abc import Mapping
from types import MappingProxyType

from facelib.engine.deformers import fields, frames, interpolation, linear, rbf
from facelib.engine.deformers.base import Deformer
from facelib.errors import FaceModelError

__all__ = ["ALIASES", "BUILTIN", "deformer", "deformer_names", "registry"]


BUILTIN: tuple[Deformer, ...] = (
    linear.RAISED_COSINE, rbf.RBF, linear.WEIGHTS,
    *interpolation.DEFORMERS, *frames.DEFORMERS, *fields.DEFORMERS,
)
"""The deformers facelib ships, in registry order."""

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


_REGISTRY = _freeze(BUILTIN)
