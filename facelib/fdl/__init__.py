"""FDL, the Face Description Language: sandboxed Lua storyboards.

The cue types a storyboard becomes live in :mod:`facelib.cues`; they are re-exported here
for compatibility.
"""

from facelib.cues import (
    ExpressionCue,
    GazeCue,
    Origin,
    SpeechSpec,
    Storyboard,
    VisemeCue,
)
from facelib.fdl.describe import describe
from facelib.fdl.loader import load, loads
from facelib.fdl.sandbox import Sandbox

__all__ = [
    "ExpressionCue",
    "GazeCue",
    "Origin",
    "Sandbox",
    "SpeechSpec",
    "Storyboard",
    "VisemeCue",
    "describe",
    "load",
    "loads",
]
