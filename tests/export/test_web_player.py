"""The web player in a real browser (Debian's chromium, headless, driven by puppeteer-core):
the page loads the exported .glb, plays (frames change), and a scrubbed frame has the
silhouette of facelib's own render of that frame."""

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from gltf_eval import busy_stream

from facelib.engine import default_face
from facelib.export.web import WEB_DIR, export_html

pytestmark = [pytest.mark.browser, pytest.mark.render, pytest.mark.slow]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
GREEN = (0.0, 1.0, 0.0)


def _png(path: Path) -> np.ndarray:
    import imageio.v3 as iio

    return np.asarray(iio.imread(path))[..., :3]


def _silhouette(image: np.ndarray) -> np.ndarray:
    """Pixels that are not the pure green background."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return ~((g > 200) & (r < 60) & (b < 60))


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    if CHROMIUM is None or not (WEB_DIR / "node_modules" / "puppeteer-core").exists():
        pytest.skip("needs chromium and the npm packages (make setup)")
    from facelib.rendering.scene import FaceRenderer

    root = tmp_path_factory.mktemp("web")
    stream = busy_stream(250)  # 10 s: playing must not reach the end between slow shots
    audio = Path(__file__).parents[2] / "examples" / "hello" / "hello.flac"
    export_html(stream, root / "page", audio=audio)
    face = default_face()
    frames = (0, 12, 25)
    with FaceRenderer(face, width=640, height=480, background=GREEN) as renderer:
        camera = renderer.scene.main_camera_node.camera
        job = {"bg": "00ff00", "chromium": CHROMIUM, "play_ms": 300,
               "camera": [renderer.camera_pose.tolist(), camera.yfov, camera.znear,
                          camera.zfar],
               "times": [i / stream.fps for i in frames]}
        own = [renderer.frame(face.deform_frame(stream.values[i])) for i in frames]
    (root / "job.json").write_text(json.dumps(job))
    (root / "out").mkdir()
    run = subprocess.run(["node", str(WEB_DIR / "tools" / "shoot.mjs"), str(root / "page"),
                          str(root / "out"), str(root / "job.json")],
                         capture_output=True, text=True, timeout=180, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    summary = json.loads(run.stdout.strip().splitlines()[-1])
    return root / "out", summary, own, frames


def test_page_loads_without_errors_and_scrubs(shots):
    out, summary, _, frames = shots
    assert summary["errors"] == []
    np.testing.assert_allclose(summary["seek"], [i / 25 for i in frames], atol=1e-6)
    assert (out / "seek_0.png").stat().st_size > 1000


def test_scrubbed_frames_match_facelibs_render(shots):
    out, _, own, _ = shots
    for i, image in enumerate(own):
        browser = _silhouette(_png(out / f"seek_{i}.png"))
        ours = _silhouette(image)
        overlap = (browser & ours).sum() / (browser | ours).sum()
        print(f"frame {i}: silhouette overlap {overlap:.4f}")
        assert overlap >= 0.95, f"frame {i}: silhouette overlap {overlap:.3f}"
    # the frames differ from each other where the head turns (the test can fail)
    a, b = _silhouette(_png(out / "seek_0.png")), _silhouette(_png(out / "seek_1.png"))
    assert (a ^ b).sum() > 0.02 * a.sum()


def test_playing_changes_the_frames(shots):
    out, summary, _, _ = shots
    first, second = _png(out / "play_0.png"), _png(out / "play_1.png")
    assert summary["play"][1] > summary["play"][0]
    assert np.abs(first.astype(int) - second.astype(int)).max() > 50


def test_the_page_carries_the_chosen_hair_and_the_bust(tmp_path):
    """``facelib export --html DIR --hair long``: the browser shows the long hair and the
    bust (framed on the bust) with the silhouette of facelib's render of that face."""
    if CHROMIUM is None or not (WEB_DIR / "node_modules" / "puppeteer-core").exists():
        pytest.skip("needs chromium and the npm packages (make setup)")
    from facelib.cli import main
    from facelib.engine import load_face
    from facelib.mpeg4 import write_fap_complete
    from facelib.rendering.scene import FaceRenderer, framing_points

    stream = busy_stream(50)
    write_fap_complete(stream, tmp_path / "busy.fap")
    assert main(["export", str(tmp_path / "busy.fap"), "--html", str(tmp_path / "page"),
                 "--hair", "long"]) == 0
    faces = {style: load_face(hair=style) for style in ("long", "none")}
    bust = framing_points(faces["long"], "bust")  # both framed as the long-haired face
    own = {}
    for style, face in faces.items():
        with FaceRenderer(face, width=640, height=480, background=GREEN,
                          framing=bust) as renderer:
            camera = renderer.scene.main_camera_node.camera
            job = {"bg": "00ff00", "chromium": CHROMIUM, "play_ms": 100,
                   "camera": [renderer.camera_pose.tolist(), camera.yfov, camera.znear,
                              camera.zfar], "times": [0.0]}
            own[style] = _silhouette(renderer.frame(face.deform_frame(stream.values[0])))
    (tmp_path / "job.json").write_text(json.dumps(job))
    (tmp_path / "out").mkdir()
    run = subprocess.run(["node", str(WEB_DIR / "tools" / "shoot.mjs"), str(tmp_path / "page"),
                          str(tmp_path / "out"), str(tmp_path / "job.json")],
                         capture_output=True, text=True, timeout=180, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    browser = _silhouette(_png(tmp_path / "out" / "seek_0.png"))
    assert browser.shape == own["long"].shape
    overlap = (browser & own["long"]).sum() / (browser | own["long"]).sum()
    assert overlap >= 0.95, overlap
    bald = (browser & own["none"]).sum() / (browser | own["none"]).sum()
    assert bald < overlap - 0.05, (bald, overlap)  # the hair is in the page
    # the bust's shoulders fill the bottom rows as wide as in facelib's render
    assert browser[-20:].mean() > 0.3
    assert abs(browser[-20:].mean() - own["long"][-20:].mean()) < 0.03
