"""Unix conventions of the `facelib` command: stdout, suffixes, pipes, signals, verbosity."""

from __future__ import annotations

import importlib.util
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from facelib import read_fap
from facelib.cli import main

ROOT = Path(__file__).resolve().parents[2]
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"
HAS_RENDER = importlib.util.find_spec("pyrender") is not None


def facelib_cmd(*args: str, **kwargs) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "facelib.cli", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kwargs)


def long_storyboard(folder: Path, seconds: int) -> Path:
    story = folder / "long.fdl"
    story.write_text(f'fps = 25\nshow {{ "joy", at = 0, dur = {seconds} }}\n'
                     f'look {{ "default", "talking", 0.9, dur = {seconds} }}\n')
    return story


def test_dash_writes_the_fap_to_stdout(tmp_path, capsys):
    out = tmp_path / "small.fap"
    assert main(["run", str(SMALL), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["run", str(SMALL), "-o", "-"]) == 0
    captured = capsys.readouterr()
    assert captured.out == out.read_text()
    assert not Path("-").exists()


def test_output_suffix_must_match_the_format(tmp_path, capsys):
    out = tmp_path / "x.json"
    assert main(["run", str(SMALL), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "run writes .fap, not 'x.json'" in err and "'x.fap'" in err
    assert not out.exists()
    assert main(["render", str(SMALL), "-o", str(tmp_path / "x.avi")]) == 2
    assert "render writes .mp4 or .gif or .png" in capsys.readouterr().err
    assert main(["plot", str(SMALL), "-o", str(tmp_path / "x.fap")]) == 2


def test_storyboard_output_is_honoured_inside_the_storyboards_folder(
        tmp_path, monkeypatch, capsys):
    story = tmp_path / "stories" / "named.fdl"
    story.parent.mkdir()
    story.write_text('fps = 25\noutput = "named_out.fap"\nshow { "joy", at = 0, dur = 0.4 }\n')
    here = tmp_path / "work"
    here.mkdir()
    monkeypatch.chdir(here)
    assert main(["run", str(story)]) == 0
    assert (story.parent / "named_out.fap").is_file()
    assert not (here / "named_out.fap").exists()
    assert "wrote" in capsys.readouterr().err  # status to stderr, stdout stays clean


def test_quiet_prints_nothing_and_verbose_explains(tmp_path, capsys):
    assert main(["run", str(SMALL), "-o", str(tmp_path / "a.fap"), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""
    bad = tmp_path / "bad.fdl"
    bad.write_text('fps = 25\nshow { "happy", at = 0, dur = 1 }\n')
    assert main(["-v", "check", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and f"{bad}:2: unknown expression 'happy'" in err
    assert main(["check", str(bad)]) == 1
    assert "Traceback" not in capsys.readouterr().err


@pytest.mark.slow  # four fresh processes
def test_a_closed_pipe_ends_quietly(tmp_path):
    """`facelib ... | head` where head has already gone: the write fails with EPIPE."""
    story = long_storyboard(tmp_path, 30)  # ~200 kB of .fap text
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "facelib.cli", "run", str(story), "-o", "-"],
                            env=env, stdout=write_end, stderr=subprocess.PIPE)
    os.close(write_end)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141
    assert err == ""
    for command in (["info", str(ROOT / "tests" / "data" / "fap" / "xface.fap")],
                    ["list", "expressions"]):
        read_end, write_end = os.pipe()
        os.close(read_end)
        proc = subprocess.Popen([sys.executable, "-m", "facelib.cli", *command], env=env,
                                stdout=write_end, stderr=subprocess.PIPE)
        os.close(write_end)
        assert proc.stderr.read() == b""
        assert proc.wait(timeout=60) == 141


@pytest.mark.render
@pytest.mark.skipif(not HAS_RENDER, reason="needs the render extra")
@pytest.mark.parametrize(("sig", "status", "word"), [(signal.SIGTERM, 143, "terminated"),
                                                     (signal.SIGINT, 130, "interrupted")])
def test_signals_exit_with_one_line_and_no_temporary_files(tmp_path, sig, status, word):
    story = long_storyboard(tmp_path, 20)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    proc = facelib_cmd("render", str(story), "-o", str(out_dir / "long.mp4"),
                       "--width", "160", "--height", "120")
    # ready: the first progress line ("rendering: 10% (50/500 frames, ...)") comes once
    # frames are being encoded into the temporary file, 90 % of the render still to go
    before = []
    for line in iter(proc.stderr.readline, b""):
        before.append(line.decode())
        if line.startswith(b"rendering: "):
            break
    else:
        pytest.fail("the render ended before its first progress line: " + "".join(before))
    assert any(out_dir.iterdir()), "rendering, but no temporary file"
    proc.send_signal(sig)
    err = "".join(before) + proc.stderr.read().decode()
    assert proc.wait(timeout=60) == status, err
    assert err.strip().splitlines()[-1] == f"facelib: {word}"
    assert "Traceback" not in err
    assert list(out_dir.iterdir()) == []


def test_a_signal_a_library_turned_into_another_error_still_exits_as_that_signal(capsys):
    # SIGTERM arriving inside pyrender's ctypes call to OSMesa reaches the command as a
    # ctypes.ArgumentError wrapping Terminated, not as Terminated itself
    import argparse
    import ctypes

    from facelib.cli.console import Console
    from facelib.cli.dispatch import dispatch

    def run(args, console):
        console.signals.received = signal.SIGTERM
        raise ctypes.ArgumentError("argument 2: Terminated: ")

    assert dispatch(run, argparse.Namespace(), Console()) == 143
    assert capsys.readouterr().err.strip() == "facelib: terminated"

    def broken(args, console):
        raise ValueError("a bug, with no signal")

    with pytest.raises(ValueError, match="a bug"):
        dispatch(broken, argparse.Namespace(), Console())


def test_exit_codes_are_documented():
    text = (ROOT / "docs" / "getting-started.md").read_text()
    for code in ("130", "141", "143"):
        assert code in text


def test_stdout_of_align_can_be_tsv(tmp_path, capsys):
    pytest.importorskip("pocketsphinx")
    audio = ROOT / "examples" / "hastalavista" / "hastalavista.wav"
    assert main(["align", str(audio), "--text", "Hasta la vista, baby.", "-o", "-",
                 "--format", "tsv"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) > 5 and all(len(line.split("\t")) >= 3 for line in lines[1:])


def test_fap_written_by_stdout_reads_back(tmp_path, capsys):
    assert main(["run", str(SMALL), "-o", "-", "--dialect", "extended"]) == 0
    path = tmp_path / "piped.fap"
    path.write_text(capsys.readouterr().out)
    assert read_fap(path).n_frames > 25
