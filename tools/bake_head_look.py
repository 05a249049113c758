"""Bake the default head's look: skin tone variation and per-vertex ambient occlusion.

Usage (from the repository root, after ``tools/build_default_head.py``, which also runs it)::

    PYTHONPATH=. python tools/bake_head_look.py

Two things, both stored in ``facelib/data/head/default_head.npz``:

1. **Skin tone** (:func:`skin_tone`, called by ``build_default_head.py`` while it paints the
   skin): the tints of ``facelib/data/head/skin_tone.json`` (warmer cheeks, nose and ears,
   a darker brow ridge and under-eye), a faint low-frequency mottle, and the neck darkening
   toward its cut. Applied to the build's base colours, so rebuilding never tints twice.
2. **Ambient occlusion** (``vertex_ao``, ``(V,) uint8``, 255 = open sky; :func:`occlusion`):
   for each of ``DIRECTIONS`` directions spread evenly over the sphere, an orthographic
   depth map of the whole head (every part, no culling) seen from that direction; a vertex
   is lit from a direction when it lies in front of the depth map there. The occlusion is
   the cosine-weighted fraction of the directions of its normal's hemisphere that reach
   it, the classic hemisphere integral of ambient occlusion, sampled by depth maps instead
   of ray casts (trimesh's ray casts need rtree, which the ``mesh`` extra does not have).
   Each vertex keeps the most open value over ``POSES`` (the neutral face and a wide-open
   jaw): the mouth cavity, teeth and tongue are judged as they are seen, with the mouth
   open, and the skin outside as it rests; teeth and tongue also over ``INSIDE_POSES``
   (the upper lip raised off the teeth). The renderer multiplies it in
   (``render_look.json``: ``occlusion``).

Deterministic: fixed directions, fixed poses, the same depth maps on any machine up to the
rasteriser's rounding (a few units of 255 on a handful of vertices at most).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
HEAD = ROOT / "facelib" / "data" / "head"

DIRECTIONS = 256  # hemisphere samples over the whole sphere (about 128 per vertex)
RESOLUTION = 1024  # depth map pixels across the head's bounding sphere (~0.3 mm each)
NORMAL_OFFSET = 0.0004  # metres: a vertex is tested this far out along its normal ...
DEPTH_BIAS = 0.0006  # ... and counts as lit within this distance behind the depth map
SMOOTHING = 2  # rounds of averaging each vertex's occlusion with its neighbours' (half)
POSES = {"neutral": {}, "open jaw": {"open_jaw": 700.0}}  # FAP values (FAP units)
# Poses that count for the parts inside the mouth only (RELATIVE_PARTS): the upper lip
# raised off the teeth, so the upper incisors' faces and the gums, hidden behind the lip at
# rest and in a plain jaw drop, are judged as they are seen when the lips part.
INSIDE_POSES = {"lips apart": {"open_jaw": 500.0, "lower_t_midlip": -500.0,
                               "lower_t_lip_lm": -450.0, "lower_t_lip_rm": -450.0}}
# Parts inside the mouth see the sky only through the opening (occlusion 0.0-0.2), which
# would paint them black; they keep their occlusion relative to the most open vertices of
# their front half (the front teeth, the tongue's blade), so they darken toward the back
# yet still read against the cavity, which stays dark. The power steepens that fall. The
# teeth parts (crowns and gums, most of them out of sight) are judged by a lower percentile,
# so the labial faces of the front teeth and the front gums, not only the incisors' very
# edges, count as open.
RELATIVE_PARTS = ("teeth_upper", "teeth_lower", "tongue")
RELATIVE_PERCENTILE = {"teeth_upper": 85.0, "teeth_lower": 85.0, "tongue": 98.0}
# the teeth fall off a little faster than the tongue: the front teeth catch the light, the
# molars stay dimmer, yet every crown keeps enough to read as a tooth (with its gaps)
RELATIVE_POWER = {"teeth_upper": 1.5, "teeth_lower": 1.5, "tongue": 1.5}
# The tongue leaves the mouth (tongue out, FAP 43-44): its top, deep under the palate at
# rest, must not turn black outside, so it keeps at least this much. The teeth keep a little
# (the molars seen past the corners of the lips are dim, not black).
RELATIVE_FLOOR = {"tongue": 0.3, "teeth_upper": 0.1, "teeth_lower": 0.1}


# ----------------------------------------------------------------------------- skin tone
def skin_tone(pos: np.ndarray, colours: np.ndarray, points: dict[str, int], *,
              neck_point: np.ndarray, neck_normal: np.ndarray) -> np.ndarray:
    """Tinted skin colours ``(Vs, 3)`` in [0, 1] from base colours ``colours (Vs, 3)``.

    ``pos`` ``(V, 3)`` metres (the skin's vertices first), ``points`` feature point id ->
    vertex; the neck plane by a point and its unit normal (pointing into the head).
    The rules are ``facelib/data/head/skin_tone.json``.
    """
    spec = json.loads((HEAD / "skin_tone.json").read_text())
    skin = pos[: len(colours)]
    out = np.array(colours, np.float64)
    for region in spec["regions"]:
        centre = pos[[points[p] for p in region["points"]]].mean(0)
        centre = centre + np.array(region["offset_mm"]) / 1000.0
        centres = [centre, centre * [-1, 1, 1]] if region.get("mirror") else [centre]
        tint = np.array(region["tint"]) - 1.0
        for c in centres:
            weight = np.exp(-(np.linalg.norm(skin - c, axis=1) / (region["radius_mm"] / 1e3))
                            ** 2)
            out *= 1.0 + weight[:, None] * tint
    out *= 1.0 + _mottle(skin, spec["variation"])
    neck = spec["neck"]
    height = (skin - neck_point) @ neck_normal
    t = np.clip(height / (neck["fade_mm"] / 1000.0), 0.0, 1.0)
    out *= (neck["darkest"] + (1.0 - neck["darkest"]) * t * t * (3 - 2 * t))[:, None]
    return np.clip(out, 0.0, 1.0)


def _mottle(pos: np.ndarray, spec: dict) -> np.ndarray:
    """``(V, 3)`` relative colour change: a sum of seeded plane waves of a few lengths."""
    rng = np.random.default_rng(spec["seed"])
    total = np.zeros((len(pos), 3))
    for wavelength, amplitude in zip(spec["wavelengths_mm"], spec["amplitudes"], strict=True):
        for _ in range(spec["waves"]):
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            phase = rng.uniform(0, 2 * np.pi)
            wave = np.sin(pos @ direction * (2 * np.pi * 1000.0 / wavelength) + phase)
            hue = 1.0 + np.array(spec["hue"]) * rng.uniform(-1, 1)
            total += amplitude / np.sqrt(spec["waves"]) * wave[:, None] * hue
    return total


# ----------------------------------------------------------------------- ambient occlusion
def sphere_directions(n: int) -> np.ndarray:
    """``(n, 3)`` unit vectors spread evenly over the sphere (Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    y = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - y * y)
    phi = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.stack([r * np.cos(phi), y, r * np.sin(phi)], axis=1)


def _camera_frame(direction: np.ndarray) -> np.ndarray:
    """``(3, 3)`` rows x, y, z of a camera whose +z is ``direction`` (it looks along -z)."""
    z = direction / np.linalg.norm(direction)
    up = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def _metric_depth(depth: np.ndarray, znear: float, zfar: float) -> np.ndarray:
    """Undo pyrender's perspective depth linearisation for an orthographic camera.

    pyrender turns window depth into ``2 n f / (f + n - z_ndc (f - n))`` whatever the
    camera; for an orthographic camera the true distance is linear in ``z_ndc``.
    Background (0) becomes ``inf``.
    """
    out = np.full(depth.shape, np.inf)
    hit = depth > 0
    z_ndc = (zfar + znear - 2.0 * znear * zfar / depth[hit]) / (zfar - znear)
    out[hit] = znear + (z_ndc + 1.0) / 2.0 * (zfar - znear)
    return out


def visibility(vertices: np.ndarray, triangles: np.ndarray, normals: np.ndarray,
               directions: np.ndarray) -> np.ndarray:
    """``(V, D) bool``: whether vertex ``v`` sees the open sky along direction ``d``.

    ``vertices`` ``(V, 3)`` metres, ``triangles`` ``(F, 3)``, unit ``normals`` ``(V, 3)``,
    ``directions`` ``(D, 3)`` unit vectors pointing away from the surface.
    """
    import pyrender

    centre = (vertices.min(0) + vertices.max(0)) / 2
    radius = float(np.linalg.norm(vertices - centre, axis=1).max()) * 1.02
    mesh = pyrender.Mesh([pyrender.Primitive(positions=vertices.astype(np.float32),
                                             indices=triangles.astype(np.uint32))])
    scene = pyrender.Scene()
    scene.add(mesh)
    camera = pyrender.OrthographicCamera(xmag=radius, ymag=radius, znear=0.5 * radius,
                                         zfar=3.5 * radius)
    cam_node = scene.add(camera)
    renderer = pyrender.OffscreenRenderer(RESOLUTION, RESOLUTION)
    probe = vertices + NORMAL_OFFSET * normals
    seen = np.zeros((len(vertices), len(directions)), bool)
    flags = pyrender.RenderFlags.DEPTH_ONLY | pyrender.RenderFlags.SKIP_CULL_FACES
    try:
        for i, direction in enumerate(directions):
            frame = _camera_frame(direction)
            pose = np.eye(4)
            pose[:3, :3] = frame.T
            pose[:3, 3] = centre + 2.0 * radius * direction
            scene.set_pose(cam_node, pose)
            depth = _metric_depth(renderer.render(scene, flags=flags), 0.5 * radius,
                                  3.5 * radius)
            local = (probe - pose[:3, 3]) @ frame.T  # camera coordinates
            col = ((local[:, 0] / radius + 1) / 2 * RESOLUTION).astype(int)
            row = ((1 - (local[:, 1] / radius + 1) / 2) * RESOLUTION).astype(int)
            col, row = np.clip(col, 0, RESOLUTION - 1), np.clip(row, 0, RESOLUTION - 1)
            seen[:, i] = -local[:, 2] <= depth[row, col] + DEPTH_BIAS
    finally:
        renderer.delete()
    return seen


def _smooth(values: np.ndarray, triangles: np.ndarray, rounds: int) -> np.ndarray:
    """Average each value half with the mean of its mesh neighbours, ``rounds`` times."""
    import scipy.sparse as sp

    n = len(values)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    adjacency = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                              shape=(n, n)).tocsr()
    adjacency = ((adjacency + adjacency.T) > 0).astype(np.float64)
    degree = np.maximum(np.asarray(adjacency.sum(1)).ravel(), 1.0)
    for _ in range(rounds):
        values = 0.5 * values + 0.5 * (adjacency @ values) / degree
    return values


