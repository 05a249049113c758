"""Issue 38, class 12: inputs that crashed with a traceback or an empty message now give
one line naming the file (and line) and the value."""

from __future__ import annotations

import importlib.util
import re
import struct
from pathlib import Path

import numpy as np
import pytest

from facelib import fdl
from facelib.atomic import output_folder
from facelib.cli import main
from facelib.engine.setup.headmesh import head_mesh, load_head_mesh
from facelib.errors import FaceModelError, FdlError, FileError

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"


@pytest.mark.parametrize(("value", "message"), [
    ('params = "ab"', r"params must be a table of parameter = value, got 'ab'"),
    ("args = {1, 2}", r"args must be a list of argument tables"),
    ("blink_scale = 1e300", r"blink_scale must be a number in \[0, 100\], got 1e\+300"),
    ("interval_scale = 1e300", r"interval_scale must be a number in \[0, 100\]"),
    ("gaze_offset_deg = {1e300, 0}", r"gaze_offset_deg must be \[left, up\] degrees"),
    ("direction_percent = {1e300, 1, 1, 1, 1, 1, 1, 1}", r"direction_percent must be 8"),
    ("base = 3", r"base must be a text, got 3"),
])
def test_define_gaze_values_are_checked(tmp_path, capsys, value, message):
    story = tmp_path / "g.fdl"
    story.write_text(f'define_gaze {{ "mine", {value} }}\nlook {{ "mine", at = 0, dur = 1 }}\n')
    assert main(["run", str(story), "-o", str(tmp_path / "g.fap")]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"{story}:1: eye behaviour 'mine': " in err
    assert re.search(message, err), err


@pytest.mark.parametrize(("script", "hint"), [
    ('show { "joyy" }', "'joyy' is not a known expression; did you mean 'joy'?"),
    ('look { "defualt" }', "'defualt' is not a known eye behaviour; did you mean 'default'?"),
])
def test_a_misspelt_name_is_hinted_even_when_dur_is_missing(tmp_path, capsys, script, hint):
    story = tmp_path / "j.fdl"
    story.write_text(script + "\n")
    assert main(["check", str(story)]) == 1
    err = capsys.readouterr().err
    assert "needs dur" in err and hint in err
    with pytest.raises(FdlError, match=r"needs dur = \.\.\.$"):
        fdl.loads('show { "joy" }\n', name="ok.fdl")


def _cube(scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float) * scale
    t = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, t


def test_a_vertex_at_1e308_is_refused_before_set_up():
    v, t = _cube()
    v[3] = [1e308, 0, 0]
    with pytest.raises(FaceModelError, match=r"vertex 3 is at \[1e\+308, 0.0, 0.0\], beyond"):
        head_mesh(v, t, name="head.obj")


def test_html_into_a_file_is_a_file_error(tmp_path, capsys):
    target = tmp_path / "afile"
    target.write_text("keep")
    with pytest.raises(FileError, match="afile: exists and is not a folder"):
        output_folder(target)
    with pytest.raises(FileError, match="cannot write"):
        output_folder(target / "sub")
    if (ROOT / "facelib/export/web/dist/player.js").is_file():
        assert main(["export", str(SMALL), "--html", str(target)]) == 1
        err = capsys.readouterr().err
        assert "is not a folder" in err and "Traceback" not in err
    assert target.read_text() == "keep"


def _glb(json_text: bytes) -> bytes:
    json_text += b" " * (-len(json_text) % 4)
    body = struct.pack("<II", len(json_text), 0x4E4F534A) + json_text
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


@pytest.mark.skipif(importlib.util.find_spec("trimesh") is None, reason="needs trimesh")
@pytest.mark.parametrize("content", [
    _glb(b'{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{}]}], "nodes": '
         b'[{"mesh": 0}], "scenes": [{"nodes": [0]}], "accessors": []}'),
    _glb(b"[]"),
])
def test_broken_glbs_say_what_is_wrong(tmp_path, content):
    path = tmp_path / "broken.glb"
    path.write_bytes(content)
    with pytest.raises(FaceModelError) as info:
        load_head_mesh(path)
    message = str(info.value)
    assert message.startswith(f"{path}: cannot read the mesh: the GLB file is malformed")
    assert message.rstrip().endswith(")") and "()" not in message
