"""Paths a storyboard or a caller names: inputs stay inside the storyboard's folder and are
decoded by facelib, never handed to ffmpeg's demuxers; outputs never replace the
storyboard, its inputs, hidden files, devices or links; interrupted writes leave nothing."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile

from facelib import fdl
from facelib.atomic import atomic_path, write_text_atomic
from facelib.errors import FdlError, FileError, ParameterError
from facelib.mpeg4 import FapStream, write_fap


@pytest.mark.parametrize(("output", "message"), [
    ("story.fdl", "must end in one of"),
    (".bashrc", "must end in one of"),
    (".hidden.fap", "hidden file"),
    ("speech.mp4", "inputs"),
])
def test_storyboard_outputs_are_restricted(tmp_path, output, message):
    (tmp_path / "speech.mp4").write_bytes(b"")
    story = tmp_path / "story.fdl"
    story.write_text(f'output = "{output}"\nsay {{ audio = "speech.mp4" }}\n')
    with pytest.raises(FdlError, match=message) as info:
        fdl.load(story)
    assert info.value.line == 1


def test_playlist_audio_never_reaches_ffmpeg(tmp_path):
    """An .m3u8 named as speech must not make ffmpeg read a file outside the folder."""
    pytest.importorskip("pyrender")
    from facelib.rendering.video import open_writer

    secret = tmp_path / "secret"
    secret.mkdir()
    soundfile.write(secret / "memo.wav", np.zeros(8000, np.float32), 8000)
    story = tmp_path / "story"
    story.mkdir()
    (story / "x.m3u8").write_text("#EXTM3U\n#EXTINF:1,\n../secret/memo.wav\n")
    with pytest.raises(ParameterError, match="cannot be decoded"):
        open_writer(story / "out.mp4", fps=25, width=64, height=64, audio=story / "x.m3u8")
    assert sorted(p.name for p in story.iterdir()) == ["x.m3u8"]


@pytest.mark.parametrize("kind", ["device", "symlink", "folder", "empty"])
def test_outputs_never_replace_special_files(tmp_path, kind):
    stream = FapStream.zeros(2, fps=25)
    if kind == "device":
        target = "/dev/null"
    elif kind == "symlink":
        real = tmp_path / "real.fap"
        real.write_text("keep")
        target = tmp_path / "link.fap"
        target.symlink_to(real)
    elif kind == "folder":
        target = tmp_path / "out.fap"
        target.mkdir()
    else:
        target = ""
    with pytest.raises(FileError, match=r"will not replace|empty"):
        write_fap(stream, target)
    assert Path("/dev/null").exists() and not Path("/dev/null").is_file()
    if kind == "symlink":
        assert (tmp_path / "link.fap").is_symlink()
        assert (tmp_path / "real.fap").read_text() == "keep"


def test_unwritable_folder_is_a_file_error(tmp_path):
    if os.geteuid() == 0:
        target = "/proc/facelib/out.fap"  # cannot be created even by root
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "out.fap"
    with pytest.raises(FileError, match="cannot write"):
        write_text_atomic(target, "x")


def test_interrupted_write_leaves_no_temporary(tmp_path):
    def interrupted() -> None:
        with atomic_path(tmp_path / "out.mp4") as temp:
            temp.write_bytes(b"partial")
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        interrupted()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # starts and kills processes
def test_temporaries_of_killed_processes_are_swept(tmp_path):
    """A process killed with SIGKILL cannot clean up; the next write to the folder does."""
    code = ("import os, sys\nfrom facelib.atomic import atomic_path\n"
            f"with atomic_path({str(tmp_path / 'out.fap')!r}) as t:\n"
            "    t.write_text('half'); os.kill(os.getpid(), 9)\n")
    subprocess.run([sys.executable, "-c", code], check=False)
    left = [p.name for p in tmp_path.iterdir()]
    assert len(left) == 1 and left[0].startswith(".out.")
    write_text_atomic(tmp_path / "other.fap", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.fap"]
