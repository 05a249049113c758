"""The viewer in a real X server (Xvfb): plays, closes by itself at the end; its controls."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.render

ROOT = Path(__file__).resolve().parents[2]


def test_playback_controls_pause_resume_and_step():
    from facelib.rendering.viewer import Playback

    state = Playback(fps=25.0, n_frames=50)
    state.origin = time.perf_counter() - 0.4  # 0.4 s in: frame 10
    assert state.due() == 10
    state.toggle()  # space: pause
    time.sleep(0.1)
    assert state.paused and state.due() == 10
    state.step(1)
    assert state.due() == 11
    state.step(-20)  # clamped at the first frame
    assert state.due() == 0
    state.step(10)
    state.step(100)
    assert state.due() == 49  # clamped at the last
    state.toggle()  # space again: resume from the frame shown
    assert not state.paused and state.due() in (49, 50)


@pytest.fixture
def xvfb():
    if shutil.which("Xvfb") is None:
        pytest.skip("needs Xvfb (tools/debian-packages.txt)")
    read, write = os.pipe()
    server = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0",
                               "1024x768x24", "+extension", "GLX", "-nolisten", "tcp"],
                              pass_fds=(write,), stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as pipe:
        display = pipe.readline().strip()
    try:
        yield f":{display}"
    finally:
        server.terminate()
        server.wait(timeout=10)


@pytest.mark.render
@pytest.mark.skipif(importlib.util.find_spec("pyglet") is None, reason="render extra")
def test_the_viewer_plays_and_closes_at_the_end(xvfb, tmp_path):
    story = tmp_path / "short.fdl"
    story.write_text('fps = 25\nshow { "joy", at = 0, dur = 0.8 }\n')
    env = {**os.environ, "DISPLAY": xvfb, "PYTHONPATH": str(ROOT)}
    env.pop("PYOPENGL_PLATFORM", None)
    started = time.monotonic()
    result = subprocess.run([sys.executable, "-m", "facelib.cli", "view", str(story)], env=env,
                            capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    assert time.monotonic() - started >= 0.8  # it played in real time, then closed itself


@pytest.mark.render
@pytest.mark.skipif(importlib.util.find_spec("pyglet") is None, reason="render extra")
def test_the_viewer_plays_the_speech_with_the_frames(xvfb):
    code = f"""
import numpy as np
from pathlib import Path
from types import SimpleNamespace
import facelib
from facelib.clip import Clip
from facelib.rendering import viewer
audio = Path({str(ROOT / "examples" / "hello" / "hello.flac")!r})
player = viewer._sound(Clip(facelib.FapStream(25, np.zeros((2, 84), np.float32)), audio=audio))
print("player", type(player).__name__, round(player.source.duration, 2))
clip = SimpleNamespace(faps=facelib.FapStream(25, np.zeros((20, 84), np.float32)),
                       audio=audio, audio_offset=0.2)
viewer.view(clip)
print("closed")
"""
    env = {**os.environ, "DISPLAY": xvfb, "PYTHONPATH": str(ROOT)}
    env.pop("PYOPENGL_PLATFORM", None)
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                            text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    import soundfile

    info = soundfile.info(str(ROOT / "examples" / "hello" / "hello.flac"))
    assert f"player Player {round(info.duration, 2)}" in result.stdout  # decoded, queued
    assert "closed" in result.stdout
