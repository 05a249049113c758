"""Discoverability: `facelib list`, the names in the docs, compact reprs (newcomer items 6-7)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

import facelib
from facelib.catalog import catalog
from facelib.cli import main
from facelib.expressions import default_library
from facelib.gaze.behaviours import behaviour_library
from facelib.mpeg4.visemes import viseme_names

ROOT = Path(__file__).resolve().parents[2]


def test_list_expressions_names_every_library_expression_with_its_gallery(capsys):
    assert main(["list", "expressions"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(default_library().names)
    assert all("docs/images/expressions.png" in line for line in lines)
    assert (ROOT / "docs" / "images" / "expressions.png").is_file()


def test_list_visemes_and_behaviours(capsys):
    assert main(["list", "visemes"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == list(viseme_names())
    assert "script names: TD, T, D" in lines[3]
    assert main(["list", "behaviours"]) == 0
    names = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert names == [n for n in behaviour_library() if not n.startswith("_")]
    assert all(entry.description for entry in catalog("behaviours"))


def test_docs_name_every_expression_and_behaviour():
    text = (ROOT / "docs" / "fdl.md").read_text()
    for name in (*default_library().names, *(e.name for e in catalog("behaviours"))):
        assert re.search(rf"`{name}`", text), f"docs/fdl.md does not name {name!r}"


def test_reprs_are_one_short_line():
    face = facelib.load_face()
    stream = facelib.FapStream(25, np.zeros((10, 84), np.float32))
    for obj in (face, stream):
        text = repr(obj)
        assert "\n" not in text and len(text) < 200
    assert repr(face).startswith("Face(vertices=")
    assert "active_faps=0" in repr(stream)
