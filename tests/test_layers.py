"""The layer rules of DESIGN.md ("Layout and import rules"), checked on every module's imports.

Every ``import`` and ``from ... import`` in ``facelib/`` (at module level or inside a
function, lazy ones included) must go to a package its layer may use; a new upward import
fails here, naming the file and line.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "facelib"

BASE = {"errors", "checks", "atomic", "data", "progress", "optional"}
GENERATORS = {"fdl", "speech", "visemes", "expressions", "gaze"}
OUTPUTS = {"rendering", "tracking", "export"}
TOP = {"batch", "cluster", "dataset", "evaluate", "catalog", "cli", "plot", "__init__", "__main__"}

# unit -> the facelib units it may import (besides itself)
ALLOWED: dict[str, set[str]] = {
    **dict.fromkeys(BASE, BASE),
    "mpeg4": BASE,
    "cues": BASE | {"mpeg4"},
    **{unit: BASE | {"mpeg4", "cues"} for unit in GENERATORS},
    "sync": BASE | {"mpeg4"},
    "animation": BASE | {"mpeg4", "cues", "sync"} | GENERATORS,
    "engine": BASE | {"mpeg4"},
    "clip": BASE | {"mpeg4", "engine"},
    **{unit: BASE | {"mpeg4", "engine", "clip"} for unit in OUTPUTS},
    # live sessions: on the layer of animation, plus the outputs they stream (DESIGN.md)
    "live": BASE | {"mpeg4", "cues", "sync", "animation", "export", "clip"} | GENERATORS,
}
ALLOWED["visemes"] = ALLOWED["visemes"] | {"speech"}
ALLOWED["tracking"] = ALLOWED["tracking"] | {"rendering"}  # landmarks found on a render
# Third-party packages the base layer may use (DESIGN.md: the standard library and numpy).
BASE_THIRD_PARTY = {"numpy"}


def unit_of(path: Path) -> str:
    parts = path.relative_to(PACKAGE).with_suffix("").parts
    return parts[0]


def imports_of(path: Path, package: str) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in ``path``, a module of ``package``."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                module = ".".join([*base, node.module] if node.module else base)
            else:
                module = node.module or ""
            names = [f"{module}.{alias.name}" for alias in node.names]
            # "from facelib import x" imports the unit x
            found += [(node.lineno, n) for n in names] if module == "facelib" else [
                (node.lineno, module)]
    return found


MODULES = sorted(PACKAGE.rglob("*.py"))


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(PACKAGE)))
def test_module_imports_follow_the_layers(path: Path) -> None:
    unit = unit_of(path)
    if unit in TOP:
        return
    assert unit in ALLOWED, f"{path}: unit {unit!r} is not in the layer table of DESIGN.md"
    wrong = []
    package = ".".join(("facelib", *path.relative_to(PACKAGE).parent.parts))
    for line, module in imports_of(path, package):
        parts = module.split(".")
        if parts[0] == "facelib":
            target = parts[1] if len(parts) > 1 else "__init__"
            if target != unit and target not in ALLOWED[unit]:
                wrong.append(f"{path.name}:{line} imports {module} ({unit} -> {target})")
        elif unit in BASE and parts[0] not in sys.stdlib_module_names | BASE_THIRD_PARTY:
            wrong.append(f"{path.name}:{line} imports third-party {module} in the base layer")
    assert not wrong, "\n".join(wrong)


def test_the_checker_sees_lazy_and_relative_imports(tmp_path: Path) -> None:
    fake = tmp_path / "x.py"
    fake.write_text("def f():\n    from facelib.visemes import animate\n"
                    "from ..engine import face\nfrom facelib import rendering\n")
    assert sorted(imports_of(fake, "facelib.gaze")) == [
        (2, "facelib.visemes"), (3, "facelib.engine"), (4, "facelib.rendering")]
    assert "visemes" not in ALLOWED["gaze"]
    assert "rendering" not in ALLOWED["engine"]
    assert "clip" not in ALLOWED["engine"]
    assert not {"cues", "animation", "rendering", "export"} & ALLOWED["clip"]


ENGINE = PACKAGE / "engine"
# room of facelib/engine -> the rooms it may import (DESIGN.md: the engine's rooms)
ENGINE_ROOMS: dict[str, set[str]] = {
    "deformers": {"deformers"},
    "core": {"core", "deformers"},
    "setup": {"core", "deformers", "setup"},
}


def engine_room(module: str) -> str:
    """``deformers``, ``setup`` or ``core`` for a module name under ``facelib.engine``."""
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[2] in ENGINE_ROOMS else "core"


@pytest.mark.parametrize("path", sorted(ENGINE.rglob("*.py")),
                         ids=lambda p: str(p.relative_to(ENGINE)))
def test_engine_rooms_import_only_downward(path: Path) -> None:
    package = ".".join(("facelib", *path.relative_to(PACKAGE).parent.parts))
    own = engine_room(package)
    wrong = [f"{path.name}:{line} imports {module} ({own} -> {engine_room(module)})"
             for line, module in imports_of(path, package)
             if module.startswith("facelib.engine")
             and engine_room(module) not in ENGINE_ROOMS[own]]
    assert not wrong, "\n".join(wrong)


def test_engine_rooms_are_told_apart() -> None:
    assert engine_room("facelib.engine") == engine_room("facelib.engine.face") == "core"
    assert engine_room("facelib.engine.deformers") == "deformers"
    assert engine_room("facelib.engine.deformers.rbf") == "deformers"
    assert engine_room("facelib.engine.setup.tps") == "setup"
    assert "setup" not in ENGINE_ROOMS["core"] | ENGINE_ROOMS["deformers"]
    assert "core" not in ENGINE_ROOMS["deformers"]
