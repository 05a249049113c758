"""Speech audio copied beside a ``.glb`` or into a web player gets a name facelib chooses: the
export's own stem and the suffix of the format its first bytes show, never the suffix the
caller's file had (a WAV named ``voice.html`` with a script appended must not become a page
beside ``index.html``); a file that is no audio format is refused."""

import io
from pathlib import Path

import numpy as np
import pytest
import soundfile
from gltf_eval import busy_stream

from facelib.errors import ParameterError
from facelib.export import export_gltf
from facelib.export.web import WEB_DIR, export_html

pytest.importorskip("pygltflib")
HELLO = Path(__file__).parents[2] / "examples" / "hello" / "hello.flac"
SCRIPT = b"<html><script>alert(document.domain)</script></html>"


def _wav() -> bytes:
    out = io.BytesIO()
    soundfile.write(out, np.zeros(800, np.float32), 8000, format="WAV")
    return out.getvalue()


@pytest.mark.parametrize(("name", "content", "suffix"), [
    ("voice.html", _wav() + SCRIPT, ".wav"),
    ("voice.svg", _wav() + b"<svg onload='alert(1)'/>", ".wav"),
    ("voice", HELLO.read_bytes(), ".flac"),
    ("voice.WAV", HELLO.read_bytes(), ".flac"),
])
def test_the_copy_is_named_by_its_content(tmp_path, name, content, suffix):
    audio = tmp_path / "in" / name
    audio.parent.mkdir()
    audio.write_bytes(content)
    out = tmp_path / "out"
    out.mkdir()
    result = export_gltf(busy_stream(), out / "a.glb", audio=audio)
    assert result.audio == out / f"a{suffix}"
    assert result.audio.read_bytes() == content
    assert sorted(p.name for p in out.iterdir()) == sorted(["a.glb", f"a{suffix}"])


@pytest.mark.parametrize("content", [SCRIPT, b"", b"RIFF\0\0\0\0AVI LIST", b"\0" * 64])
def test_a_file_that_is_not_audio_is_refused(tmp_path, content):
    audio = tmp_path / "voice.wav"
    audio.write_bytes(content)
    with pytest.raises(ParameterError, match="not an audio file") as info:
        export_gltf(busy_stream(), tmp_path / "a.glb", audio=audio)
    assert "voice.wav" in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["voice.wav"]


def test_the_web_player_gets_face_wav_not_face_html(tmp_path):
    if not (WEB_DIR / "dist" / "player.js").is_file():
        pytest.skip("the web player is not built (make setup)")
    audio = tmp_path / "voice.html"
    audio.write_bytes(_wav() + SCRIPT)
    page = export_html(busy_stream(), tmp_path / "web", audio=audio)
    names = sorted(p.name for p in (tmp_path / "web").iterdir())
    assert names == ["face.glb", "face.wav", "index.html", "player.js", "scene.js"]
    assert page.audio == tmp_path / "web" / "face.wav"
    assert '"audio":"face.wav"' in (tmp_path / "web" / "scene.js").read_text()
