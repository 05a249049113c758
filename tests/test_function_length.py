"""No function in facelib runs over 60 lines (docstring included): long ones are split
into named steps. ruff checks branches, statements and complexity; this checks length."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).parents[1] / "facelib"
MAX_LINES = 60


def _functions():
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                yield path.relative_to(PACKAGE.parent), node


def test_no_function_over_60_lines():
    long = [
        f"{path}:{node.lineno} {node.name} ({node.end_lineno - node.lineno + 1} lines)"
        for path, node in _functions()
        if node.end_lineno - node.lineno + 1 > MAX_LINES
    ]
    assert not long, "split these functions:\n" + "\n".join(long)


def test_the_check_sees_functions():
    names = {node.name for _, node in _functions()}
    assert {"load", "render", "animate", "deform"} <= names


@pytest.mark.parametrize("source", ["def f():\n" + "    x = 1\n" * 61])
def test_a_long_function_is_counted(source):
    node = ast.parse(source).body[0]
    assert node.end_lineno - node.lineno + 1 > MAX_LINES
