"""Groom hair for facelib's default head: a scalp cap and layers of hair cards per style.

Usage (from the repository root, after ``tools/build_bust.py``)::

    PYTHONPATH=. python tools/build_hair.py            # writes facelib/data/head/default_hair.npz
    PYTHONPATH=. python tools/build_hair.py --check    # builds, reports, writes nothing

The rules are ``facelib/data/head/hair_styles.json`` (hairline, styles). For each style:

1. **Cap**: the skin triangles above the hairline (ears excluded), copied ``cap_mm`` outside
   the skin along its normals, coloured as the roots and fading into the skin's colour (and
   onto the skin) over ``soft_mm`` above the hairline: no skin shows through the cards.
2. **Cards**: per layer, roots spread over the cap (area-weighted, seeded), each grown as a
   polyline along the style's flow (hugging the head at the layer's offset from the nearest
   skin or bust vertex, pulled down by gravity once it leaves the head, never inside), then
   swept into a ribbon that lies along the surface and narrows to the tip.
3. A ``tie`` style ends its strands at the tie point and adds a ponytail (cards around a
   spline spine) and a band.

Every vertex carries ``uv``: ``u`` = card index + position across the card (0-1), ``v`` = 0 at
the root to 1 at the tip; the renderer's shader draws strands across ``u`` and runs the
anisotropic highlight along ``v``. Colours run from the roots' to the tips' with a seeded
variation per card; the occlusion darkens inner layers and roots. The file holds, per style
``S``: ``S_vertices``, ``S_triangles`` (the style's own indices), ``S_colors`` (uint8),
``S_ao`` (uint8), ``S_uv``; and ``styles``. Deterministic: seeded per style.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"
OUT = HEAD / "default_hair.npz"
DOWN = np.array([0.0, -1.0, 0.0])
# z (m): a parted style's hair is not parted behind the first, fully parted in front of the second
PART_BACK = (-0.035, 0.015)


def vertex_normals(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    n = np.zeros_like(v)
    face = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    for k in range(3):
        np.add.at(n, t[:, k], face)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


class Body:
    """The surfaces hair must stay outside: head skin and bust, as points with normals."""

    def __init__(self, points: np.ndarray, normals: np.ndarray, centre_z: float):
        self.points, self.normals, self.centre_z = points, normals, centre_z
        self.tree = cKDTree(points)

    def nearest(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nearest points ``(N, 3)``, their normals and the signed distances ``(N,)``."""
        _, i = self.tree.query(p)
        q, n = self.points[i], self.normals[i]
        return q, n, np.einsum("ij,ij->i", p - q, n)

    def keep_out(self, p: np.ndarray, offset: float) -> np.ndarray:
        for _ in range(3):
            _, n, d = self.nearest(p)
            p = p + np.clip(offset - d, 0, None)[:, None] * n
        return p


def load_head(doc: dict | None = None, head: dict | None = None, bust: dict | None = None
              ) -> dict:
    """What grooming needs of a head: the default head and bust, or the face definition
    ``doc``, head arrays ``head`` (``vertices``, ``triangles``, ``vertex_colors``) and bust
    arrays ``bust`` (``vertices``, ``triangles``) given (tools/build_characters.py)."""
    if doc is None or head is None or bust is None:
        doc = json.loads((HEAD / "default_head.json").read_text())
        with np.load(HEAD / "default_head.npz") as data:
            head = {k: data[k] for k in data.files}
        with np.load(HEAD / "default_bust.npz") as data:
            bust = {k: data[k] for k in data.files}
    v, t, c = head["vertices"].astype(float), head["triangles"], head["vertex_colors"]
    lo, hi = doc["parts"]["skin"]
    skin_t = t[(t >= lo).all(1) & (t < hi).all(1)]
    normals = vertex_normals(v, skin_t)
    bv = bust["vertices"].astype(float)
    bt = bust["triangles"]
    allv = np.concatenate([v, bv])
    bn = vertex_normals(allv, bt)[len(v):]
    fp = doc["feature_points"]
    ears = np.array([v[fp[k]] for k in ("10.1", "10.2", "10.5", "10.6", "10.3", "10.4")])
    centre_z = float((v[lo:hi, 2].min() + v[lo:hi, 2].max()) / 2)
    body = Body(np.concatenate([v[lo:hi], bv]), np.concatenate([normals[lo:hi], bn]), centre_z)
    return {"v": v, "skin_t": skin_t, "normals": normals, "colours": c / 255.0,
            "ears": ears, "body": body, "centre_z": centre_z}


