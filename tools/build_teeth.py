"""Give facelib's default head individual teeth and gums, upper and lower.

Usage (from the repository root)::

    PYTHONPATH=. python tools/build_teeth.py            # replaces the teeth, re-bakes the AO
    PYTHONPATH=. python tools/build_teeth.py --check    # builds, reports, writes nothing

``tools/build_default_head.py`` runs it after building the head, so a rebuilt head has these
teeth. The geometry is facelib's own (procedural, under the project's MIT licence), made to
sit where the MakeHuman helper teeth sat: two 68-vertex slabs whose rows of vertices, measured
once and kept below as ``SLAB_ROWS``, give the dental arch (the labial line of the biting
edges, the gum line, the base and the lingual line), the crowns' heights and the bite (the
lower incisors' edges 1.8 mm above and 2 mm behind the upper ones: a normal overbite and
overjet). The script:

1. fits each row with a cubic spline over the slab's stations (mirrored through the midline);
2. places seven teeth a side per jaw (central and lateral incisor, canine, two premolars, two
   molars) along the labial edge line, their mesio-distal widths the usual adult proportions
   (``TEETH``) scaled to fill the slab's arch, each tooth's axis along the slab's labial face;
3. makes each tooth a smooth closed surface of rings of superellipses whose size changes from
   the biting end to the root (incisors thin and chisel-edged, canines pointed, premolars with
   two cusps, molars with four, a neck narrower than the crown), the back teeth meeting across
   a thin gap where the slabs overlapped, so no tooth passes through another;
4. sweeps the gums along the arch: a closed tube whose labial and lingual walls come down to a
   scalloped margin (higher over each crown, a papilla between teeth) and run into the teeth
   there, so the pink ends on the enamel;
5. paints the teeth ivory, each tooth a little different (seeded), greyer at the biting edge
   and warmer at the neck, the gums pink;
6. splices the two parts into ``facelib/data/head/default_head.npz`` and ``default_head.json``
   in place of the old ones: skin and eye vertex ids stay; the tongue's and lashes' ids shift,
   and every vertex id that the head's data holds moves with them (feature points, regions,
   riders, the MediaPipe embedding ``facelib/data/tracking/default_head_mediapipe.json``; a
   landmark that sat on an old tooth moves to the nearest new vertex of that row; after the
   bake the embedding is found afresh by ``tools/build_tracking_embedding.py``, as its test
   asks). Feature points 9.10 and 9.11 (the biting edges of the upper and lower teeth,
   middle) go on the left central incisors' edges;
7. re-bakes the head's ambient occlusion (``tools/bake_head_look.py``).

Deterministic: fixed tables and seed; running it again gives the same head (up to the AO
rasteriser's rounding).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import build_tracking_embedding
import numpy as np
from build_tracking_embedding import EMBEDDING
from scipy.interpolate import CubicSpline

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"
SEED = 31

# The MakeHuman slabs' rows (mm, head frame: +x the face's left, +y up, +z forward), from the
# midline (x = 0) to the back end; each row has the slabs' nine stations. Upper: edge = labial
# line of the biting edges, gum = labial line where the crowns meet the gum, base = top of the
# slab, lingual = the palatal line. Lower: the same, base the bottom of the slab.
SLAB_ROWS = {
    "upper": {
        "edge": [(0, -37.5, 130.7), (8.9, -37.1, 130.4), (17.4, -35.5, 125.1),
                 (22.1, -33.5, 118.1), (25.4, -31.8, 109.9), (28.4, -29.8, 101.2),
                 (29.7, -28.7, 94.3), (31.1, -27.1, 87.8), (30.9, -25.4, 80.6)],
        "gum": [(0, -27.7, 132.9), (8.3, -27.4, 132.6), (16.9, -26.2, 127.4),
                (21.6, -24.8, 119.5), (25.2, -23.3, 111.4), (28.3, -22.2, 102.4),
                (29.2, -21.6, 95.5), (30.6, -20.7, 88.6), (31.0, -20.2, 81.0)],
        "base": [(0, -18.4, 135.0), (7.8, -18.3, 134.7), (16.1, -17.4, 129.3),
                 (21.0, -16.4, 120.9), (24.8, -15.3, 113.0), (28.2, -14.8, 103.8),
                 (29.2, -14.9, 96.7), (30.6, -14.1, 89.7), (31.0, -14.2, 82.0)],
        "lingual": [(0, -27.1, 125.3), (4.8, -26.8, 124.8), (10.1, -25.8, 121.6),
                    (14.4, -24.4, 116.6), (16.6, -23.2, 111.0), (18.4, -21.8, 104.8),
                    (19.2, -21.0, 98.5), (19.4, -19.8, 92.0), (19.5, -18.6, 84.6)],
    },
    "lower": {
        "edge": [(0, -35.7, 128.6), (9.1, -35.4, 128.1), (17.7, -33.8, 123.2),
                 (22.2, -31.9, 115.9), (25.6, -30.1, 107.7), (28.4, -28.5, 98.8),
                 (29.2, -27.0, 92.0), (30.6, -25.6, 85.4), (31.0, -23.7, 78.0)],
        "gum": [(0, -43.8, 126.7), (9.2, -43.1, 126.4), (18.3, -41.2, 121.5),
                (22.9, -39.1, 114.5), (26.0, -36.8, 106.3), (28.6, -34.5, 97.5),
                (29.2, -33.1, 90.7), (30.6, -31.3, 84.3), (31.0, -29.6, 77.0)],
        "base": [(0, -53.1, 124.6), (9.7, -52.2, 124.3), (19.0, -50.0, 119.6),
                 (23.5, -47.5, 113.0), (26.5, -44.8, 104.7), (28.7, -41.8, 96.0),
                 (29.2, -40.1, 89.3), (30.6, -37.9, 83.1), (31.1, -35.6, 76.1)],
        "lingual": [(0, -46.5, 119.0), (4.9, -46.2, 118.8), (10.1, -44.9, 115.8),
                    (14.7, -43.0, 110.3), (16.5, -41.2, 105.1), (18.4, -39.5, 99.1),
                    (19.3, -37.8, 92.7), (19.6, -36.1, 86.5), (19.6, -34.1, 79.3)],
    },
}


@dataclass(frozen=True)
class Kind:
    """One tooth type of one jaw. width, depth: mesio-distal and labio-lingual size (mm,
    typical adult crowns, before scaling to the arch); edge: where its biting end sits
    relative to the slab's edge line (mm toward the root; negative: past it); shape:
    ``incisor``, ``canine``, ``premolar`` or ``molar``."""

    name: str
    width: float
    depth: float
    edge: float
    shape: str


# typical adult crown sizes (mm; Wheeler's dental anatomy tables, rounded), midline outward.
# The slab's edge line rises 1.1 mm from the upper central incisors to the laterals and 3 mm
# to the canines: the edges below bring the laterals' edges 0.8 mm and the canines' tips 1.9 mm
# above the centrals' (a smile shows a row, not the centrals alone), and the lower laterals
# and canines to the lower centrals' level (so they stay behind the longer uppers).
TEETH = {
    "upper": (Kind("central incisor", 8.5, 7.0, 0.0, "incisor"),
              Kind("lateral incisor", 6.5, 6.0, -0.3, "incisor"),
              Kind("canine", 7.5, 8.0, -1.0, "canine"),
              Kind("first premolar", 7.0, 9.0, 0.3, "premolar"),
              Kind("second premolar", 6.5, 9.0, 0.3, "premolar"),
              Kind("first molar", 10.0, 11.0, 0.2, "molar"),
              Kind("second molar", 9.0, 10.5, 0.3, "molar")),
    "lower": (Kind("central incisor", 5.0, 5.7, 0.0, "incisor"),
              Kind("lateral incisor", 5.5, 6.1, 0.5, "incisor"),
              Kind("canine", 7.0, 7.5, 2.0, "canine"),
              Kind("first premolar", 7.0, 7.7, 0.3, "premolar"),
              Kind("second premolar", 7.0, 8.0, 0.3, "premolar"),
              Kind("first molar", 11.0, 10.5, 0.2, "molar"),
              Kind("second molar", 10.5, 10.0, 0.3, "molar")),
}
GAP = 0.15  # mm between neighbouring crowns, so each tooth reads on its own
BACK = 1.0  # mm of arch left free behind the last molar
ROOT_LENGTH = 4.5  # mm of root kept above the gum line (hidden in the gum)
# posterior teeth (premolars, molars): where the slabs overlapped, both rows meet at the mean
# occlusal level, leaving this gap (mm) between the cusps
OCCLUSAL_GAP = 0.6
LON = 12  # vertices round each ring of a tooth
# rings of each shape, from the biting end to the root; the first and last are poles. Each:
# (where: below CROWN, mm from the biting end toward the root; from CROWN on, CROWN + a share
# of the crown height (CROWN + 1: the gum line; the last ring is always ROOT_LENGTH past it),
# mesio-distal scale, labio-lingual scale of the cross-section)
CROWN = 10.0
RINGS = {
    # thin, chisel-shaped edge; flat labial face, the lingual side sloping to the edge
    "incisor": ((0.0, 0.0, 0.0), (0.12, 0.95, 0.22), (0.9, 0.995, 0.42), (10.3, 1.0, 0.78),
                (10.62, 0.95, 0.97), (10.92, 0.78, 0.86), (11.25, 0.6, 0.68), (11.45, 0.0, 0.0)),
    # one pointed cusp: the crown narrows in both directions to a tip
    "canine": ((-0.2, 0.0, 0.0), (0.35, 0.34, 0.44), (1.3, 0.72, 0.72), (10.35, 0.98, 0.94),
               (10.65, 0.96, 1.0), (10.92, 0.76, 0.86), (11.25, 0.58, 0.68), (11.45, 0.0, 0.0)),
    # an occlusal table with cusps (grooves below) and a bulging crown, narrower at the neck
    "premolar": ((0.0, 0.0, 0.0), (0.1, 0.6, 0.62), (0.6, 0.9, 0.9), (10.3, 1.0, 1.0),
                 (10.65, 0.97, 0.97), (10.95, 0.8, 0.84), (11.3, 0.62, 0.66), (11.5, 0.0, 0.0)),
    "molar": ((0.0, 0.0, 0.0), (0.1, 0.64, 0.64), (0.6, 0.92, 0.92), (10.3, 1.0, 1.0),
              (10.65, 0.98, 0.98), (10.95, 0.84, 0.86), (11.3, 0.68, 0.7), (11.5, 0.0, 0.0)),
}
# superellipse exponent of the cross-sections (2 = ellipse; more = squarer)
SQUARENESS = {"incisor": 3.2, "canine": 2.2, "premolar": 2.3, "molar": 2.6}
# how far the cross-sections near the biting end shift toward the labial face (share of the
# depth they lose), so the labial face stays flat and the lingual side slopes to the edge
LABIAL_BIAS = {"incisor": 0.85, "canine": 0.8, "premolar": 0.0, "molar": 0.0}
# occlusal grooves (mm deep at the centre) between the cusps of the back teeth
GROOVE = {"premolar": 1.0, "molar": 1.2}

# gums: how far (share of the crown height) the margin comes down between teeth (papilla),
# and the tube's walls (mm): outside the tooth's labial line, and inside the tooth
PAPILLA = 0.3
GUM_OUT, GUM_IN = 0.8, 1.8
GUM_STATIONS = 4  # stations of the gum tube per tooth

# colours (sRGB 0-1)
ENAMEL = np.array([0.93, 0.89, 0.80])  # ivory, not paper white
EDGE_TINT = np.array([0.95, 0.95, 0.96])  # the thin biting edge: a little greyer
NECK_TINT = np.array([0.98, 0.95, 0.86])  # the neck: warmer, more yellow
TOOTH_VARIATION = 0.025  # relative lightness spread between teeth (seeded)
CANINE_YELLOW = 0.96  # canines are a shade yellower (their blue channel times this)
WARM = np.array([1.0, 0.9, 0.86])  # the back teeth's tint (times the enamel)
BACK_WARMTH = 1.0  # share of WARM on the last molar, from none on the central incisor
GUM = np.array([0.80, 0.45, 0.47])
GUM_DEEP = np.array([0.70, 0.36, 0.39])  # toward the base, out of sight


# ------------------------------------------------------------------------------ the arch
class Row:
    """A slab row as a smooth curve over the station index ``k`` in [-8, 8] (0: midline)."""

    def __init__(self, points: list[tuple[float, float, float]] | np.ndarray,
                 ks: np.ndarray | None = None):
        half = np.asarray(points, np.float64) / 1000.0  # metres
        ks = np.arange(len(half), dtype=np.float64) if ks is None else ks
        full = np.concatenate([half[:0:-1] * [-1, 1, 1], half])
        self.end = float(ks[-1])
        self.spline = CubicSpline(np.concatenate([-ks[:0:-1], ks]), full, axis=0)

    @classmethod
    def between(cls, labial: Row, lingual: Row) -> Row:
        """The line midway between two rows (horizontally, along the labial row's normal),
        at the labial row's height, over the labial row's stations."""
        ks = np.linspace(0.0, labial.end, 33)
        mid = np.array([labial(k) - outward(labial.tangent(k)) * slab_depth(labial, lingual, k) / 2
                        for k in ks])
        return cls(mid * 1000.0, ks)

    def __call__(self, k: np.ndarray | float) -> np.ndarray:
        return np.asarray(self.spline(k))

    def tangent(self, k: float) -> np.ndarray:
        t = np.asarray(self.spline(k, 1))
        t[1] = 0.0
        return t / np.linalg.norm(t)


def outward(t: np.ndarray) -> np.ndarray:
    """The horizontal normal of the arch (pointing out of the mouth) at tangent ``t``."""
    return np.array([-t[2], 0.0, t[0]])


def slab_depth(labial: Row, lingual: Row, k: float) -> float:
    """Horizontal distance (m) from the labial row at ``k`` to the nearest point of the
    lingual row."""
    dense = lingual(np.linspace(-lingual.end, lingual.end, 801))
    return float(np.min(np.linalg.norm((dense - labial(k))[:, [0, 2]], axis=1)))


def arc_lengths(row: Row, ks: np.ndarray) -> np.ndarray:
    """Arc length (m) of ``row`` from the midline to each ``k`` (signed)."""
    dense = np.linspace(0.0, row.end, 2001)
    pts = row(dense)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    return np.sign(ks) * np.interp(np.abs(ks), dense, s)


def k_at(row: Row, s: np.ndarray) -> np.ndarray:
    dense = np.linspace(0.0, row.end, 2001)
    lengths = arc_lengths(row, dense)
    return np.sign(s) * np.interp(np.abs(s), lengths, dense)


@dataclass(frozen=True)
class Placed:
    """A tooth in place: its kind, arch span (station index of its centre, half-width in arch
    length), frame (``m`` along the arch, ``b`` outward, ``a`` toward the root), the point on
    its labial line at its biting end, crown height, depth and width (m)."""

    kind: Kind
    side: float
    k: float
    s: float
    half: float
    m: np.ndarray
    b: np.ndarray
    a: np.ndarray
    edge: np.ndarray
    crown: float
    depth: float
    width: float


def frame(rows: dict[str, Row], k: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(m, b, a): along the arch, outward, toward the root, at station ``k``."""
    m = rows["edge"].tangent(k)
    a = rows["gum"](k) - rows["edge"](k)
    a = a - (a @ m) * m
    a /= np.linalg.norm(a)
    b = outward(m)
    b = b - (b @ a) * a
    return m, b / np.linalg.norm(b), a


def place(jaw: str, rows: dict[str, Row], other: dict[str, Row]) -> list[Placed]:
    """The jaw's 14 teeth along its arch (see the module's step 2)."""
    kinds = TEETH[jaw]
    edge = rows["edge"]
    centre = Row.between(edge, rows["lingual"])  # widths are measured along the tooth centres
    total = float(arc_lengths(centre, np.array([centre.end]))[0]) - BACK / 1000.0
    widths = np.array([k.width for k in kinds]) / 1000.0
    scale = (total - GAP / 1000.0 * len(kinds)) / widths.sum()
    print(f"{jaw} teeth: widths scaled by {scale:.3f} to the slab's arch")
    dense_other = other["edge"](np.linspace(-other["edge"].end, other["edge"].end, 801))
    out = []
    for side in (1.0, -1.0):
        start = GAP / 2000.0
        for kind, w in zip(kinds, widths * scale, strict=True):
            s_mid = start + w / 2
            start += w + GAP / 1000.0
            k = float(k_at(centre, np.array([side * s_mid]))[0])
            m, b, a = frame(rows, k)
            point = edge(k)
            crown = float(np.linalg.norm(rows["gum"](k) - point))
            room = slab_depth(edge, rows["lingual"], k)
            depth = min(kind.depth * scale / 1000.0, 0.95 * room)
            start_at = kind.edge / 1000.0
            if kind.shape in ("premolar", "molar"):
                # meet the other row at the mean level of the two slabs' edges here
                near = dense_other[np.argmin(np.linalg.norm(
                    (dense_other - point)[:, [0, 2]], axis=1))]
                mean_y = (point[1] + near[1]) / 2
                toward = np.sign(a[1])  # +1: the root is up (upper jaw)
                start_at = max(start_at, toward * (mean_y - point[1]) / abs(a[1])
                               + OCCLUSAL_GAP / 2000.0 / abs(a[1]))
            point = point + start_at * a
            out.append(Placed(kind, side, k, side * s_mid, w / 2 + GAP / 2000.0, m, b, a,
                              point, crown - start_at, depth, w))
    return out


# ----------------------------------------------------------------------------- tooth mesh
def superellipse(n: int, p: float) -> np.ndarray:
    """``(n, 2)`` points (x along the arch, y outward) of a unit superellipse."""
    th = 2 * np.pi * (np.arange(n) + 0.5) / n
    c, s = np.cos(th), np.sin(th)
    return np.stack([np.sign(c) * np.abs(c) ** (2 / p), np.sign(s) * np.abs(s) ** (2 / p)], 1)


def tooth(t: Placed) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One tooth: vertices ``(N, 3)`` metres, triangles ``(F, 3)`` (outward), and each vertex's
    height ``(N,)`` from the biting end (0) to the root (1) for painting."""
    shape = t.kind.shape
    rings = RINGS[shape]
    ring = superellipse(LON, SQUARENESS[shape])
    verts, heights = [], []
    for i, (at, sm, sb) in enumerate(rings):
        dist = (at - CROWN) * t.crown if at >= CROWN else at / 1000.0
        if i == len(rings) - 1:
            dist = t.crown + ROOT_LENGTH / 1000.0
        x = ring[:, 0] * sm
        y = ring[:, 1] * sb
        # the sections near the end shift toward the labial face
        shift = LABIAL_BIAS[shape] * (1.0 - sb)
        yc = y + shift
        along = np.full(LON, dist)
        if shape in GROOVE and i <= 2:
            groove = np.exp(-((y / 0.32) ** 2))
            if shape == "molar":
                groove = np.maximum(groove, np.exp(-((x / 0.3) ** 2)))
            along = along + (1.0 if i < 2 else 0.4) * GROOVE[shape] / 1000.0 * groove
        pts = (t.edge - t.b * t.depth / 2 + along[:, None] * t.a
               + (x * t.width / 2)[:, None] * t.m + (yc * t.depth / 2)[:, None] * t.b)
        if sm == 0.0 and sb == 0.0:  # a pole
            pts = pts[:1]  # (on a back tooth, the groove puts it in the central fossa)
        verts.append(pts)
        heights.append(np.full(len(pts), dist / (t.crown + ROOT_LENGTH / 1000.0)))
    v = np.concatenate(verts)
    tris = []
    n_rings = len(rings)
    first = 1
    tris += [[0, first + j, first + (j + 1) % LON] for j in range(LON)]
    for r in range(n_rings - 3):
        a0 = first + r * LON
        for j in range(LON):
            p, q = a0 + j, a0 + (j + 1) % LON
            tris += [[p, p + LON, q + LON], [p, q + LON, q]]
    last = len(v) - 1
    base = first + (n_rings - 3) * LON
    for j in range(LON):
        tris.append([base + j, last, base + (j + 1) % LON])
    tris_a = orient(v, np.array(tris))
    return v, tris_a, np.concatenate(heights)


def orient(v: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Flip all triangles if the closed surface's signed volume is negative."""
    a, b, c = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    volume = np.einsum("ij,ij->i", a - v.mean(0), np.cross(b - v.mean(0), c - v.mean(0))).sum()
    return tris if volume > 0 else tris[:, [0, 2, 1]]


# ------------------------------------------------------------------------------- the gums
def gums(rows: dict[str, Row], teeth: list[Placed]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The gum tube along the arch: vertices, triangles, depth share (0 margin, 1 base)."""
    edge = Row.between(rows["edge"], rows["lingual"])  # the arch of the tooth centres
    centres = np.array([t.s for t in teeth])
    halves = np.array([t.half for t in teeth])
    crowns = np.array([t.crown for t in teeth])
    order = np.argsort(centres)
    stations = []
    for i in order:
        stations += [centres[i] - halves[i] + (j + 0.5) * 2 * halves[i] / GUM_STATIONS
                     for j in range(GUM_STATIONS)]
    s_end = float(arc_lengths(edge, np.array([edge.end]))[0])
    stations = [-s_end + 0.0005, *stations, s_end - 0.0005]
    loops, shares = [], []
    for s in stations:
        k = float(k_at(edge, np.array([s]))[0])
        _, b, a = frame(rows, k)
        i = int(np.argmin(np.abs(centres - s)))
        u = np.clip((s - centres[i]) / halves[i], -1.0, 1.0)
        bump = (1 - np.cos(np.pi * u)) / 2
        e, g, top = (rows[n](k) for n in ("edge", "gum", "base"))
        crown = float(np.linalg.norm(g - e))
        margin = crown - PAPILLA * min(crowns[i], crown) * bump
        up = float((top - e) @ a)
        back = slab_depth(rows["edge"], rows["lingual"], k)  # the slab's depth, labial to lingual
        dense = rows["lingual"](np.linspace(-8.0, 8.0, 801))
        lg = dense[np.argmin(np.linalg.norm((dense - e)[:, [0, 2]], axis=1))]
        lin_margin = float((lg - e) @ a) - PAPILLA * 0.6 * crown * bump
        mm = 1e-3
        loop = [
            e + (margin - 1.2 * mm) * a - GUM_IN * mm * b,
            e + (margin + 0.2 * mm) * a + 0.25 * mm * b,
            e + (margin + 2.0 * mm) * a + GUM_OUT * mm * b,
            e + (up - 1.5 * mm) * a + (GUM_OUT - 0.2) * mm * b,
            e + (up + 0.5 * mm) * a - 0.45 * back * b,
            e + (max(up - 3 * mm, lin_margin + 3 * mm)) * a - (back + GUM_OUT * mm) * b,
            e + (lin_margin + 0.2 * mm) * a - (back + 0.25 * mm) * b,
            e + (lin_margin - 1.2 * mm) * a - (back - GUM_IN * mm) * b,
        ]
        loops.append(np.array(loop))
        shares.append(np.array([0.0, 0.0, 0.25, 0.8, 1.0, 0.8, 0.0, 0.0]))
    n = len(loops[0])
    v = np.concatenate([*loops, loops[0].mean(0, keepdims=True),
                        loops[-1].mean(0, keepdims=True)])
    tris = []
    for r in range(len(loops) - 1):
        for j in range(n):
            p, q = r * n + j, r * n + (j + 1) % n
            tris += [[p, q, q + n], [p, q + n, p + n]]
    cap0, cap1 = len(v) - 2, len(v) - 1
    last = (len(loops) - 1) * n
    for j in range(n):
        tris += [[cap0, (j + 1) % n, j], [cap1, last + j, last + (j + 1) % n]]
    tris_a = np.array(tris)
    # outward: the normal of a wall triangle points away from its loop's centre
    centre = np.concatenate([np.repeat(np.array([lp.mean(0) for lp in loops]), n, 0),
                             v[-2:]])
    a0, b0, c0 = v[tris_a[:, 0]], v[tris_a[:, 1]], v[tris_a[:, 2]]
    normal = np.cross(b0 - a0, c0 - a0)
    away = (a0 + b0 + c0) / 3 - centre[tris_a[:, 0]]
    if (np.einsum("ij,ij->i", normal, away) < 0).mean() > 0.5:
        tris_a = tris_a[:, [0, 2, 1]]
    return v, tris_a, np.concatenate([*shares, np.ones(2)])


# ------------------------------------------------------------------------------- one jaw
def build_jaw(jaw: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                          int]:
    """Vertices ``(N, 3)`` m, triangles ``(F, 3)``, colours ``(N, 3)`` sRGB of one jaw's teeth
    and gums, and the vertex of the left central incisor's biting edge nearest the midline."""
    rows = {name: Row(pts) for name, pts in SLAB_ROWS[jaw].items()}
    other = {name: Row(pts) for name, pts in SLAB_ROWS["lower" if jaw == "upper"
                                                       else "upper"].items()}
    placed = place(jaw, rows, other)
    verts, tris, cols = [], [], []
    start = 0
    edge_point = -1
    for t in placed:
        v, f, h = tooth(t)
        shade = 1.0 + TOOTH_VARIATION * rng.standard_normal()
        tint = ENAMEL * shade
        # toward the back, the light a tooth gets is what the gums, tongue and cheeks send
        # back: warmer
        back = BACK_WARMTH * TEETH[jaw].index(t.kind) / (len(TEETH[jaw]) - 1)
        tint = tint * (1 + back * (WARM - 1))
        if t.kind.shape == "canine":
            tint = tint * [1.0, 0.995, CANINE_YELLOW]
        near_edge = np.clip(1 - h / 0.12, 0, 1)[:, None]
        near_neck = np.clip((h - 0.45) / 0.3, 0, 1)[:, None]
        c = tint * (1 + near_edge * (EDGE_TINT - 1)) * (1 + near_neck * (NECK_TINT - 1))
        if t.kind.name == "central incisor" and t.side > 0:
            # the biting end's vertices (ring 1), the one nearest the midline
            ring1 = np.arange(1, 1 + LON)
            edge_point = start + int(ring1[np.argmin(np.abs(v[ring1, 0]) + 0.3 * np.abs(
                (v[ring1] - t.edge) @ t.a))])
        verts.append(v)
        tris.append(f + start)
        cols.append(np.clip(c, 0, 1))
        start += len(v)
    gv, gf, share = gums(rows, placed)
    verts.append(gv)
    tris.append(gf + start)
    cols.append(GUM + share[:, None] * (GUM_DEEP - GUM))
    return np.concatenate(verts), np.concatenate(tris), np.concatenate(cols), edge_point


# ---------------------------------------------------------------------------- the splice
def winding(points: np.ndarray, v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Generalised winding number ``(P,)`` of a closed triangle mesh at ``points``."""
    out = np.zeros(len(points))
    for chunk in range(0, len(points), 256):
        p = points[chunk:chunk + 256, None, :]
        a, b, c = v[f[:, 0]] - p, v[f[:, 1]] - p, v[f[:, 2]] - p
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        num = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("pfi,pfi->pf", a, b) * lc
               + np.einsum("pfi,pfi->pf", b, c) * la + np.einsum("pfi,pfi->pf", c, a) * lb)
        out[chunk:chunk + 256] = 2 * np.arctan2(num, den).sum(1) / (4 * np.pi)
    return out


def splice(arrays: dict[str, np.ndarray], doc: dict, new: dict[str, tuple]) -> tuple[
        dict[str, np.ndarray], dict, np.ndarray]:
    """Replace the parts ``teeth_upper`` and ``teeth_lower`` (consecutive ranges) by ``new``
    (part -> vertices, triangles, colours); returns the arrays, the definition and the old ->
    new id map (``-1`` for the old teeth's vertices)."""
    parts = doc["parts"]
    (a0, a1), (b0, b1) = parts["teeth_upper"], parts["teeth_lower"]
    if a1 != b0:
        raise SystemExit("teeth_upper and teeth_lower must be consecutive ranges")
    n_old = len(arrays["vertices"])
    n_new = len(new["teeth_upper"][0]) + len(new["teeth_lower"][0])
    delta = n_new - (b1 - a0)
    remap = np.arange(n_old)
    remap[a0:b1] = -1
    remap[b1:] += delta
    v, t = arrays["vertices"], arrays["triangles"]
    old_teeth = ((t >= a0) & (t < b1)).any(1)
    if not old_teeth[((t >= a0) & (t < b1)).all(1)].all() or (
            old_teeth & ~((t >= a0) & (t < b1)).all(1)).any():
        raise SystemExit("a triangle joins the teeth to another part")
    first = int(np.argmax(old_teeth))
    kept = remap[t[~old_teeth]]
    at = int((~old_teeth[:first]).sum())
    upper_v, upper_t, upper_c = new["teeth_upper"]
    lower_v, lower_t, lower_c = new["teeth_lower"]
    new_t = np.concatenate([upper_t + a0, lower_t + a0 + len(upper_v)])
    out = dict(arrays)
    out["vertices"] = np.concatenate([v[:a0], upper_v, lower_v, v[b1:]]).astype(np.float32)
    out["triangles"] = np.concatenate([kept[:at], new_t, kept[at:]]).astype(np.int32)
    colours = np.round(np.concatenate([upper_c, lower_c]) * 255).astype(np.uint8)
    out["vertex_colors"] = np.concatenate(
        [arrays["vertex_colors"][:a0], colours, arrays["vertex_colors"][b1:]])
    if "vertex_ao" in arrays:  # re-baked afterwards
        out["vertex_ao"] = np.concatenate(
            [arrays["vertex_ao"][:a0], np.full(n_new, 255, np.uint8), arrays["vertex_ao"][b1:]])
    doc = json.loads(json.dumps(doc))

    def ids(values, what):
        arr = remap[np.asarray(values, np.int64)]
        if (arr < 0).any():
            raise SystemExit(f"{what} refers to an old tooth vertex")
        return arr.tolist()

    for name, (p, q) in list(doc["parts"].items()):
        if name in ("teeth_upper", "teeth_lower"):
            continue
        doc["parts"][name] = [int(remap[p]), int(remap[q - 1]) + 1]
    doc["parts"]["teeth_upper"] = [a0, a0 + len(upper_v)]
    doc["parts"]["teeth_lower"] = [a0 + len(upper_v), a0 + n_new]
    doc["parts"] = {k: doc["parts"][k] for k in sorted(doc["parts"],
                                                       key=lambda k: doc["parts"][k][0])}
    for key in ("9.8", "9.9", "9.10", "9.11"):
        doc["feature_points"].pop(key, None)
    doc["feature_points"] = {k: ids([i], f"feature point {k}")[0]
                             for k, i in doc["feature_points"].items()}
    for region in doc["regions"]:
        for key in ("vertices", "anchors"):
            if key in region:
                region[key] = ids(region[key], f"region {region['name']} {key}")
    for name, rider in doc.get("riders", {}).items():
        rider["anchors"] = [ids(pair, f"riders of {name}") for pair in rider["anchors"]]
    return out, doc, remap


def sort_points(points: dict[str, int]) -> dict[str, int]:
    return {k: points[k] for k in sorted(points, key=lambda s: tuple(map(int, s.split("."))))}


def remap_embedding(remap: np.ndarray, old_v: np.ndarray, new_v: np.ndarray,
                    doc: dict, old_parts: dict) -> None:
    """Move the MediaPipe embedding's vertex ids with the splice (old teeth -> nearest new
    vertex of the same row)."""
    emb = json.loads(EMBEDDING.read_text())
    out = []
    for i in emb["vertices"]:
        j = int(remap[i])
        if j < 0:
            part = "teeth_upper" if old_parts["teeth_upper"][0] <= i < old_parts[
                "teeth_upper"][1] else "teeth_lower"
            p, q = doc["parts"][part]
            j = p + int(np.argmin(np.linalg.norm(new_v[p:q] - old_v[i], axis=1)))
        out.append(j)
    emb["vertices"] = out
    EMBEDDING.write_text(json.dumps(emb) + "\n")


def build() -> dict[str, tuple]:
    rng = np.random.default_rng(SEED)
    new = {}
    for jaw in ("upper", "lower"):
        v, f, c, edge = build_jaw(jaw, rng)
        new[f"teeth_{jaw}"] = (v, f, c, edge)
        print(f"teeth_{jaw}: {len(v)} vertices, {len(f)} triangles")
    return new


def check(new: dict[str, tuple]) -> int:
    """Vertices of one tooth inside another (in a jaw and across the bite); prints and returns
    the count."""
    size = LON * (len(RINGS["incisor"]) - 2) + 2  # vertices of one tooth (the gums follow)
    pieces = []
    for name in ("teeth_upper", "teeth_lower"):
        v, f = new[name][0], new[name][1]
        for start in range(0, 14 * size, size):
            inside = (f >= start).all(1) & (f < start + size).all(1)
            pieces.append((name, start, v[start:start + size], f[inside] - start))
    bad = 0
    for i, (n1, s1, v1, _) in enumerate(pieces):
        for j, (n2, s2, v2, f2) in enumerate(pieces):
            if i == j or np.linalg.norm(v1.mean(0) - v2.mean(0)) > 0.02:
                continue
            inside = np.abs(winding(v1, v2, f2)) > 0.5
            if inside.any():
                print(f"  {n1} tooth at {s1}: {int(inside.sum())} vertices inside {n2} tooth "
                      f"at {s2}")
                bad += int(inside.sum())
    print(f"{bad} tooth vertices inside other teeth")
    return bad


def main(*, write: bool = True, tracking: bool = True, bake: bool = True) -> None:
    sys.path.insert(0, str(ROOT))
    new = build()
    check(new)
    if not write:
        return
    doc = json.loads((HEAD / "default_head.json").read_text())
    with np.load(HEAD / "default_head.npz") as z:
        arrays = {k: z[k] for k in z.files}
    old_parts = dict(doc["parts"])
    out, doc, remap = splice(arrays, doc, {k: v[:3] for k, v in new.items()})
    for key, part in (("9.10", "teeth_upper"), ("9.11", "teeth_lower")):
        doc["feature_points"][key] = doc["parts"][part][0] + new[part][3]
    doc["feature_points"] = sort_points(doc["feature_points"])
    np.savez_compressed(HEAD / "default_head.npz", **out)
    (HEAD / "default_head.json").write_text(json.dumps(doc, indent=1) + "\n")
    if tracking:
        remap_embedding(remap, arrays["vertices"], out["vertices"], doc, old_parts)
    print(f"{len(out['vertices'])} vertices, {len(out['triangles'])} triangles in the head")
    if bake:
        import bake_head_look

        bake_head_look.main()
    if tracking and bake:
        # the MediaPipe embedding found afresh on the new head (needs the ``render`` and
        # ``track`` extras): the open mouth that it is found on looks different now, so
        # MediaPipe's fit moves, and the remapped ids alone no longer match a fresh run
        build_tracking_embedding.main()


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="build and report, write nothing")
    parser.add_argument("--no-bake", action="store_true", help="leave the AO un-baked")
    args = parser.parse_args()
    main(write=not args.check, bake=not args.no_bake)
