"""Render the default head in a few FAP poses for visual checks and the docs.

Usage (from the repository root)::

    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/render_head_views.py docs/images/engine

Writes ``<name>.png``, a labelled grid of all poses (``--zoom`` and ``--target-y`` frame a
close-up, ``--side`` adds side views). Needs pyrender
(the ``render`` extra) and matplotlib; it is a tool, not part of the library.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from facelib.engine import load_face
from facelib.mpeg4.tables import fap

POSES: dict[str, dict[str, float]] = {
    "neutral": {},
    "jaw open": {"open_jaw": 800},
    "lip corners raised": {"raise_l_cornerlip_o": 300, "raise_r_cornerlip_o": 300,
                           "raise_l_cornerlip": 300, "raise_r_cornerlip": 300,
                           "stretch_l_cornerlip_o": 120, "stretch_r_cornerlip_o": 120,
                           "stretch_l_cornerlip": 120, "stretch_r_cornerlip": 120},
    "brows raised": {f"raise_{s}_{p}_eyebrow": 250 for s in "lr" for p in "imo"},
    "eyes left": {"yaw_l_eyeball": 30000, "yaw_r_eyeball": 30000},
    "eyes right": {"yaw_l_eyeball": -30000, "yaw_r_eyeball": -30000},
    "eyes up": {"pitch_l_eyeball": -25000, "pitch_r_eyeball": -25000},
    "blink": {"close_t_l_eyelid": 1024, "close_t_r_eyelid": 1024,
              "close_b_l_eyelid": 0, "close_b_r_eyelid": 0},
    "half blink": {"close_t_l_eyelid": 512, "close_t_r_eyelid": 512},
    "head turned": {"head_yaw": 30000, "head_pitch": 10000, "open_jaw": 300},
    "speech 'oo'": {"open_jaw": 250, "push_b_lip": 200, "push_t_lip": 200,
                    "stretch_l_cornerlip_o": -250, "stretch_r_cornerlip_o": -250,
                    "stretch_l_cornerlip": -250, "stretch_r_cornerlip": -250},
    "tongue out": {"open_jaw": 700, "thrust_tongue_tip": 500, "raise_tongue_tip": 750},
}


def frame(values: dict[str, float]) -> np.ndarray:
    out = np.zeros(84, np.float32)
    for name, v in values.items():
        out[fap(name).index] = v
    return out


def render(face, positions, *, side: bool = False, size: int = 420, zoom: float = 1.0,
           target_y: float = 0.0):
    import pyrender
    import trimesh

    # the baked ambient occlusion, as facelib's renderer multiplies it in (linearly here)
    ao = np.ones(len(face.vertices)) if face.vertex_ao is None else face.vertex_ao
    colours = (face.vertex_colors * ao[:, None] * 255).astype(np.uint8)
    mesh = trimesh.Trimesh(positions, face.triangles, vertex_colors=colours, process=False)
    scene = pyrender.Scene(ambient_light=[0.35, 0.35, 0.35], bg_color=[0.2, 0.22, 0.26, 1])
    scene.add(pyrender.Mesh.from_trimesh(mesh, smooth=True))
    target = np.array([0.0, target_y, 0.09])
    dist = 0.42 / zoom
    direction = np.array([0.85, 0.0, 0.53]) if side else np.array([0.0, 0.0, 1.0])
    eye = target + dist * direction
    z = (eye - target) / np.linalg.norm(eye - target)
    x = np.cross([0, 1, 0], z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], 1)
    pose[:3, 3] = eye
    scene.add(pyrender.PerspectiveCamera(yfov=0.55), pose=pose)
    light = pose.copy()
    light[:3, 3] += [0.2, 0.3, 0]
    scene.add(pyrender.DirectionalLight(intensity=3.0), pose=pose)
    scene.add(pyrender.PointLight(intensity=0.6), pose=light)
    r = pyrender.OffscreenRenderer(size, size)
    try:
        color, _ = r.render(scene)
    finally:
        r.delete()
    return color


def main() -> None:
    import matplotlib as mpl

    mpl.use("Agg")
    import matplotlib.pyplot as plt

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--zoom", type=float, default=1.0)
    parser.add_argument("--name", default="poses", help="file name of the grid, without .png")
    parser.add_argument("--side", action="store_true", help="add two side views")
    parser.add_argument("--target-y", type=float, default=0.0, help="look at this height (m)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    face = load_face()
    images = {}
    for name, values in POSES.items():
        pos = face.deform_frame(frame(values))
        images[name] = render(face, pos, zoom=args.zoom, target_y=args.target_y)
    if args.side:
        images["neutral, side"] = render(face, face.vertices, side=True)
        images["jaw open, side"] = render(face, face.deform_frame(frame(POSES["jaw open"])),
                                          side=True)
    cols = 4
    rows = -(-len(images) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(cols * 3, rows * 3.2))
    for ax, (name, img) in zip(axes.flat, images.items(), strict=False):
        ax.imshow(img)
        ax.set_title(name, fontsize=10)
    for ax in axes.flat:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(args.out / f"{args.name}.png", dpi=80)


if __name__ == "__main__":
    main()
