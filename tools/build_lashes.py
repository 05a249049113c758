"""Add eyelashes to facelib's default head: thin tapered cards along the lid margins.

Usage (from the repository root)::

    python tools/build_lashes.py          # adds (or rebuilds) the lashes of the built head

``tools/build_default_head.py`` runs it at the end of every build, so a rebuilt head keeps its
lashes. Reads and rewrites ``facelib/data/head/default_head.npz`` and ``default_head.json``:
the lash vertices are appended after every other part (no other vertex index changes), as
the optional part ``lashes``, and every lash vertex gets a rider entry (two margin vertices
and a blend): the engine moves it with that point of the lid margin, through the linear
operator and the lid's rotation over the eye (see ``facelib/engine/riders.py``). The build is
deterministic (a fixed seed jitters spacing, length and direction).

How the margin is found: the skin vertices just outside the eyeball sphere (under 1.1 radii
from the eye centre) are the socket lining; the vertices next to the lining, in front of the
eye, form the inner rim of the lids, and their neighbours further out the front rim, where
lashes grow. The front rim splits into the upper line (members of the upper-lid region) and
the lower line (the rest below the eye between the corners).
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from facelib.engine.surface import segments_cross, vertex_normals

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"
SEED = 14

LINING = 1.1  # eye radii: skin closer to the eye centre than this lines the socket
UPPER_MIN_WEIGHT = 0.15  # front-rim vertices with at least this upper-lid weight carry upper lashes
# per lid: lash spacing along the margin (m), longest lash (m), how far the longest sits
# along the line from the outer corner (0) to the inner one (1), the share of the length
# that rises away from the eye (curl), width at the root and tip (m)
LIDS = {
    "upper": {"spacing": 0.00034, "length": 0.0068, "peak": 0.40, "curl": 0.5,
              "root": 0.00036, "tip": 0.00006},
    "lower": {"spacing": 0.00055, "length": 0.0028, "peak": 0.35, "curl": 0.2,
              "root": 0.00024, "tip": 0.00004},
}
# the lower line: front-rim vertices between these angles (degrees about the eye centre, 0 =
# toward the outer corner, -90 = straight down); lashes nearer the outer corner would stick
# through the upper lid as it closes over them
LOWER_ANGLES = (-160.0, -22.0)
SECTIONS = (0.0, 0.25, 0.5, 0.75, 1.0)  # positions along a lash where its card has a rib
RIBS = 2 * len(SECTIONS) - 1  # vertices per lash (two per rib, one at the tip)
# lashes that pass through the skin in any of these poses (a blink, half and full, and every
# library expression) are shortened by SHORTEN until none does
SHORTEN, MAX_ROUNDS = 0.8, 12
MIN_LENGTH = 0.0006  # metres: a lash shortened below this is left out
ROOTED = 0.0004  # metres of a lash next to its root that may lie in the skin, as real roots do
BLINKS = ({"close_t_l_eyelid": 512.0, "close_t_r_eyelid": 512.0},
          {"close_t_l_eyelid": 1024.0, "close_t_r_eyelid": 1024.0})
ROOT_COLOUR = np.array([0.045, 0.035, 0.03])
TIP_COLOUR = np.array([0.16, 0.12, 0.10])
RADIAL_LEAN = 2  # lashes leave the skin along its normal plus this much of the eye's radius
LIFT = 0.00005  # metres: roots sit this far outside the margin, off the skin


def neighbours(tris: np.ndarray) -> dict[int, set[int]]:
    adj: dict[int, set[int]] = defaultdict(set)
    for a, b, c in tris.tolist():
        adj[a] |= {b, c}
        adj[b] |= {a, c}
        adj[c] |= {a, b}
    return adj


def front_rim(pos, skin, adj, centre, radius):
    """Skin vertices of the lids' front rim around one eye (a set of ids)."""
    ratio = np.linalg.norm(pos[skin] - centre, axis=1) / radius
    lining = set(skin[ratio < LINING].tolist())
    near = {int(i) for i, r in zip(skin, ratio, strict=True)
            if r < 1.5 and pos[i, 2] - centre[2] > 0.4 * radius}
    inner = {i for i in near if i not in lining and adj[i] & lining}
    return {j for i in inner for j in adj[i]
            if j not in inner and j not in lining and pos[j, 2] >= pos[i, 2] - 1e-4}


def lid_lines(pos, rim, centre, side_sign, upper_weights):
    """(upper, lower) margin lines, each an ordered array of vertex ids from the outer
    corner to the inner one."""
    rim = np.array(sorted(rim))
    rel = pos[rim] - centre
    angle = np.degrees(np.arctan2(rel[:, 1], side_sign * rel[:, 0]))
    w = np.array([upper_weights.get(int(i), 0.0) for i in rim])
    up = w >= UPPER_MIN_WEIGHT
    up_angle = np.where(angle > -90, angle, angle + 360)
    upper = rim[up][np.argsort(up_angle[up])]
    low = ~up & (angle < LOWER_ANGLES[1]) & (angle > LOWER_ANGLES[0])
    lower = rim[low][np.argsort(-angle[low])]
    return upper, lower


