"""The deformer types: what a deformer sees of a region, its weights and its exact step.

A deformer is a :class:`Deformer`: a name, a ``weights`` function of a :class:`RegionSetup`
and, for a non-linear one, a ``step`` giving its :class:`FrameStep` (see
:mod:`facelib.engine.deformers.registry` for the shapes of the weights).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from facelib.errors import FaceModelError

__all__ = ["Deformer", "FrameStep", "RegionSetup"]


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
    displacements: (Vr, 3) float64 learned target displacements (``field``; else empty).
    """

    name: str
    members: np.ndarray
    controls: np.ndarray
    anchors: np.ndarray
    vertices: np.ndarray
    triangles: np.ndarray
    weights: np.ndarray
    params: Mapping[str, Any]
    displacements: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

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
