"""FDL, the Face Description Language: sandboxed Lua storyboards."""

from facelib.fdl.describe import describe
from facelib.fdl.loader import load, loads
from facelib.fdl.sandbox import Sandbox
from facelib.fdl.storyboard import (
    ExpressionCue,
    GazeCue,
    SpeechSpec,
    Storyboard,
    VisemeCue,
)

__all__ = [
    "ExpressionCue",
    "GazeCue",
    "Sandbox",
    "SpeechSpec",
    "Storyboard",
    "VisemeCue",
    "describe",
    "load",
    "loads",
]
