"""The storyboard commands: check, run, render, plot, play, align."""

import importlib.util
from pathlib import Path

import pytest

from facelib import read_fap
from facelib.cli import main

ROOT = Path(__file__).parents[2]
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"


def test_check_lists_cues_with_lines(capsys):
    assert main(["check", str(SMALL)]) == 0
    out = capsys.readouterr().out
    assert "joy" in out and "lookTo" in out and "small.fdl:6" in out


def test_check_reports_script_errors_with_file_and_line(tmp_path, capsys):
    bad = tmp_path / "bad.fdl"
    bad.write_text('fps = 25\nshow { "joy", at = 0 }\n')
    assert main(["check", str(bad)]) == 1
    err = capsys.readouterr().err
    assert f"{bad}:2" in err and "Traceback" not in err


def test_run_writes_the_fap_and_defaults_to_the_current_directory(tmp_path, monkeypatch):
    out = tmp_path / "small.fap"
    assert main(["run", str(SMALL), "-o", str(out)]) == 0
    assert read_fap(out, strict=True).n_frames > 25
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    assert main(["run", str(SMALL)]) == 0  # no output named: STEM.fap in the current folder
    assert read_fap(here / "small.fap") == read_fap(out)
    assert not (SMALL.parent / "small.fap").exists()


def test_seed_option_changes_the_eyes(tmp_path):
    a, b = tmp_path / "a.fap", tmp_path / "b.fap"
    main(["run", str(SMALL), "-o", str(a), "--seed", "1"])
    main(["run", str(SMALL), "-o", str(b), "--seed", "2"])
    assert read_fap(a) != read_fap(b)


def test_plot_writes_a_png(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "curves.png"
    assert main(["plot", str(SMALL), "-o", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.render  # renders video
def test_render_and_play(tmp_path):
    if importlib.util.find_spec("pyrender") is None:  # importing it would pick a GL platform
        pytest.skip("rendering needs the render extra")
    gif = tmp_path / "small.gif"
    fap = tmp_path / "small.fap"
    assert main(["render", str(SMALL), "-o", str(gif), "--fap", str(fap), "--width", "160",
                 "--height", "120"]) == 0
    assert gif.stat().st_size > 1000 and fap.exists()
    frames = tmp_path / "frames"
    assert main(["play", str(ROOT / "examples" / "fap" / "xface_smile.fap"), "-o",
                 str(frames), "--width", "96", "--height", "72", "--fps", "5"]) == 0
    assert len(list(frames.glob("*.png"))) == 10


def test_align_writes_a_viseme_script(tmp_path):
    pytest.importorskip("pocketsphinx")
    audio = ROOT / "examples" / "hastalavista" / "hastalavista.wav"
    out = tmp_path / "sentence.sb"
    assert main(["align", str(audio), "--text", "Hasta la vista, baby.", "-o", str(out)]) == 0
    text = out.read_text()
    assert "Sentence = {" in text and '"A"' in text
