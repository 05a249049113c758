"""Written outputs: MP4 frame count, duration and audio; GIF; PNG folders; atomicity."""

from __future__ import annotations

import io
import os
import stat
from pathlib import Path

import numpy as np
import pytest
import soundfile
from PIL import Image

from facelib.errors import ParameterError, RenderError
from facelib.rendering.frames import render
from facelib.rendering.video import encode_png, open_writer, probe_video, save_png

pytestmark = pytest.mark.render

W, H = 96, 72


@pytest.fixture
def jaw_stream(fap_stream):
    """``jaw_stream(n, fps)``: the jaw opens and closes once over ``n`` frames."""
    return lambda n, fps=25: fap_stream(n, fps=fps, open_jaw=700 * np.sin(np.linspace(0, np.pi, n)))


def _tone(path: Path, seconds: float, rate: int = 16000) -> Path:
    t = np.arange(int(seconds * rate)) / rate
    soundfile.write(path, 0.3 * np.sin(2 * np.pi * 220 * t), rate)
    return path


def test_mp4_has_frame_count_duration_and_audio(tmp_path, synthetic_face, jaw_stream):
    stream = jaw_stream(30)  # 1.2 s
    speech = _tone(tmp_path / "speech.wav", 1.5)
    out = render(stream, face=synthetic_face, out=tmp_path / "a.mp4", width=W, height=H,
                 audio=speech, progress=False)
    assert out == tmp_path / "a.mp4"
    info = probe_video(out)
    assert info["frames"] == 30
    assert info["duration"] == pytest.approx(1.2, abs=0.05)
    assert info["audio"] is True
    silent = render(stream, face=synthetic_face, out=tmp_path / "b.mp4", width=W, height=H,
                    progress=False)
    assert probe_video(silent) == {"frames": 30, "duration": pytest.approx(1.2, abs=0.05),
                                   "audio": False}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mp4", "b.mp4", "speech.wav"]


def test_animation_source_brings_its_audio(tmp_path, synthetic_face, jaw_stream):
    class Animation:
        faps = jaw_stream(10, fps=20)
        audio = _tone(tmp_path / "s.wav", 0.5)
        audio_offset = 0.1

    out = render(Animation(), face=synthetic_face, out=tmp_path / "anim.mp4", width=W,
                 height=H, progress=False)
    info = probe_video(out)
    assert info["frames"] == 10 and info["audio"] is True


def test_png_folder_holds_the_same_frames(tmp_path, synthetic_face, jaw_stream):
    stream = jaw_stream(4)
    frames = render(stream, face=synthetic_face, width=W, height=H, progress=False)
    folder = render(stream, face=synthetic_face, out=tmp_path / "frames", width=W, height=H,
                    progress=False)
    names = sorted(p.name for p in folder.iterdir())
    assert names == [f"frame_{i:06d}.png" for i in range(4)]
    for i, name in enumerate(names):
        assert np.array_equal(np.asarray(Image.open(folder / name)), frames[i])
    # rewriting the folder replaces its frames, leaving no temporaries beside it
    render(jaw_stream(2), face=synthetic_face, out=folder, width=W, height=H, progress=False)
    assert len(list(folder.iterdir())) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frames"]


def test_gif_and_single_png(tmp_path, synthetic_face, jaw_stream):
    gif = render(jaw_stream(5), face=synthetic_face, out=tmp_path / "a.gif", width=W, height=H,
                 progress=False)
    with Image.open(gif) as image:
        assert image.n_frames == 5 and image.size == (W, H)
    still = render(jaw_stream(1), face=synthetic_face, out=tmp_path / "one.png", width=W,
                   height=H, progress=False)
    assert np.asarray(Image.open(still)).shape == (H, W, 3)
    with pytest.raises(ParameterError, match="one PNG"):
        render(jaw_stream(3), face=synthetic_face, out=tmp_path / "x.png", width=W, height=H)


def test_encode_png_round_trips(rng):
    for shape in ((5, 7, 3), (3, 2, 4)):
        image = rng.integers(0, 256, shape, dtype=np.uint8)
        assert np.array_equal(np.asarray(Image.open(io.BytesIO(encode_png(image)))), image)
    with pytest.raises(ParameterError, match="uint8"):
        encode_png(np.zeros((4, 4, 3), np.float32))


def test_failed_render_leaves_no_output(tmp_path, synthetic_face, jaw_stream):
    class Broken:
        def __init__(self, face):
            self.__dict__.update({k: getattr(face, k) for k in
                                  ("vertices", "triangles", "vertex_colors", "parts")})

        def deform(self, stream):
            raise RuntimeError("deformer exploded")

    target = tmp_path / "clip.mp4"
    with pytest.raises(RuntimeError, match="exploded"):
        render(jaw_stream(3), face=Broken(synthetic_face), out=target, width=W, height=H,
               progress=False)
    assert list(tmp_path.iterdir()) == []
    save_png(np.zeros((4, 4, 3), np.uint8), tmp_path / "keep.png")
    assert [p.name for p in tmp_path.iterdir()] == ["keep.png"]


def test_writer_rejects_bad_requests(tmp_path):
    with pytest.raises(ParameterError, match="even"):
        open_writer(tmp_path / "a.mp4", fps=25, width=95, height=72)
    with pytest.raises(ParameterError, match=r"\.avi"):
        open_writer(tmp_path / "a.avi", fps=25, width=96, height=72)
    with pytest.raises(ParameterError, match="does not exist"):
        open_writer(tmp_path / "a.mp4", fps=25, width=96, height=72,
                    audio=tmp_path / "missing.wav")
    writer = open_writer(tmp_path / "b.mp4", fps=25, width=96, height=72)
    with pytest.raises(ParameterError, match="96x72"):
        writer.write(np.zeros((10, 10, 3), np.uint8))
    writer.abort()
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    with pytest.raises(RenderError, match=r"notes\.txt"):
        open_writer(tmp_path / "busy", fps=25, width=96, height=72)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["busy"]


def test_outputs_get_ordinary_permissions(tmp_path, synthetic_face, jaw_stream):
    old = os.umask(0o022)
    try:
        png = save_png(np.zeros((4, 4, 3), np.uint8), tmp_path / "a.png")
        folder = render(jaw_stream(1), face=synthetic_face, out=tmp_path / "f", width=W, height=H,
                        progress=False)
        gif = render(jaw_stream(2), face=synthetic_face, out=tmp_path / "g.gif", width=W,
                     height=H, progress=False)
    finally:
        os.umask(old)
    assert stat.S_IMODE(png.stat().st_mode) == 0o644
    assert stat.S_IMODE(gif.stat().st_mode) == 0o644
    assert stat.S_IMODE(folder.stat().st_mode) == 0o755


@pytest.mark.speech
def test_text_only_storyboard_renders_with_synthesized_speech(tmp_path, synthetic_face):
    from facelib import run_fdl

    story = tmp_path / "de.fdl"
    story.write_text('language = "de"\nsay "Mama backt Brot."\n', encoding="utf-8")
    anim = run_fdl(story)
    out = render(anim, face=synthetic_face, out=tmp_path / "de.mp4", width=W, height=H,
                 progress=False)
    info = probe_video(out)
    assert info["audio"]
    assert info["frames"] == anim.faps.n_frames
    speech = anim.speech_audio
    # the video runs on through the mouth's 150 ms release ramp after the speech
    assert abs(info["duration"] - speech.samples.size / speech.sample_rate - 0.15) < 0.1