def occlusion(face) -> np.ndarray:
    """``(V,) float64`` ambient occlusion in [0, 1] (1 = open sky) of a facelib ``Face``."""
    from facelib.engine.surface import vertex_normals
    from facelib.mpeg4 import fap

    directions = sphere_directions(DIRECTIONS)
    best = np.zeros(face.n_vertices)
    inside = np.concatenate([face.parts[name].vertex_ids for name in RELATIVE_PARTS])
    for pose, values in {**POSES, **INSIDE_POSES}.items():
        frame = np.zeros(84, np.float32)
        for name, value in values.items():
            frame[fap(name).index] = value
        vertices = np.asarray(face.deform_frame(frame), np.float64)
        # smooth normals as rendered: each part its own, except where parts share vertices
        # (the bust's first row is the head's neck loop: both sides' triangles count there)
        normals = vertex_normals(vertices, face.triangles, unused=(0.0, 0.0, 1.0))
        seen = visibility(vertices, face.triangles, normals, directions)
        weight = np.clip(normals @ directions.T, 0.0, None)
        open_sky = (seen * weight).sum(1) / np.maximum(weight.sum(1), 1e-9)
        if pose in INSIDE_POSES:
            best[inside] = np.maximum(best[inside], open_sky[inside])
        else:
            best = np.maximum(best, open_sky)
    ao = np.clip(_smooth(best, np.asarray(face.triangles), SMOOTHING), 0.0, 1.0)
    for name in RELATIVE_PARTS:
        ids = face.parts[name].vertex_ids
        # judged on the front half (the part's root may poke out of the cavity's floor,
        # unseen, into the open neck, where it sees the sky)
        front = ids[face.vertices[ids, 2] >= np.median(face.vertices[ids, 2])]
        top = max(float(np.percentile(ao[front], RELATIVE_PERCENTILE[name])), 1e-3)
        floor = RELATIVE_FLOOR.get(name, 0.0)
        ao[ids] = floor + (1.0 - floor) * np.clip(ao[ids] / top, 0.0, 1.0) ** RELATIVE_POWER[name]
    return ao


