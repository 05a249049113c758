"""Regions of the skin laid out around MPEG-4 feature points: expression wrinkles and tints.

The face shader draws wrinkles (forehead lines, glabellar lines, crow's feet, bunny lines on
the nose, the nasolabial furrow) as valleys of a per-vertex *phase*: where the phase is a
whole number the skin is creased (darker, its normal tilted across the line). The layout is
data (``facelib/data/wrinkles/regions.json``), placed by the face's own feature points and
measured in its eye separation, so that it fits any face definition. How deep each region's
valleys get follows the FAPs (``facelib/data/wrinkles/drivers.csv``): a smile deepens the
nasolabial furrow, a brow raise draws the forehead lines, and with every FAP at zero the
skin is smooth.

:func:`skin_layout` computes the per-vertex phase and region weights once per face;
:func:`wrinkle_activation` maps one frame's FAPs to each region's activation;
:meth:`SkinLayout.amplitudes` turns those into the per-vertex depth the shader reads.
:func:`tint_factors` paints the skin's colour variation (redder cheeks, nose and lips) from
the look's ``skin_tint`` regions, with the same ellipses around feature points.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from facelib import data
from facelib.errors import DataError
from facelib.mpeg4.tables import fap

__all__ = ["SkinLayout", "WrinkleDrivers", "skin_layout", "tint_factors", "wrinkle_activation",
           "wrinkle_drivers"]

N_CHANNELS = 2
"""Wrinkle channels of the shader (two regions may overlap when on different channels)."""


@dataclass(frozen=True)
class WrinkleDrivers:
    """The regions of ``regions.json`` and how FAPs drive them.

    ``names``: region names, in order; ``gains``: ``(R, 84) float32`` activation per FAP
    unit of each FAP (1 / full of ``drivers.csv``); ``regions``: the layout of each region.
    """

    names: tuple[str, ...]
    gains: np.ndarray
    regions: Mapping[str, Mapping[str, Any]]


@lru_cache(maxsize=1)
def wrinkle_drivers() -> WrinkleDrivers:
    """The default :class:`WrinkleDrivers` from ``facelib/data/wrinkles``."""
    regions = data.json_data("wrinkles/regions.json")["regions"]
    names = tuple(regions)
    gains = np.zeros((len(names), 84), np.float32)
    for line, row in data.csv_rows("wrinkles/drivers.csv"):
        where = str(data.path("wrinkles/drivers.csv"))
        if row["region"] not in regions:
            raise DataError(f"unknown wrinkle region {row['region']!r}", path=where, line=line)
        try:
            full = float(row["full"])
            column = fap(row["fap"]).index
        except (ValueError, KeyError, LookupError) as exc:
            raise DataError(f"bad driver row ({exc})", path=where, line=line) from exc
        if full == 0:
            raise DataError("full must not be 0", path=where, line=line)
        gains[names.index(row["region"]), column] += 1.0 / full
    gains.setflags(write=False)
    return WrinkleDrivers(names, gains, regions)


def wrinkle_activation(faps: np.ndarray, drivers: WrinkleDrivers | None = None) -> np.ndarray:
    """``(R,) float32`` activation in [0, 1] of each wrinkle region for one frame's FAP
    values ``faps`` ``(84,)`` (FAP units); all zeros for the neutral face."""
    drivers = drivers or wrinkle_drivers()
    values = np.nan_to_num(np.asarray(faps, np.float32).reshape(-1)[:84])
    return np.clip(drivers.gains @ values, 0.0, 1.0).astype(np.float32)


@dataclass(frozen=True)
class SkinLayout:
    """Per-vertex wrinkle layout of one face's skin.

    ``phase``: ``(V, 2) float32`` the valley coordinate of each vertex on each channel
    (valleys at whole numbers); ``weights``: ``(2, V, R) float32`` how much region r's
    activation deepens the valleys of channel c at each vertex (region mask times depth,
    zero off the region's channel). V counts the vertices given to :func:`skin_layout`.
    """

    phase: np.ndarray
    weights: np.ndarray

    def amplitudes(self, activation: np.ndarray) -> np.ndarray:
        """``(V, 2) float32`` valley depth per vertex and channel for region
        ``activation`` ``(R,)``."""
        return np.einsum("cvr,r->vc", self.weights, np.asarray(activation, np.float32))


def _point(spec: Mapping[str, Any], points: Mapping[str, np.ndarray], es: float) -> np.ndarray:
    """``(2,)`` a layout point: the mean of its feature points (x, y) plus its offset (ES)."""
    base = np.mean([points[k][:2] for k in spec["points"]], axis=0)
    return base + np.asarray(spec.get("offset", (0.0, 0.0)), np.float64) * es


def _smooth_inside(r: np.ndarray) -> np.ndarray:
    """1 inside r < 0.55, easing to 0 at r = 1 (smoothstep)."""
    t = np.clip((1.0 - r) / 0.45, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _lines(p: np.ndarray, spec: Mapping[str, Any], pts: Mapping[str, np.ndarray],
           es: float) -> tuple[np.ndarray, np.ndarray]:
    centre = _point(spec["centre"], pts, es)
    angle = np.radians(float(spec["axis_deg"]))
    axis = np.array([np.cos(angle), np.sin(angle)])
    d = p - centre
    half = np.asarray(spec["half_size"], np.float64) * es
    # half_size is (x, y) of the face: measure the ellipse in those axes
    r = np.hypot(d[:, 0] / half[0], d[:, 1] / half[1])
    phase = d @ axis / (float(spec["spacing"]) * es) + float(spec.get("phase", 0.0))
    return phase, _smooth_inside(r)


def _fan(p: np.ndarray, spec: Mapping[str, Any], pts: Mapping[str, np.ndarray],
         es: float) -> tuple[np.ndarray, np.ndarray]:
    centre = _point(spec["centre"], pts, es)
    d = p - centre
    mirror = -1.0 if spec["centre"].get("offset", (0.0,))[0] < 0 else 1.0
    angle = np.degrees(np.arctan2(d[:, 1], mirror * d[:, 0]))
    lo, hi = (float(a) for a in spec["angle_deg"])
    inner, outer = (float(x) * es for x in spec["radius"])
    radius = np.hypot(d[:, 0], d[:, 1])
    mid, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    across = np.abs(angle - mid) / half
    along = np.abs(radius - (inner + outer) / 2.0) / ((outer - inner) / 2.0)
    mask = _smooth_inside(across) * _smooth_inside(along)
    return angle / float(spec["spacing_deg"]), mask


def _fold(p: np.ndarray, spec: Mapping[str, Any], pts: Mapping[str, np.ndarray],
          es: float) -> tuple[np.ndarray, np.ndarray]:
    start, end = _point(spec["from"], pts, es), _point(spec["to"], pts, es)
    seg = end - start
    length = float(np.linalg.norm(seg))
    along_unit = seg / max(length, 1e-12)
    d = p - start
    t = d @ along_unit / max(length, 1e-12)
    across = d @ np.array([-along_unit[1], along_unit[0]])
    width = float(spec["width"]) * es
    # the valley at across = 0; the next whole phase lies four widths out, where the mask
    # has long gone, so each fold is one furrow
    phase = across / (4.0 * width)
    mask = np.exp(-((across / (1.6 * width)) ** 2)) * _smooth_inside(np.abs(2.0 * t - 1.0))
    return phase, mask


_KINDS = {"lines": _lines, "fan": _fan, "fold": _fold}


def _frontal(normals: np.ndarray) -> np.ndarray:
    """How much each vertex faces forward (+z): 0 facing sideways or back, 1 from n_z 0.35."""
    t = np.clip(normals[:, 2] / 0.35, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _frame_points(face: Any) -> tuple[dict[str, np.ndarray], float] | None:
    fps = getattr(face, "feature_points", None) or {}
    es = (getattr(face, "fapu", None) or {}).get("ES")
    if es is None or not fps:
        return None
    vertices = np.asarray(face.vertices, np.float64)
    return {k: vertices[v] for k, v in fps.items()}, float(es) * 1024.0


def skin_layout(face: Any, vertex_ids: np.ndarray, normals: np.ndarray,
                drivers: WrinkleDrivers | None = None) -> SkinLayout | None:
    """The :class:`SkinLayout` of ``face``'s vertices ``vertex_ids`` ``(V,)`` with their rest
    unit ``normals`` ``(V, 3)``; None when the face lacks FAPU or a feature point that the
    layout needs (its skin then stays smooth)."""
    drivers = drivers or wrinkle_drivers()
    framed = _frame_points(face)
    if framed is None:
        return None
    pts, es = framed
    p = np.asarray(face.vertices, np.float64)[vertex_ids][:, :2]
    frontal = _frontal(np.asarray(normals, np.float64))
    phase = np.zeros((len(vertex_ids), N_CHANNELS), np.float32)
    weights = np.zeros((N_CHANNELS, len(vertex_ids), len(drivers.names)), np.float32)
    strongest = np.zeros((len(vertex_ids), N_CHANNELS))
    for r, name in enumerate(drivers.names):
        spec = drivers.regions[name]
        try:
            region_phase, mask = _KINDS[spec["kind"]](p, spec, pts, es)
        except KeyError:
            return None
        mask = mask * frontal
        channel = int(spec["channel"])
        take = mask > strongest[:, channel]
        phase[take, channel] = region_phase[take]
        strongest[take, channel] = mask[take]
        weights[channel, :, r] = mask * float(spec.get("depth", 1.0))
    # a vertex takes the phase of its channel's strongest region; a weaker overlapping
    # region on the same channel would draw with that phase, so it is left out there
    for channel in range(N_CHANNELS):
        owner = np.argmax(weights[channel], axis=1)
        keep = np.zeros_like(weights[channel])
        rows = np.arange(len(vertex_ids))
        keep[rows, owner] = weights[channel][rows, owner]
        weights[channel] = keep
    return SkinLayout(phase, weights)


def tint_factors(face: Any, vertex_ids: np.ndarray, normals: np.ndarray,
                 tints: Mapping[str, Mapping[str, Any]]) -> tuple[np.ndarray, np.ndarray]:
    """``(colour (V, 3), surface (V, 2))`` float32 factors of ``face``'s vertices
    ``vertex_ids`` from the look's ``skin_tint`` regions: an ellipse of ``half_size`` ES
    around ``centre`` (as in ``regions.json``) multiplies the linear colour by ``colour``,
    the specular by ``shine`` and the roughness by ``roughness`` (``surface``'s two columns;
    each default 1) at its middle, easing to 1 at its rim; ones where the face lacks what a
    region needs."""
    out = np.ones((len(vertex_ids), 3), np.float32)
    surface = np.ones((len(vertex_ids), 2), np.float32)
    framed = _frame_points(face)
    if framed is None:
        return out, surface
    pts, es = framed
    p = np.asarray(face.vertices, np.float64)[vertex_ids][:, :2]
    frontal = _frontal(np.asarray(normals, np.float64))
    for spec in tints.values():
        if not all(k in pts for k in spec["centre"]["points"]):
            continue
        d = p - _point(spec["centre"], pts, es)
        half = np.asarray(spec["half_size"], np.float64) * es
        r = np.hypot(d[:, 0] / half[0], d[:, 1] / half[1])
        weight = (np.clip(1.0 - r, 0.0, 1.0) ** 2 * frontal)[:, None]
        colour = np.asarray(spec.get("colour", (1.0, 1.0, 1.0)), np.float64)
        out *= (1.0 + weight * (colour - 1.0)).astype(np.float32)
        factors = np.array([float(spec.get("shine", 1.0)), float(spec.get("roughness", 1.0))])
        surface *= (1.0 + weight * (factors - 1.0)).astype(np.float32)
    return out, surface
