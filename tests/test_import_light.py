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


def test_import_facelib_does_not_load_scipy_signal():
    # scipy.signal alone cost 74 % of import facelib's CPU (issue 30): the gaze model's drift
    # filter is written out instead, and the engine (scipy.sparse, scipy.spatial) loads on
    # first use of facelib.Face / facelib.load_face
    code = ("import sys, facelib\n"
            "heavy = ('scipy.signal', 'facelib.engine')\n"
            "print(sorted(m for m in sys.modules if m in heavy or m.startswith(\n"
            "    tuple(h + '.' for h in heavy))))\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "[]"
