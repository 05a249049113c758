"""docs/images/vrm_three_vrm.png: facelib's VRM avatar playing the hello example's VRM
animation in @pixiv/three-vrm (headless Chromium, facelib/export/web/tools/vrm_check.mjs),
one cell per chosen time, each labelled with the strongest expressions facelib wrote there.

Run from the repository root (needs node, the npm packages of ``make web`` and chromium)::

    python tools/render_vrm_shots.py
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import imageio.v3 as iio
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from contact_sheet import label, sheet

import facelib
from facelib.export import export_gltf, export_vrm, export_vrma
from facelib.export.web import WEB_DIR

ROOT = Path(__file__).parents[1]
TIMES = (0.0, 1.0, 2.0, 3.48, 4.6, 6.0)


def main() -> None:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    animation = facelib.run_fdl(ROOT / "examples" / "hello" / "hello.fdl")
    cells = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        avatar = export_vrm(animation, root / "hello.vrm")
        motion = export_vrma(animation, root / "hello.vrma")
        for t in TIMES:
            png = root / f"shot_{t}.png"
            job = {"vrm": str(avatar.path), "vrma": str(motion.path), "chromium": chromium,
                   "shoot": {"t": t, "png": str(png)}}
            (root / "job.json").write_text(json.dumps(job))
            subprocess.run(["node", str(WEB_DIR / "tools" / "vrm_check.mjs"),
                            str(root / "job.json")], check=True, capture_output=True)
            frame = min(round(t * motion.fps), motion.n_frames - 1)
            weights = motion.weights[frame]
            top = [f"{motion.presets[k]} {weights[k]:.2f}" for k in np.argsort(-weights)[:2]
                   if weights[k] > 0.05]
            cells.append(label(np.asarray(iio.imread(png))[..., :3],
                               f"{t:.2f} s  " + ", ".join(top)))
        _write("vrm_three_vrm.png", sheet(cells, 3))
        glb = export_gltf(animation, root / "hello.glb").path
        shots = []
        for t in TIMES:
            png = root / f"blender_{t}.png"
            frame = min(round(t * motion.fps), motion.n_frames - 1) + 1  # Blender's
            subprocess.run(["blender", "-b", "--factory-startup", "--python",
                            str(ROOT / "tools" / "blender_shot.py"), "--", str(glb), str(png),
                            str(frame), str(int(motion.fps))], check=True, capture_output=True)
            shots.append(label(np.asarray(iio.imread(png))[..., :3], f"Blender, {t:.2f} s"))
        _write("blender_hello.png", sheet(shots, 3))


def _write(name: str, image: np.ndarray) -> None:
    out = ROOT / "docs" / "images" / name
    iio.imwrite(out, image)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
