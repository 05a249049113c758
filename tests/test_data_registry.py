"""tests/data/registry.toml says how every fixture is made: each file is covered by an
entry, each entry matches a file and says what it is, who uses it and how to remake it."""

import tomllib
from pathlib import Path

DATA = Path(__file__).parent / "data"
REGISTRY = tomllib.loads((DATA / "registry.toml").read_text(encoding="utf-8"))["fixture"]


def _files() -> set[Path]:
    return {p for p in DATA.rglob("*") if p.is_file() and "__pycache__" not in p.parts}


def test_every_fixture_is_registered():
    covered = {p for entry in REGISTRY for p in DATA.glob(entry["path"])}
    missing = sorted(str(p.relative_to(DATA)) for p in _files() - covered)
    assert not missing, f"add these to tests/data/registry.toml: {missing}"


def test_every_entry_matches_a_file_and_is_complete():
    for entry in REGISTRY:
        assert list(DATA.glob(entry["path"])), f"{entry['path']} matches no file"
        assert {"what", "used_by", "regenerate"} <= set(entry), entry["path"]
        assert all(entry[key].strip() for key in ("what", "used_by", "regenerate"))
