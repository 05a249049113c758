"""Batch rendering on a process pool: outputs per source, one failure does not stop the rest."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import pytest

from facelib.batch import plan_jobs, render_batch
from facelib.cli import main
from facelib.errors import ParameterError

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"
SMILE = ROOT / "examples" / "fap" / "xface_smile.fap"

pytestmark = [pytest.mark.render, pytest.mark.skipif(
    importlib.util.find_spec("pyrender") is None, reason="needs the render extra")]


def test_plan_refuses_two_sources_writing_one_file(tmp_path):
    (tmp_path / "a").mkdir()
    twin = tmp_path / "a" / "small.fdl"
    twin.write_text(SMALL.read_text())
    with pytest.raises(ParameterError, match=r"would both write small\.mp4"):
        plan_jobs([SMALL, twin], tmp_path / "out")
    jobs = plan_jobs([SMALL, SMILE], tmp_path / "out", suffix=".gif")
    assert [Path(j.output).name for j in jobs] == ["small.gif", "xface_smile.gif"]


def test_a_batch_reports_the_failure_and_finishes_the_rest(tmp_path, capsys):
    bad = tmp_path / "bad.fdl"
    bad.write_text('fps = 25\nshow { "happy", at = 0, dur = 1 }\n')
    tiny = tmp_path / "small.fdl"
    tiny.write_text('fps = 25\nshow { "joy", at = 0, dur = 0.3 }\n')
    calls = []
    results = render_batch([tiny, bad, SMILE], tmp_path / "out", jobs=2, suffix=".gif",
                           width=64, height=48, progress=lambda d, t: calls.append((d, t)))
    assert [r.ok for r in results] == [True, False, True]
    assert f"{bad}:2: unknown expression 'happy'" in results[1].error
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["small.gif",
                                                                    "xface_smile.gif"]
    assert all(r.output.read_bytes()[:6] == b"GIF89a" for r in results if r.ok)
    assert calls == [(1, 3), (2, 3), (3, 3)]


def test_the_cli_batch_exits_1_when_one_fails(tmp_path, capsys):
    bad = tmp_path / "bad.fdl"
    bad.write_text('fps = 25\nlook { "lookAt", dur = 1 }\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        status = main(["render", str(SMILE), str(bad), "-o", str(tmp_path / "out"), "-j", "2",
                       "--width", "64", "--height", "48"])
    assert status == 1
    err = capsys.readouterr().err
    assert "unknown eye behaviour 'lookAt'" in err and "1 of 2 failed" in err
    assert (tmp_path / "out" / "xface_smile.mp4").stat().st_size > 1000