def lashes_of_line(pos, normals, line, centre, *, lid, rng, scales):
    """Cards of one lid line: ``(verts (N, 3), tris (M, 3) local, colours (N, 3),
    anchors (N, 2), blend (N,), kept (K,), n)``: ``n`` places along the line, the lashes
    built at places ``kept`` (``scales`` (n,) shortens each place's lash; shorter than
    MIN_LENGTH leaves it out)."""
    spec = LIDS[lid]
    pts = pos[line]
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    n = int(arc[-1] / spec["spacing"])
    at = (np.arange(n) + 0.5 + rng.uniform(-0.3, 0.3, n)) / n * arc[-1]
    verts, tris, cols, anchors, blend, kept = [], [], [], [], [], []
    away = 1.0 if lid == "upper" else -1.0
    for i, s in enumerate(at):
        k = int(np.clip(np.searchsorted(arc, s) - 1, 0, len(line) - 2))
        t = float((s - arc[k]) / seg[k])
        root = (1 - t) * pts[k] + t * pts[k + 1]
        tangent = (pts[k + 1] - pts[k]) / seg[k]
        radial = (root - centre) / np.linalg.norm(root - centre)
        # out of the skin, leaning away from the eye centre
        radial = (1 - t) * normals[line[k]] + t * normals[line[k + 1]] + RADIAL_LEAN * radial
        radial /= np.linalg.norm(radial)
        rise = np.array([0.0, away, 0.0]) - away * radial[1] * radial
        rise /= np.linalg.norm(rise)
        u = s / arc[-1]
        shape = np.sin(np.pi * np.clip(u / (2 * spec["peak"]), 0, 0.5)) if u < spec["peak"] \
            else np.cos(0.5 * np.pi * (u - spec["peak"]) / (1 - spec["peak"]))
        length = spec["length"] * (0.08 + 0.92 * shape**0.7) * rng.uniform(0.85, 1.1)
        fan = np.cross(radial, rise) * rng.uniform(-0.12, 0.12)
        length *= scales[i] if i < len(scales) else 1.0
        if length < MIN_LENGTH:
            continue
        base = len(verts)
        for j, h in enumerate(SECTIONS):
            along = root + LIFT * radial + length * (
                (1 - spec["curl"] * 0.5) * h * (radial + fan) + spec["curl"] * h * h * rise)
            half = 0.5 * (spec["root"] + (spec["tip"] - spec["root"]) * h)
            ribs = [along] if j == len(SECTIONS) - 1 else [along - half * tangent,
                                                            along + half * tangent]
            verts.extend(ribs)
            cols.extend([(1 - h) * ROOT_COLOUR + h * TIP_COLOUR] * len(ribs))
        for j in range(len(SECTIONS) - 2):
            a = base + 2 * j
            tris.extend([(a, a + 1, a + 3), (a, a + 3, a + 2)])
        a = base + 2 * (len(SECTIONS) - 2)
        tris.append((a, a + 1, a + 2))
        kept.append(i)
        anchors.extend([(line[k], line[k + 1])] * (len(verts) - base))
        blend.extend([t] * (len(verts) - base))
    return (np.array(verts), np.array(tris), np.array(cols), np.array(anchors),
            np.array(blend), np.array(kept, int), n)


def strip_lashes(verts, tris, cols, doc):
    """The head without lashes (a rebuild starts from this)."""
    if "lashes" not in doc["parts"]:
        return verts, tris, cols, doc
    start = doc["parts"].pop("lashes")[0]
    doc.pop("riders", None)
    keep = (tris < start).all(axis=1)
    return verts[:start], tris[keep], cols[:start], doc


