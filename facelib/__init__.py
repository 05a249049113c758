"""facelib: scriptable MPEG-4 facial animation.

Storyboards in FDL (Lua) become FAP streams, deformed face meshes, videos and ``.fap``
files::

    import facelib
    animation = facelib.run_fdl("examples/hello/hello.fdl")
    facelib.write_fap(animation.faps, "hello.fap")
    facelib.render(animation, out="hello.mp4")

``import facelib`` loads numpy, scipy and lupa at most; rendering (OpenGL), speech
alignment (pocketsphinx) and plotting (matplotlib) load on first use.
"""

from typing import TYPE_CHECKING, Any

from facelib import expressions, fdl, gaze, mpeg4, sync, visemes
from facelib.animation import (
    Animation,
    Scene,
    animate,
    animate_scene,
    run_fdl,
    run_scene,
)
from facelib.errors import (
    ArkitFormatError,
    DataError,
    FacelibError,
    FacelibWarning,
    FaceModelError,
    FapFormatError,
    FdlError,
    FdlWarning,
    FileError,
    MissingExtraError,
    ParameterError,
    PronunciationWarning,
    RenderError,
    SpeechError,
    SpeechWarning,
    TrackingError,
    TrackingWarning,
    facelib_warnings,
)
from facelib.mpeg4 import FapStream, FapTrack, fap, feature_point, read_fap, write_fap
from facelib.visemes import visemes_from_audio

if TYPE_CHECKING:
    from facelib.engine import Face, load_face

__version__ = "0.1.0"

_LAZY = {
    "Face": "facelib.engine",
    "load_face": "facelib.engine",
    "render": "facelib.rendering.frames",
    "render_still": "facelib.rendering.frames",
    "render_scene": "facelib.rendering.shots",
    "save_png": "facelib.rendering.frames",
    "view": "facelib.rendering.viewer",
    "plot_curves": "facelib.plot",
    "export_gltf": "facelib.export",
    "export_html": "facelib.export",
    "export_vrm": "facelib.export",
    "export_vrma": "facelib.export",
    "export_arkit": "facelib.export",
    "import_arkit": "facelib.export",
    "to_arkit": "facelib.export",
    "from_arkit": "facelib.export",
    "arkit_residuals": "facelib.export",
    "setup_face": "facelib.engine.setup",
    "write_face": "facelib.engine.writer",
    "landmarks_to_faps": "facelib.tracking.faps",
    "track_video_faps": "facelib.tracking.video",
}


def __getattr__(name: str) -> Any:
    """Rendering, the viewer, plotting, the exports and face set-up import OpenGL,
    matplotlib, pygltflib or trimesh, and the engine scipy's sparse and spatial
    modules: load them on first use."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'facelib' has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's names and the lazy ones (so completion offers ``render`` before use)."""
    return sorted({*globals(), *_LAZY})


__all__ = [
    "Animation",
    "ArkitFormatError",
    "DataError",
    "Face",
    "FaceModelError",
    "FacelibError",
    "FacelibWarning",
    "FapFormatError",
    "FapStream",
    "FapTrack",
    "FdlError",
    "FdlWarning",
    "FileError",
    "MissingExtraError",
    "ParameterError",
    "PronunciationWarning",
    "RenderError",
    "Scene",
    "SpeechError",
    "SpeechWarning",
    "TrackingError",
    "TrackingWarning",
    "__version__",
    "animate",
    "animate_scene",
    "arkit_residuals",
    "export_arkit",
    "export_gltf",
    "export_html",
    "export_vrm",
    "export_vrma",
    "expressions",
    "facelib_warnings",
    "fap",
    "fdl",
    "feature_point",
    "from_arkit",
    "gaze",
    "import_arkit",
    "landmarks_to_faps",
    "load_face",
    "mpeg4",
    "plot_curves",
    "read_fap",
    "render",
    "render_scene",
    "render_still",
    "run_fdl",
    "run_scene",
    "save_png",
    "setup_face",
    "sync",
    "to_arkit",
    "track_video_faps",
    "view",
    "visemes",
    "visemes_from_audio",
    "write_face",
    "write_fap",
]
