"""``facelib.__all__`` is what ``facelib`` offers, and docs/api.md names every entry.

What ``facelib/__init__.py`` offers: the names its own statements bind (imports, defs,
assignments; not ``TYPE_CHECKING`` blocks, not private ones) plus the lazily loaded ones
of ``_LAZY``. Every error and warning class of ``facelib.errors`` must be among them.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import re
from pathlib import Path

import facelib
from facelib import errors

ROOT = Path(__file__).resolve().parents[1]
HELPERS = {"Any", "TYPE_CHECKING"}  # typing names the module uses itself


def bound_names(path: Path) -> set[str]:
    """Public names the module-level statements of ``path`` bind (TYPE_CHECKING left out)."""
    names: set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names |= {t.id for t in targets if isinstance(t, ast.Name)}
    return {n for n in names if not n.startswith("_") or n == "__version__"} - HELPERS


def test_all_is_exactly_what_facelib_offers() -> None:
    offered = bound_names(ROOT / "facelib" / "__init__.py") | set(facelib._LAZY)
    assert len(facelib.__all__) == len(set(facelib.__all__)), "a name repeats in __all__"
    assert sorted(set(facelib.__all__) - offered) == [], "in __all__ but not offered"
    assert sorted(offered - set(facelib.__all__)) == [], "offered but missing from __all__"


def test_every_error_and_warning_class_is_public() -> None:
    classes = {name for name, obj in vars(errors).items() if inspect.isclass(obj)
               and issubclass(obj, (errors.FacelibError, errors.FacelibWarning))}
    assert {"TrackingError", "TrackingWarning", "ArkitFormatError"} <= classes
    assert sorted(classes - set(facelib.__all__)) == []


def test_lazy_names_resolve_and_dir_lists_them() -> None:
    for name, module in facelib._LAZY.items():
        assert hasattr(importlib.import_module(module), name), f"{module} has no {name}"
    listed = dir(facelib)
    assert set(facelib.__all__) <= set(listed)
    assert listed == sorted(listed)


def test_docs_api_mentions_every_public_name() -> None:
    api = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    in_code = {word for span in re.findall(r"`([^`]+)`", api)
               for word in re.findall(r"[A-Za-z_][A-Za-z_0-9]*", span)}
    assert sorted(set(facelib.__all__) - in_code) == [], "public names docs/api.md never names"
