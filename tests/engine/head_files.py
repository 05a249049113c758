"""The default face definition copied into a test's folder with every mesh it names (the
head's, the bust's and the hair's), so that a test can edit the definition and load it."""

from __future__ import annotations

import json
import shutil
from importlib import resources
from pathlib import Path
from typing import Any

HEAD = Path(str(resources.files("facelib.data").joinpath("head")))


def copy_head_files(folder: Path) -> dict[str, Any]:
    """Copy the meshes the default definition names into ``folder``; return its document."""
    doc: dict[str, Any] = json.loads((HEAD / "default_head.json").read_text())
    names = [doc["mesh"]] + [doc[key]["mesh"] for key in ("bust", "hair") if key in doc]
    for name in names:
        shutil.copy(HEAD / name, folder / name)
    return doc
