"""The standard's vocabulary in the code: FAPs by name or by the table, never by a bare
column number; feature points are never called ``fps`` (that is a frame rate)."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).parents[1] / "facelib"
FAP_ARRAYS = {"f", "values", "weight", "frame", "faps"}
"""Names that hold (n, 84) FAP arrays in these modules."""


def _bare_fap_columns(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not (isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name)
                and node.value.id in FAP_ARRAYS and isinstance(node.slice, ast.Tuple)):
            continue
        column = node.slice.elts[-1]
        if isinstance(column, ast.Constant) and isinstance(column.value, int):
            found.append(f"{path.name}:{node.lineno} {ast.unparse(node)}")
        if isinstance(column, ast.Slice) and any(
                isinstance(b, ast.Constant) for b in (column.lower, column.upper)):
            found.append(f"{path.name}:{node.lineno} {ast.unparse(node)}")
    return found


@pytest.mark.parametrize("module", ["engine/face.py", "gaze/animate.py", "sync/combine.py",
                                    "tracking/lipclosure.py", "tracking/observation.py",
                                    "tracking/closedloop.py", "tracking/faps.py"])
def test_no_bare_fap_columns(module):
    assert _bare_fap_columns(PACKAGE / module) == []


def test_the_check_finds_a_bare_column(tmp_path):
    path = tmp_path / "old.py"
    path.write_text("values[:, 18] = upper\nopen_ = f[:, 2]\nweight[:, 47:50] = 1\n")
    assert len(_bare_fap_columns(path)) == 3


def test_feature_points_are_not_called_fps_in_the_engine():
    for path in (PACKAGE / "engine").rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.arg) and node.arg == "fps" and node.annotation is not None:
                assert "Mapping" not in ast.unparse(node.annotation), f"{path.name}: {node.lineno}"
            if (isinstance(node, ast.Assign) and "fps" in {ast.unparse(t) for t in node.targets}
                    and "feature_point" in ast.unparse(node.value)):
                raise AssertionError(f"{path.name}:{node.lineno} calls feature points 'fps'")
