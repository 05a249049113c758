"""The `facelib export` and `facelib import-arkit` commands (thin layers over the API)."""

import csv
from pathlib import Path

import numpy as np
import pytest

from facelib import read_fap
from facelib.cli import main

FAP = Path(__file__).parents[1] / "data" / "fap" / "xface.fap"


@pytest.mark.slow  # every export of a storyboard
def test_export_glb_html_and_arkit_then_import(tmp_path, capsys):
    assert main(["export", str(FAP), "-o", str(tmp_path / "x.glb"),
                 "--html", str(tmp_path / "page")]) == 0
    out = capsys.readouterr().err  # status lines go to stderr
    assert "morph targets" in out and (tmp_path / "x.glb").stat().st_size > 100_000
    assert {p.name for p in (tmp_path / "page").iterdir()} >= {
        "index.html", "player.js", "scene.js", "face.glb"}
    assert main(["export", str(FAP), "-o", str(tmp_path / "x.csv"), "--arkit"]) == 0
    assert "fit residual" in capsys.readouterr().err
    rows = list(csv.reader((tmp_path / "x.csv").read_text().splitlines()))
    assert len(rows) == 4 and rows[0][19] == "JawOpen"
    assert main(["import-arkit", str(tmp_path / "x.csv"), "-o", str(tmp_path / "back.fap")]) == 0
    back = read_fap(tmp_path / "back.fap", strict=True)
    # the file animates with FAP 1/2 and open_jaw: the jaw comes back opening
    assert back.n_frames == 3 and np.argmax(back.values[:, 2]) == 2


def test_export_needs_an_output(capsys):
    assert main(["export", str(FAP)]) == 2  # a usage error
    assert "give -o" in capsys.readouterr().err


def test_export_vrm_writes_an_avatar_and_checks_the_suffix(tmp_path, capsys):
    out = tmp_path / "head.vrm"
    assert main(["export", str(FAP), "--vrm", str(out)]) == 0
    assert "17 expression presets" in capsys.readouterr().err
    assert out.read_bytes()[:4] == b"glTF" and b'"VRMC_vrm"' in out.read_bytes()[:200_000]
    assert main(["export", str(FAP), "--vrm", str(tmp_path / "head.glb")]) == 2
    assert "writes .vrm" in capsys.readouterr().err
