"""`facelib check` rejects, with file and line, everything `run` rejects (newcomer items 1-2)."""

from __future__ import annotations

from pathlib import Path

import pytest

from facelib.cli import main

BAD = [
    ('show { "happy", at = 0, dur = 1 }', 2, "unknown expression 'happy'"),
    ('look { "lookAt", dur = 1 }', 2, "unknown eye behaviour 'lookAt'"),
    ('look { "lookTo", "left", 15.0, "yes", 3, 4, dur = 1 }', 2, "lookTo takes at most 3"),
    ('look { "lookTo", "sideways", 15.0, "yes", dur = 1 }', 2, "unknown direction 'sideways'"),
    ('define_gaze { "nervous", blink_rate = 0.6 }\nlook { "nervous", dur = 3 }',
     2, "eye behaviour 'nervous': unknown key"),
]


@pytest.mark.parametrize(("body", "line", "message"), BAD, ids=[b[2] for b in BAD])
def test_check_rejects_first_what_run_rejects(tmp_path, capsys, body, line, message):
    story = tmp_path / "story.fdl"
    story.write_text(f"fps = 25\n{body}\n")
    assert main(["check", str(story)]) == 1
    check_err = capsys.readouterr().err
    assert main(["run", str(story), "-o", str(tmp_path / "x.fap")]) == 1
    run_err = capsys.readouterr().err
    assert f"{story}:{line}: " in check_err and message in check_err
    assert check_err == run_err  # the same validation, the same message
    assert not (tmp_path / "x.fap").exists()


def test_check_passes_a_good_storyboard_with_its_length(tmp_path, capsys):
    story = tmp_path / "good.fdl"
    story.write_text('fps = 25\nshow { "joy", at = 0, dur = 1 }\n'
                     'define_gaze { "nervous", base = "discomfort", blink_scale = 3.0 }\n'
                     'look { "nervous", dur = 2 }\n')
    assert main(["check", str(story)]) == 0
    captured = capsys.readouterr()
    assert "joy" in captured.out and "nervous" in captured.out
    assert "ok: 51 frames at 25 fps (2.04 s)" in captured.err
    assert f"without -o writes {Path.cwd() / 'good.fap'}" in captured.err
