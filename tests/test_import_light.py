"""`import facelib` loads numpy, scipy and lupa at most: no OpenGL, speech or plotting."""

import subprocess
import sys

HEAVY = ("OpenGL", "pyrender", "pocketsphinx", "matplotlib", "pyglet", "imageio_ffmpeg", "trimesh",
         "pygltflib")


def test_import_facelib_is_light():
    code = (
        "import sys, facelib, facelib.cli\n"
        f"heavy = [m for m in sys.modules if m.split('.')[0] in {HEAVY!r}]\n"
        "print(','.join(heavy))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == ""
