"""A static web page that plays an exported glTF with its speech audio (three.js).

``export_html(source, "out/player/")`` writes ``index.html``, ``player.js`` (three.js and the
player, bundled by esbuild when facelib is set up: ``make setup`` runs ``npm run build`` in
``facelib/export/web``), ``scene.js`` (the ``.glb`` as base64, so the page also works from
``file://`` without a server), ``face.glb`` and the audio. Nothing is fetched from the network.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from facelib import data
from facelib.atomic import atomic_path, output_folder, write_text_atomic
from facelib.engine import Face
from facelib.errors import FacelibError
from facelib.export.gltf import export_gltf
from facelib.export.source import Source, export_clip

__all__ = ["WEB_DIR", "WebExport", "export_html"]

WEB_DIR = Path(__file__).parent / "web"
_BUNDLE = WEB_DIR / "dist" / "player.js"


@dataclass(frozen=True)
class WebExport:
    """What :func:`export_html` wrote: the folder, its page and its ``.glb``."""

    folder: Path
    page: Path
    glb: Path
    audio: Path | None


def export_html(
    source: Source,
    out_dir: str | os.PathLike[str],
    *,
    face: Face | None = None,
    audio: str | os.PathLike[str] | None = None,
    targets: str = "fap",
) -> WebExport:
    """Write a web player for ``source`` into the folder ``out_dir`` (created if missing).

    ``source``, ``face``, ``audio`` and ``targets`` as for
    :func:`facelib.export.export_gltf`. The page has play/pause, a time slider for scrubbing
    and orbit (drag), zoom (wheel) and pan. With ``targets="arkit"`` the folder is also the
    head of the live page (``examples/live/``, ``docs/live.md``): it sets the 52 ARKit
    weights of a ``facelib serve`` session's frames on the morph targets.
    """
    if not _BUNDLE.is_file():
        raise FacelibError(f"the web player is not built ({_BUNDLE} is missing): run "
                           "'make setup', or 'npm ci && npm run build' in "
                           f"{WEB_DIR}")
    folder = output_folder(out_dir)
    clip = export_clip(source, face=face, audio=audio)
    result = export_gltf(clip, folder / "face.glb", targets=targets)
    look = data.json_data("render_look.json")
    scene = {
        "glb": base64.b64encode(result.path.read_bytes()).decode("ascii"),
        "fps": result.fps, "nFrames": result.n_frames,
        "audio": result.audio.name if result.audio else None,
        "audioOffset": clip.audio_offset,
        "look": {k: look[k] for k in ("lights", "ambient", "background", "camera")},
    }
    write_text_atomic(folder / "scene.js",
                      "window.FACELIB_SCENE = " + json.dumps(scene, separators=(",", ":")) + ";\n")
    for name, src in (("player.js", _BUNDLE), ("index.html", WEB_DIR / "page" / "index.html")):
        with atomic_path(folder / name) as temp:
            shutil.copyfile(src, temp)
    return WebExport(folder, folder / "index.html", result.path, result.audio)
