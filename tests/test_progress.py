"""Progress: a bar on a terminal, a line per 10 % otherwise, callbacks in the APIs."""

from __future__ import annotations

import importlib.util
import io
import warnings
from pathlib import Path

import numpy as np
import pytest

import facelib
from facelib.errors import ParameterError
from facelib.progress import ConsoleProgress, progress_callback

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "data" / "pipeline" / "small.fdl"


def test_lines_every_tenth_when_not_a_terminal():
    out = io.StringIO()
    report = ConsoleProgress("rendering", stream=out)
    for done in range(1, 121):
        report(done, 120)
    lines = out.getvalue().splitlines()
    assert [line.split(":")[1].split("%")[0].strip() for line in lines] == [
        str(p) for p in range(0, 101, 10)]  # 0 %: the job has started
    assert lines[4].startswith("rendering: 40% (48/120 frames, ")


def test_a_bar_redrawn_in_place_on_a_terminal():
    out = io.StringIO()
    report = ConsoleProgress("batch", unit="files", stream=out, tty=True)
    for done in range(1, 4):
        report(done, 3)
    text = out.getvalue()
    assert "\n" not in text and text.count("\r") >= 2
    assert "[##########--------------------] 1/3 files" in text
    assert text.endswith("\r")  # erased at the end


def test_progress_argument():
    assert progress_callback(None, "x") is None and progress_callback(False, "x") is None
    assert isinstance(progress_callback(True, "x"), ConsoleProgress)
    seen = []
    assert progress_callback(lambda d, t: seen.append(d), "x") is not None
    with pytest.raises(ParameterError, match="progress must be"):
        progress_callback("yes", "x")  # type: ignore[arg-type]


def test_run_fdl_reports_its_four_stages():
    calls: list[tuple[int, int]] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        facelib.run_fdl(SMALL, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]


@pytest.mark.render
@pytest.mark.skipif(importlib.util.find_spec("pyrender") is None, reason="render extra")
def test_render_calls_back_once_per_frame():
    stream = facelib.FapStream(25, np.zeros((7, 84), np.float32))
    calls: list[tuple[int, int]] = []
    facelib.render(stream, width=64, height=48, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(i, 7) for i in range(1, 8)]