def add_lashes(verts, tris, cols, doc, scales=None):
    """``(verts, tris, cols, doc, slots, places)``: the head with the lashes of both eyes
    appended (vertex arrays as the mesh file stores them: metres, colours uint8; ``doc`` the
    face definition), which of the ``places`` along the margins each lash grows at
    (``slots`` (n_lashes,)), and how many places there are. ``scales`` (places,) shortens
    the lash of each place (all 1 if None)."""
    verts, tris, cols, doc = strip_lashes(verts, tris, cols, doc)
    pos = verts.astype(np.float64)
    start, stop = doc["parts"]["skin"]
    skin = np.arange(start, stop)
    adj = neighbours(tris)
    skin_tris = tris[(tris < stop).all(axis=1) & (tris >= start).all(axis=1)]
    normals = vertex_normals(pos, skin_tris)
    rng = np.random.default_rng(SEED)
    pieces, slots, places = [], [], 0
    for side, sign in (("l", 1.0), ("r", -1.0)):
        centre = np.asarray(doc["pivots"][f"eye_{side}"])
        a, b = doc["parts"][f"eye_{side}"]
        radius = float(np.linalg.norm(pos[a:b] - centre, axis=1).max())
        lid = next(r for r in doc["regions"] if r["name"] == f"upper_lid_{side}")
        weights = dict(zip(lid["vertices"], lid["weights"], strict=True))
        rim = front_rim(pos, skin, adj, centre, radius)
        upper, lower = lid_lines(pos, rim, centre, sign, weights)
        for kind, line in (("upper", upper), ("lower", lower)):
            mine = np.ones(0) if scales is None else scales[places:]
            pieces.append(lashes_of_line(pos, normals, line, centre, lid=kind, rng=rng,
                                         scales=mine))
            slots.extend((places + pieces[-1][5]).tolist())
            places += pieces[-1][6]
            print(f"{side} {kind}: {len(pieces[-1][0]) // RIBS} lashes "
                  f"on {len(line)} margin vertices")
    n0 = len(verts)
    out_v, out_t, out_c = [verts], [tris], [cols]
    anchors, blend, offset = [], [], n0
    for v, t, c, an, bl, _, _ in pieces:
        out_v.append(v.astype(verts.dtype))
        out_t.append((t + offset).astype(tris.dtype))
        out_c.append(np.round(c * 255).astype(cols.dtype))
        anchors.append(an)
        blend.append(bl)
        offset += len(v)
    doc["parts"]["lashes"] = [n0, offset]
    doc["riders"] = {"lashes": {
        "anchors": np.concatenate(anchors).astype(int).tolist(),
        "blend": [round(float(x), 5) for x in np.concatenate(blend)]}}
    print(f"lashes: {offset - n0} vertices, {sum(len(p[1]) for p in pieces)} triangles, "
          f"{sum(len(p[0]) // RIBS for p in pieces)} lashes")
    return (np.concatenate(out_v), np.concatenate(out_t), np.concatenate(out_c), doc,
            np.array(slots, int), places)


def crossing_lashes(face, poses):
    """(n_lashes,) bool: lashes whose centre line passes through the skin in any pose."""

    lash = face.parts["lashes"].vertex_ids
    skin = face.parts["skin"].triangles
    out = np.zeros(lash.size // RIBS, bool)
    for pose in poses:
        p = face.deform_frame(pose).astype(np.float64)
        cards = p[lash].reshape(-1, RIBS, 3)
        line = np.concatenate([(cards[:, 0:-1:2] + cards[:, 1:-1:2]) / 2, cards[:, -1:]], 1)
        first = line[:, 1] - line[:, 0]
        step = np.linalg.norm(first, axis=1, keepdims=True)
        line[:, 0] += first * np.minimum(ROOTED / np.maximum(step, 1e-12), 0.5)
        corners = p[skin]
        centre = corners.mean(axis=1)
        near = np.zeros(len(skin), bool)
        for eye in ("eye_l", "eye_r"):
            near |= np.linalg.norm(centre - face.pivots[eye], axis=1) < 0.035
        hits = segments_cross(line[:, :-1].reshape(-1, 3), line[:, 1:].reshape(-1, 3),
                              corners[near])
        out |= hits.reshape(len(line), -1).any(axis=1)
    return out


def check_poses():
    """(P, 84) FAP frames the lashes must clear the skin in."""
    from facelib.expressions.library import default_library
    from facelib.mpeg4.tables import fap

    out = []
    for blink in BLINKS:
        f = np.zeros(84, np.float32)
        for name, value in blink.items():
            f[fap(name).index] = value
        out.append(f)
    library = default_library()
    out.extend(library.get(name).values for name in library.names)
    return out


def save(folder, arrays, doc):
    np.savez_compressed(folder / "default_head.npz", **arrays)
    (folder / "default_head.json").write_text(json.dumps(doc, indent=1) + "\n")


def main() -> None:
    import tempfile

    from facelib.engine import load_face

    doc = json.loads((HEAD / "default_head.json").read_text())
    with np.load(HEAD / "default_head.npz") as z:
        arrays = {k: z[k] for k in z.files}
    poses, scales = check_poses(), None
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(MAX_ROUNDS):
            out = dict(arrays)
            v, t, c, new_doc, slots, places = add_lashes(
                arrays["vertices"], arrays["triangles"], arrays["vertex_colors"],
                json.loads(json.dumps(doc)), scales)
            out.update(vertices=v, triangles=t, vertex_colors=c)
            save(Path(tmp), out, new_doc)
            bad = crossing_lashes(load_face(Path(tmp) / "default_head.json"), poses)
            print(f"{int(bad.sum())} lashes pass through the skin in some pose")
            if not bad.any():
                break
            scales = np.ones(places) if scales is None else scales
            scales[slots[bad]] *= SHORTEN
        else:
            raise SystemExit("lashes still pass through the skin; check the margin lines")
    save(HEAD, out, new_doc)


if __name__ == "__main__":
    main()