def hairline_height(p: np.ndarray, spec: dict, centre_z: float) -> np.ndarray:
    """Hairline height ``(N,)`` at the azimuth of each point ``(N, 3)``."""
    az = np.degrees(np.abs(np.arctan2(p[:, 0], p[:, 2] - centre_z)))
    pts = np.array(spec["points"], float)
    return np.interp(az, pts[:, 0], pts[:, 1])


def subdivide(v: np.ndarray, n: np.ndarray, tris: np.ndarray, parts: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each triangle cut into ``parts**2`` (points on its plane, normals interpolated):
    vertices ``(T*P, 3)``, unit normals and triangles."""
    ij = [(i, j) for i in range(parts + 1) for j in range(parts + 1 - i)]
    index = {key: k for k, key in enumerate(ij)}
    w = np.array([(parts - i - j, i, j) for i, j in ij], float) / parts  # (P, 3)
    pos = np.einsum("pk,tkd->tpd", w, v[tris]).reshape(-1, 3)
    nrm = np.einsum("pk,tkd->tpd", w, n[tris]).reshape(-1, 3)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    local = []
    for i, j in ij:
        if (i + 1, j) in index and (i, j + 1) in index:
            local.append((index[i, j], index[i + 1, j], index[i, j + 1]))
        if (i + 1, j + 1) in index:
            local.append((index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]))
    local_t = np.array(local)
    out = (np.arange(len(tris))[:, None, None] * len(ij) + local_t[None]).reshape(-1, 3)
    return pos, nrm, out


def above_hairline(p: np.ndarray, head: dict, spec: dict) -> np.ndarray:
    """Height ``(N,)`` of points above the hairline (negative below; near the ears: -1)."""
    above = p[:, 1] - hairline_height(p, spec, head["centre_z"])
    near_ear = np.min(np.linalg.norm(p[:, None] - head["ears"][None], axis=2), 1)
    above[near_ear < spec["ear_radius_mm"] / 1000] = -1.0
    return above


def largest_patch(pos: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """The triangles ``(F, 3)`` (into ``pos`` ``(V, 3)``, whose vertices repeat where
    triangles meet) of the largest edge-connected patch: the scalp. The skin also lines the
    mouth, and the back of that lining lies above the nape's hairline seen from the head's
    axis: hair grown there came out through the neck as a stray lock across the throat."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, same = np.unique(np.round(pos * 1e7).astype(np.int64), axis=0, return_inverse=True)
    corner = same.ravel()[tris]
    edges = np.concatenate([corner[:, [0, 1]], corner[:, [1, 2]]])
    n = int(corner.max()) + 1 if len(corner) else 0
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    label = connected_components(graph, directed=False)[1][corner[:, 0]]
    return tris[label == np.bincount(label).argmax()]


def cap(head: dict, spec: dict, colour: np.ndarray) -> dict:
    """The scalp cap: skin triangles near and above the hairline, subdivided, the pieces
    above it kept and lifted off the skin."""
    tris = head["skin_t"]
    near = (above_hairline(head["v"], head, spec)[tris] > -0.02).any(1)
    pos, nrm, sub = subdivide(head["v"], head["normals"], tris[near], 3)
    above = above_hairline(pos, head, spec)
    keep = largest_patch(pos, sub[(above[sub] > 0).all(1)])
    ids = np.unique(keep)
    soft = np.clip(above[ids] / (spec["soft_mm"] / 1000), 0, 1)
    soft = soft * soft * (3 - 2 * soft)
    v = pos[ids] + nrm[ids] * (spec["cap_mm"] / 1000 * (0.3 + 0.7 * soft))[:, None]
    skin_rgb = head["colours"][cKDTree(head["v"]).query(pos[ids])[1]]
    rgb = soft[:, None] * colour + (1 - soft[:, None]) * skin_rgb
    local = np.searchsorted(ids, keep)
    return {"v": v, "t": local, "c": rgb, "ao": 0.55 + 0.35 * (1 - soft),
            "uv": np.zeros((len(ids), 2)), "roots": (v, local, soft)}


def sample_roots(cap_mesh: tuple, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` points spread over the cap (area-weighted), where it is not fading."""
    v, t, soft = cap_mesh
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = np.linalg.norm(np.cross(b - a, c - a), axis=1) * soft[t].min(1)
    pick = rng.choice(len(t), size=count, p=area / area.sum())
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    return ((1 - s)[:, None] * a[pick] + (s * (1 - r2))[:, None] * b[pick]
            + (s * r2)[:, None] * c[pick])


def flow(style: dict, p: np.ndarray) -> np.ndarray:
    """Combing direction ``(N, 3)`` at points ``p``."""
    kind = style["flow"]
    if kind == "back":
        up = np.clip((p[:, 1] - 0.06) / 0.06, 0, 1)[:, None]
        side = np.sign(p[:, 0])[:, None] * np.array([1.0, 0, 0])
        d = up * np.array([0, 0.1, -1.0]) + (1 - up) * (DOWN + 0.9 * np.array([0, 0, -1.0])
                                                         + 0.2 * side)
    elif kind == "part":
        part = style["part_x_mm"] / 1000
        away = np.where(p[:, 0] >= part, 1.0, -1.0)[:, None] * np.array([1.0, 0, 0])
        # the parting runs from the hairline back to the crown; behind it the hair falls
        # straight down the back (parted to the nape, it opened a gap like a tent)
        parted = np.clip((p[:, 2] - PART_BACK[0]) / (PART_BACK[1] - PART_BACK[0]), 0, 1)
        d = 0.8 * parted[:, None] * away + 0.5 * DOWN + 0.45 * np.array([0, 0, -1.0])
    else:
        d = np.asarray(style["tie_mm"]) / 1000 - p
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)


def turn(d: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues: rotate ``d`` about unit ``axis`` (both ``(N, 3)``) by ``angle`` ``(N,)``."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return d * c + np.cross(axis, d) * s + axis * np.einsum("ij,ij->i", axis, d)[:, None] * (1 - c)


def grow(body: Body, style: dict, layer: dict, roots: np.ndarray,
         rng: np.random.Generator) -> np.ndarray:
    """Strand polylines ``(N, K, 3)`` from ``roots`` ``(N, 3)``."""
    n, k = len(roots), layer["segments"] + 1
    offset = layer["offset_mm"] / 1000
    top = np.clip((roots[:, 1] - 0.03) / 0.09, 0, 1)
    lo = (1 - top) * layer["length_mm"]["side"][0] + top * layer["length_mm"]["top"][0]
    hi = (1 - top) * layer["length_mm"]["side"][1] + top * layer["length_mm"]["top"][1]
    length = rng.uniform(lo, hi) / 1000
    if style["flow"] == "tie":
        length = np.linalg.norm(np.asarray(style["tie_mm"]) / 1000 - roots, axis=1) * 1.25
    step = length / (k - 1)
    jitter = np.radians(style["jitter_deg"]) * rng.normal(size=n)
    p = body.keep_out(roots, offset)
    out = [p]
    for i in range(1, k):
        _, nq, dist = body.nearest(p)
        d = turn(flow(style, p), nq, jitter)
        hug = np.clip(1 - (dist - offset) / 0.015, 0, 1)[:, None]
        d = d - hug * np.einsum("ij,ij->i", d, nq)[:, None] * nq
        d = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
        d = d + style["gravity"] * (1 - 0.8 * hug) * DOWN
        d = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-9)
        p = p + step[:, None] * d
        lift = offset * (1 + style["lift"] * i)
        p = body.keep_out(p, lift)
        out.append(p)
    return np.stack(out, 1)


def ribbons(lines: np.ndarray, up: np.ndarray, width: np.ndarray, taper: float,
            first_card: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cards along ``lines`` ``(N, K, 3)``, lying across ``up`` ``(N, K, 3)`` (the surface
    normal): vertices ``(N*K*2, 3)``, triangles, uv."""
    n, k, _ = lines.shape
    tangent = np.gradient(lines, axis=1)
    side = np.cross(up, tangent)
    side /= np.maximum(np.linalg.norm(side, axis=2, keepdims=True), 1e-12)
    s = np.linspace(0, 1, k)
    half = (width[:, None] * (1 - (1 - taper) * s[None]) / 2)[..., None]
    verts = np.stack([lines - side * half, lines + side * half], 2).reshape(-1, 3)
    uv = np.zeros((n, k, 2, 2))
    uv[..., 0] = first_card + np.arange(n)[:, None, None] + np.array([0.02, 0.98])
    uv[..., 1] = s[None, :, None]
    ids = np.arange(n * k * 2).reshape(n, k, 2)
    a, b, c, d = ids[:, :-1, 0], ids[:, :-1, 1], ids[:, 1:, 0], ids[:, 1:, 1]
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([b, d, c], -1).reshape(-1, 3)])
    return verts, tris, uv.reshape(-1, 2)


def ponytail(spec: dict, first_card: int, rng: np.random.Generator) -> dict:
    path = np.asarray(spec["path"], float) / 1000
    spine = CubicSpline(np.linspace(0, 1, len(path)), path, axis=0)
    k, n = spec["segments"] + 1, spec["cards"]
    r0, r1, r2 = np.asarray(spec["radius_mm"]) / 1000
    # each lock its own length, and the locks loosen toward the tips (fanning out and
    # winding a little about the tail): one radius for all read as a stiff tube
    reach = rng.uniform(0.72, 1.0, n)
    fan = rng.uniform(0.0, 0.9, n)
    wind, phase = rng.uniform(0.5, 1.5, n), rng.uniform(0, 2 * np.pi, n)
    s = reach[:, None] * np.linspace(0, 1, k)[None]  # (n, k) along the spine
    centre = spine(s)
    tangent = spine(s, 1)
    tangent /= np.linalg.norm(tangent, axis=2, keepdims=True)
    e1 = np.cross(tangent, [1.0, 0, 0])
    e1 /= np.linalg.norm(e1, axis=2, keepdims=True)
    e2 = np.cross(tangent, e1)
    radius = np.interp(s, [0, 0.35, 1], [r0, r1, r2]) * (1 + fan[:, None] * s ** 2)
    angle = (np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.normal(0, 0.15, n))[:, None]
    angle = angle + 0.3 * s * np.sin(2 * np.pi * wind[:, None] * s + phase[:, None])
    scale = rng.uniform(0.55, 1.05, n)
    around = np.cos(angle)[..., None] * e1 + np.sin(angle)[..., None] * e2
    lines = centre + around * (radius * scale[:, None])[..., None]
    width = spec["width_mm"] / 1000 * rng.uniform(0.8, 1.2, n)
    v, t, uv = ribbons(lines, around, width, spec["taper"], first_card)
    tangent, e1, e2 = tangent[0], e1[0], e2[0]  # the band sits where the tail starts
    ring_a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    band_v = []
    for dy, rr in ((0.0, r0 * 1.15), (0.006, r0 * 1.15)):
        at = spine(0.03) + dy * -tangent[0]
        band_v.append(at + rr * (np.cos(ring_a)[:, None] * e1[0] + np.sin(ring_a)[:, None] * e2[0]))
    bv = np.concatenate(band_v)
    i = np.arange(16)
    bt = np.concatenate([np.stack([i, (i + 1) % 16, i + 16], 1),
                         np.stack([(i + 1) % 16, (i + 1) % 16 + 16, i + 16], 1)]) + len(v)
    return {"v": np.concatenate([v, bv]), "t": np.concatenate([t, bt]),
            "uv": np.concatenate([uv, np.zeros((32, 2))]), "n_band": 32,
            "band_rgb": np.asarray(spec["band_rgb"])}


def colours_of(uv: np.ndarray, style: dict, depth: float, rng_card: np.ndarray) -> np.ndarray:
    root, tip = np.asarray(style["colour"]), np.asarray(style["tip_colour"])
    v = uv[:, 1:2]
    card = uv[:, 0].astype(int)
    rgb = root + (tip - root) * v ** 1.3
    return np.clip(rgb * rng_card[card][:, None], 0, 1)


def build_style(head: dict, hairline: dict, style: dict) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(style["seed"])
    base = cap(head, hairline, np.asarray(style["colour"]))
    parts = [base]
    card = 0
    n_layers = len(style["cards"])
    for depth, layer in enumerate(style["cards"]):
        roots = sample_roots(base["roots"], layer["count"], rng)
        lines = grow(head["body"], style, layer, roots, rng)
        _, up, _ = head["body"].nearest(lines.reshape(-1, 3))
        width = layer["width_mm"] / 1000 * rng.uniform(0.8, 1.2, len(roots))
        v, t, uv = ribbons(lines, up.reshape(lines.shape), width, layer["taper"], card)
        card += len(roots)
        ao = (0.55 + 0.35 * (depth + 1) / n_layers) * (0.75 + 0.25 * uv[:, 1])
        parts.append({"v": v, "t": t, "uv": uv, "ao": ao, "c": None})
    if "ponytail" in style:
        tail = ponytail(style["ponytail"], card, rng)
        card += style["ponytail"]["cards"]
        tail["ao"] = 0.7 + 0.3 * tail["uv"][:, 1]
        tail["c"] = None
        parts.append(tail)
    shade = rng.uniform(0.85, 1.15, card + 1)
    vs, ts, cs, aos, uvs = [], [], [], [], []
    start = 0
    for part in parts:
        rgb = part["c"] if part["c"] is not None else colours_of(part["uv"], style, 0, shade)
        if "n_band" in part:
            rgb[-part["n_band"]:] = part["band_rgb"]
        vs.append(part["v"])
        ts.append(part["t"] + start)
        cs.append(rgb)
        aos.append(part["ao"])
        uvs.append(part["uv"])
        start += len(part["v"])
    return {"vertices": np.concatenate(vs).astype(np.float32),
            "triangles": np.concatenate(ts).astype(np.int32),
            "colors": np.round(np.clip(np.concatenate(cs), 0, 1) * 255).astype(np.uint8),
            "ao": np.round(np.clip(np.concatenate(aos), 0, 1) * 255).astype(np.uint8),
            "uv": np.concatenate(uvs).astype(np.float32)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="build and report only")
    args = parser.parse_args()
    rules = json.loads((HEAD / "hair_styles.json").read_text())
    head = load_head()
    arrays: dict[str, np.ndarray] = {"styles": np.array(list(rules["styles"]))}
    for name, style in rules["styles"].items():
        built = build_style(head, rules["hairline"], style)
        print(f"{name}: {len(built['vertices'])} vertices, {len(built['triangles'])} triangles")
        arrays.update({f"{name}_{k}": a for k, a in built.items()})
    if not args.check:
        np.savez_compressed(OUT, **arrays)
        print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
