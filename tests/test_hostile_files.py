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
    assert len(left) == 1 and left[0].startswith(".facelib-tmp-")
    write_text_atomic(tmp_path / "other.fap", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.fap"]


def _dead_pid() -> int:
    child = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True, check=True)
    return int(child.stdout)


def test_the_sweep_never_touches_a_users_files(tmp_path):
    """Hidden files shaped like the old temporaries (``.name.<digits>.<8 chars>[.ext]``) are a
    user's own; only names facelib made, with the check it wrote into them, are swept."""
    dead = _dead_pid()
    users = [".photo.2019.holidays.jpg", f".notes.{dead}.abcdefgh", f".x.{dead}.ABCD_123.txt",
             f".facelib-tmp-{dead}-000000000000-00000000.fap",  # the shape, not the check
             f".out.{dead}.k3j4h5g6.fap"]
    for name in users:
        (tmp_path / name).write_text("keep")
    write_text_atomic(tmp_path / "out.fap", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*users, "out.fap"])
    assert all((tmp_path / name).read_text() == "keep" for name in users)


def test_a_huge_number_in_a_hidden_name_does_not_break_writes(tmp_path):
    names = [".a.99999999999999999999999999.abcdefgh", ".b.18446744073709551616.abcdefgh.fap"]
    for name in names:
        (tmp_path / name).write_text("keep")
    write_text_atomic(tmp_path / "out.fap", "x")
    assert (tmp_path / "out.fap").read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*names, "out.fap"])


def test_a_storyboards_output_lands_in_its_own_folder(tmp_path, monkeypatch, capsys):
    """``output = "keep.fap"`` run from another folder must not overwrite that folder's
    ``keep.fap``: it names a file beside the storyboard, as for every other file it names."""
    from facelib.cli import main

    stories = tmp_path / "stories"
    stories.mkdir()
    story = stories / "story.fdl"
    story.write_text('fps = 25\noutput = "keep.fap"\nshow { "joy", at = 0, dur = 0.2 }\n')
    here = tmp_path / "here"
    here.mkdir()
    (here / "keep.fap").write_text("the caller's own file")
    monkeypatch.chdir(here)
    assert main(["run", str(story)]) == 0
    assert (here / "keep.fap").read_text() == "the caller's own file"
    assert sorted(p.name for p in here.iterdir()) == ["keep.fap"]
    assert (stories / "keep.fap").read_text().startswith("2.1")
    assert str(stories / "keep.fap") in capsys.readouterr().err


def test_a_storyboard_cannot_make_folders(tmp_path, monkeypatch, capsys):
    from facelib.cli import main

    story = tmp_path / "story.fdl"
    story.write_text('fps = 25\noutput = "deep/er/new.fap"\nshow { "joy", at = 0, dur = 0.2 }\n')
    with pytest.raises(FdlError, match=r"folder 'deep/er' does not exist") as info:
        fdl.load(story)
    assert info.value.line == 2
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(story)]) == 1
    assert "deep/er" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["story.fdl"]
    (tmp_path / "deep" / "er").mkdir(parents=True)  # a folder that is there may be named
    assert fdl.load(story).output == tmp_path / "deep" / "er" / "new.fap"
