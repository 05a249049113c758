"""The live page (examples/live) in a real browser against `facelib serve`: Debian's chromium,
headless, driven by puppeteer-core (facelib/export/web/tools/live_shoot.mjs). The server runs
in this process on a free loopback port; the page types a line, plays the streamed audio on
its Web Audio clock and the test compares two canvases captured while that audio plays."""

import asyncio
import json
import shutil
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

from facelib.export.web import WEB_DIR, export_html

pytestmark = [pytest.mark.browser, pytest.mark.render, pytest.mark.slow, pytest.mark.speech]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
LIVE = Path(__file__).parents[2] / "examples" / "live"
LINE = ("Hello there, how are you today? I am glad to see you. Shall we talk for a while "
        "about the weather?")


def _png(path: Path) -> np.ndarray:
    import imageio.v3 as iio

    return np.asarray(iio.imread(path))[..., :3].astype(int)


def _lips(image: np.ndarray) -> np.ndarray:
    """(H, W) bool: the red of the lips (skin is paler, the background green)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (r - g > 70) & (r - b > 50)


class _Server:
    """`facelib serve` on 127.0.0.1, a free port, in a thread with its own event loop."""

    def __enter__(self) -> "_Server":
        from facelib.live.server import ServerOptions, start_server

        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.server = asyncio.run_coroutine_threadsafe(
            start_server(ServerOptions(port=0)), self.loop).result(timeout=60)
        self.port = self.server.sockets[0].getsockname()[1]
        return self

    def __exit__(self, *exc: object) -> None:
        async def close() -> None:
            self.server.close()
            await self.server.wait_closed()

        asyncio.run_coroutine_threadsafe(close(), self.loop).result(timeout=60)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=60)
        self.loop.close()


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    if CHROMIUM is None or not (WEB_DIR / "node_modules" / "puppeteer-core").exists():
        pytest.skip("needs chromium and the npm packages (make setup)")
    pytest.importorskip("websockets")
    from facelib.animation import run_fdl

    root = tmp_path_factory.mktemp("live")
    export_html(run_fdl(LIVE / "rest.fdl"), root / "head", targets="arkit")
    shutil.copyfile(LIVE / "index.html", root / "index.html")
    (root / "out").mkdir()
    with _Server() as server:
        job = {"server": f"ws://127.0.0.1:{server.port}", "line": LINE, "bg": "00ff00",
               "size": "320x240", "open": 0.25, "drop": 0.15, "timeout_ms": 90000,
               "chromium": CHROMIUM}
        (root / "job.json").write_text(json.dumps(job))
        run = subprocess.run(["node", str(WEB_DIR / "tools" / "live_shoot.mjs"),
                              str(root / "index.html"), str(root / "out"),
                              str(root / "job.json")],
                             capture_output=True, text=True, timeout=300, check=False)
    assert run.returncode == 0, run.stderr[-3000:]
    return root / "out", json.loads(run.stdout.strip().splitlines()[-1])


def test_the_page_speaks_the_typed_line(live):
    _, summary = live
    assert summary["errors"] == []
    first, second = summary["captures"]
    for state in (first, second):
        assert state["audible"] and state["audioState"] == "running"
        assert state["errors"] == []
    # later frames on a clock that moved on, while the sound played
    assert second["shown"]["i"] > first["shown"]["i"]
    assert second["audioTime"] > first["audioTime"]
    assert abs(second["shown"]["jawOpen"] - first["shown"]["jawOpen"]) >= 0.15


def test_the_mouth_moves_between_the_captures(live):
    out, _ = live
    a, b = _png(out / "live_0.png"), _png(out / "live_1.png")
    lips = _lips(a) | _lips(b)
    assert lips.sum() >= 20, "no lips found in the captures"
    ys, xs = np.nonzero(lips)
    box = (slice(max(ys.min() - 3, 0), ys.max() + 4), slice(max(xs.min() - 3, 0), xs.max() + 4))
    changed = np.abs(a - b).max(-1) > 30
    print(f"mouth box {box}: {changed[box].sum()} of {changed.sum()} changed pixels")
    assert changed[box].sum() >= 30
    assert np.abs(a[box] - b[box]).mean() > 8
    # the mouth is on the head: above the middle of the picture, near its centre line
    assert ys.mean() < a.shape[0] / 2 and abs(xs.mean() - a.shape[1] / 2) < a.shape[1] / 8
