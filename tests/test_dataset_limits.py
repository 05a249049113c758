"""Dataset specs are bounded field by field and every refusal names the field as the spec
file spells it (issue 38, class 8): ``clips = 10^12`` and ``per_clip = [10^9, 10^9]`` ran
for minutes, ``per_clip = [0, 1e300]`` failed every clip with "clip 0: ValueError"."""

from __future__ import annotations

import pytest

from facelib.cli import main
from facelib.dataset import DatasetSpec, load_spec
from facelib.errors import FacelibError, ParameterError


@pytest.mark.parametrize(("toml", "message"), [
    ("clips = 1000000000000", r"clips must be an integer in \[1, 1e\+06\], got 1000000000000"),
    ("clips = 2\n[expressions]\nper_clip = [1000000000, 1000000000]",
     r"expressions.per_clip must be a range .* <= 100, got \[1000000000, 1000000000\]"),
    ("clips = 2\n[expressions]\nper_clip = [0, 1e300]",
     r"expressions.per_clip must be two integers"),
    ("clips = 2\n[expressions]\nper_clip = [0, 1.5]", r"expressions.per_clip must be two int"),
    ("clips = 2\n[expressions]\nintensity = [0, 1e300]", r"expressions.intensity must be a "),
    ("clips = 2\n[head]\nyaw_deg = [-1e300, 0]", r"head.yaw_deg must be a range"),
    ("clips = 2\n[camera]\nzoom = [0, 1]", r"camera.zoom must be a range"),
    ("clips = 2\n[camera]\nshift = [-1e9, 0]", r"camera.shift must be a range"),
    ("clips = 2\nwidth = 1000000000", r"width must be an integer in \[8, 8192\]"),
    ("clips = 2\nfps = 1e300", r"fps must be a finite number in \[1, 1000\]"),
    ("clips = 2\nseed = -1", r"seed must be an integer from 0"),
    ("clips = 2\n[gaze]\nbehaviours = [{x = 1}]", r"gaze.behaviours\[0\] must be a non-empty text"),
    ("clips = 2\n[expressions]\nnames = ['']", r"expressions.names\[0\] must be a non-empty"),
    ("clips = 2\n[speech]\ntexts = ['" + "a" * 100_001 + "']", r"speech.texts\[0\] must be"),
])
def test_hostile_specs_are_refused_naming_the_field(tmp_path, toml, message):
    spec = tmp_path / "spec.toml"
    spec.write_text(toml + "\n")
    with pytest.raises(FacelibError, match=rf"spec.toml: {message}"):
        load_spec(spec)


def test_a_huge_spec_file_is_refused(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text("clips = 2\n" + "# padding\n" * 200_000)
    with pytest.raises(FacelibError, match="at most 1048576 bytes"):
        load_spec(spec)


def test_the_api_checks_the_same_limits():
    with pytest.raises(ParameterError, match="expressions_per_clip must be a range"):
        DatasetSpec(clips=1, expressions_per_clip=(0, 10**9))
    with pytest.raises(ParameterError, match="clips must be an integer"):
        DatasetSpec(clips=10**12)
    assert DatasetSpec(clips=1_000_000, expressions_per_clip=(0, 100)).clips == 1_000_000


def test_the_command_refuses_without_a_traceback(tmp_path, capsys):
    spec = tmp_path / "spec.toml"
    spec.write_text("clips = 2\n[expressions]\nper_clip = [0, 1e300]\n")
    assert main(["dataset", str(spec), "-o", str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err
    assert "expressions.per_clip" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()
