"""facelib: scriptable MPEG-4 facial animation.

Storyboards in FDL (Lua) become FAP streams, deformed face meshes, videos and ``.fap``
files. ``import facelib`` loads numpy, scipy and lupa at most; rendering, speech alignment
and plotting load on first use.
"""

from facelib.errors import (
    FacelibError,
    FaceModelError,
    FapFormatError,
    FdlError,
    MissingExtraError,
    ParameterError,
    RenderError,
    SpeechError,
)
from facelib.mpeg4 import FapStream, FapTrack, fap, feature_point, read_fap, write_fap

__version__ = "0.1.0"

__all__ = [
    "FaceModelError",
    "FacelibError",
    "FapFormatError",
    "FapStream",
    "FapTrack",
    "FdlError",
    "MissingExtraError",
    "ParameterError",
    "RenderError",
    "SpeechError",
    "__version__",
    "fap",
    "feature_point",
    "read_fap",
    "write_fap",
]
