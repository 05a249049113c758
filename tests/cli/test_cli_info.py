"""The command line: --version and info."""

import subprocess
import sys
from pathlib import Path

import pytest

import facelib
from facelib.cli import main

ROOT = Path(__file__).parents[2]


def test_version(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out.strip() == f"facelib {facelib.__version__}"


def test_info_summarises_the_example(capsys):
    assert main(["info", str(ROOT / "examples" / "fap" / "xface_smile.fap")]) == 0
    out = capsys.readouterr().out
    assert "dialect xface" in out
    assert "frames:    50" in out and "duration:  2.000 s" in out
    assert "open_jaw" in out and "close_t_l_eyelid" in out
    row = next(line for line in out.splitlines() if "close_t_l_eyelid" in line)
    assert row.split()[3:5] == ["0", "1024"]


def test_info_reports_errors_without_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.fap"
    bad.write_text("2.1 name 25\n")
    assert main(["info", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("facelib: error:") and f"{bad}:1" in err
    assert "Traceback" not in err


def test_console_script_entry_point():
    result = subprocess.run(
        [sys.executable, "-m", "facelib.cli", "--version"], capture_output=True, text=True,
        check=False,
    )
    assert result.returncode == 0 and "facelib" in result.stdout