def write_occlusion(mesh_path: Path, ao: np.ndarray) -> None:
    """Store ``ao`` as ``vertex_ao (V,) uint8`` in the mesh file, keeping its other arrays."""
    with np.load(mesh_path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["vertex_ao"] = np.round(np.clip(ao, 0, 1) * 255).astype(np.uint8)
    np.savez_compressed(mesh_path, **arrays)


def main() -> None:
    sys.path.insert(0, str(ROOT))
    from facelib.engine import load_face
    from facelib.rendering.platform import import_pyrender

    import_pyrender(offscreen=True)  # chooses the headless platform before OpenGL loads
    # the head alone, as it is defined without its attachments (no bust, no hair): its AO
    # serves every bust and hair style, and bald
    doc = json.loads((HEAD / "default_head.json").read_text())
    alone = HEAD / ".bake_head.json"  # beside the mesh files it names
    alone.write_text(json.dumps({k: v for k, v in doc.items() if k not in ("bust", "hair")}))
    try:
        face = load_face(alone)
    finally:
        alone.unlink()
    ao = occlusion(face)
    write_occlusion(HEAD / "default_head.npz", ao)
    for name, part in face.parts.items():
        values = ao[part.vertex_ids]
        print(f"{name}: ambient occlusion {values.min():.2f}-{values.max():.2f}, "
              f"mean {values.mean():.2f}")


if __name__ == "__main__":
    main()
