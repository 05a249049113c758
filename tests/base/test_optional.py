"""facelib.optional: the one helper behind every optional import (issue 30 item 4)."""

from __future__ import annotations

import re
import sys
import tomllib
import types
from pathlib import Path

import pytest

from facelib.errors import MissingExtraError
from facelib.optional import missing_extra, optional_uses, require

ROOT = Path(__file__).resolve().parents[2]


def _requirement_names(specs: list[str]) -> set[str]:
    return {re.split(r"[<>=!~;\[ ]", spec, maxsplit=1)[0].lower() for spec in specs}


def test_every_row_names_a_package_of_its_extra() -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    for use, row in optional_uses().items():
        assert row.extra in extras, f"{use}: no extra {row.extra!r} in pyproject.toml"
        assert row.package.lower() in _requirement_names(extras[row.extra]), (
            f"{use}: {row.package} is not in the {row.extra} extra")


def test_a_missing_module_raises_the_extra_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pygltflib", None)  # import pygltflib -> ImportError
    with pytest.raises(MissingExtraError) as info:
        require("pygltflib")
    assert str(info.value) == ("glTF export needs the 'pygltflib' package, which is not "
                               "installed; install it with: pip install 'facelib[export]'")
    assert isinstance(info.value, ImportError)
    assert isinstance(info.value.__cause__, ImportError)
    assert str(missing_extra("ffmpeg_track")).endswith("pip install 'facelib[track]'")
    assert str(missing_extra("ffmpeg_render")).startswith("video writing needs the "
                                                          "'imageio-ffmpeg' package")


def test_an_installed_module_is_returned(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = types.ModuleType("trimesh")
    monkeypatch.setitem(sys.modules, "trimesh", fake)
    assert require("trimesh") is fake
    with pytest.raises(KeyError):
        require("no such use")


def test_no_module_writes_its_own_missing_extra_message() -> None:
    """Extra names live in optional.csv only: no ``MissingExtraError(...)`` elsewhere."""
    offenders = [str(p.relative_to(ROOT)) for p in (ROOT / "facelib").rglob("*.py")
                 if p.name not in {"errors.py", "optional.py"}
                 and "MissingExtraError(" in p.read_text(encoding="utf-8")]
    assert not offenders
