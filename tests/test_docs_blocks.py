"""Every code block of README.md and docs/*.md runs, so the docs cannot drift from the code.

Storyboards (lua) go through `facelib check` and `facelib run`; Python blocks run in a fresh
interpreter; shell lines that call `facelib` run as commands. Each runs in a scratch folder
holding the example media, with `examples/` and `tests/` linked in so repository paths
resolve. Dataset specs (toml) are read and drawn from. JSON blocks illustrate a schema with
placeholders and are not run, and so is a block right after a ``<!-- not run: reason -->``
line (it needs files a reader makes first).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from facelib.cli import main

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.DOTALL | re.MULTILINE)
NOT_RUN = "<!-- not run:"
MEDIA = [*(ROOT / "examples" / "hastalavista").iterdir(),
         *(ROOT / "examples" / "hello").iterdir()]


def blocks(language: str) -> list[tuple[str, str]]:
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for match in FENCE.finditer(text):
            before = text[: match.start()].rstrip().rsplit("\n", 1)[-1]
            if match.group(1) == language and not before.startswith(NOT_RUN):
                line = text[: match.start()].count("\n") + 1
                found.append((f"{page.relative_to(ROOT)}:{line}", match.group(2)))
    return found


@pytest.fixture
def scratch(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for item in MEDIA:
        shutil.copy(item, tmp_path / item.name)
    for name in ("examples", "tests"):
        (tmp_path / name).symlink_to(ROOT / name)
    (tmp_path / "speech.wav").symlink_to(ROOT / "examples" / "hastalavista" / "hastalavista.wav")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_docs_have_blocks_of_each_kind():
    assert len(blocks("lua")) >= 7 and len(blocks("python")) >= 2 and blocks("sh")


@pytest.mark.parametrize(("where", "code"), blocks("lua"), ids=[w for w, _ in blocks("lua")])
def test_storyboard_block_checks_and_runs(scratch, where, code, capsys):
    story = scratch / "block.fdl"
    story.write_text(code, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["check", str(story)]) == 0, capsys.readouterr().err
        assert main(["run", str(story), "-o", str(scratch / "block.fap")]) == 0, (
            capsys.readouterr().err)
    if "characters {" in code:  # one .fap per character: block.NAME.fap
        assert sorted(scratch.glob("block.*.fap")), "no .fap per character"
        return
    assert (scratch / "block.fap").stat().st_size > 0


@pytest.mark.parametrize(("where", "code"), blocks("toml"), ids=[w for w, _ in blocks("toml")])
def test_dataset_spec_block_loads_and_draws(tmp_path, where, code):
    from facelib.dataset import draw_clip, load_spec

    path = tmp_path / "spec.toml"
    path.write_text(code, encoding="utf-8")
    spec = load_spec(path)
    draws = [draw_clip(spec, i) for i in range(spec.clips)]
    assert len({d.seed for d in draws}) == spec.clips


def _run(argv: list[str], cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONWARNINGS": "ignore"}
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=timeout, check=False)


@pytest.mark.slow
@pytest.mark.parametrize(("where", "code"), blocks("python"),
                         ids=[w for w, _ in blocks("python")])
def test_python_block_runs(scratch, where, code):
    result = _run([sys.executable, "-c", code], scratch)
    assert result.returncode == 0, f"{where}:\n{result.stderr[-3000:]}"


def shell_commands() -> list[tuple[str, str]]:
    """The `facelib ...` lines of the shell blocks (make targets and installs are not run
    here: `make test` is what runs this)."""
    found = []
    for where, code in blocks("sh"):
        for line in code.splitlines():
            command = line.split(" #", 1)[0].strip()
            if command.startswith("facelib "):
                found.append((where, command))
    return found


@pytest.mark.slow
@pytest.mark.parametrize(("where", "command"), shell_commands(),
                         ids=[c for _, c in shell_commands()])
def test_shell_command_runs(scratch, where, command):
    (scratch / "out").mkdir(exist_ok=True)
    argv = [sys.executable, "-m", "facelib.cli", *shlex.split(command)[1:]]
    result = _run(argv, scratch)
    assert result.returncode == 0, f"{where}: {command}\n{result.stderr[-3000:]}"
