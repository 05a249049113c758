"""The core pipeline with none of the extras: storyboard -> FAP stream -> ``.fap``.

Run by ``make minimal`` in its own virtualenv (``.venv-minimal``, facelib installed with
no extras); ``make test`` runs it. It fails if an extra's package is importable there (the
check would prove nothing) or if any step of the core pipeline needs one.

Usage: ``.venv-minimal/bin/python tools/minimal_install_check.py``
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STORYBOARD = ROOT / "tests" / "data" / "pipeline" / "small.fdl"
EXTRAS = ("pyrender", "OpenGL", "imageio_ffmpeg", "tqdm", "pyglet", "pocketsphinx",
          "matplotlib", "pytest", "hypothesis")


def main() -> int:
    present = [name for name in EXTRAS if importlib.util.find_spec(name) is not None]
    if present:
        print(f"minimal install: extras are installed here: {present}", file=sys.stderr)
        return 1
    import facelib

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "small.fap"
        # the command line, as a user without extras would run it
        subprocess.run([sys.executable, "-m", "facelib.cli", "run", str(STORYBOARD), "-o",
                        str(out)], check=True)
        stream = facelib.read_fap(out, strict=True)
        animation = facelib.run_fdl(STORYBOARD)
    moving = stream.values[:, 2:].any(axis=0).sum()
    if stream.n_frames < 25 or moving < 10 or stream.n_frames != animation.faps.n_frames:
        print(f"minimal install: implausible stream ({stream.n_frames} frames, "
              f"{moving} moving FAPs)", file=sys.stderr)
        return 1
    print(f"minimal install: {STORYBOARD.name} -> {stream.n_frames} frames at "
          f"{stream.fps:g} fps, {moving} FAPs moving, without extras")
    return 0


if __name__ == "__main__":
    sys.exit(main())
