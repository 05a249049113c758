"""FDL, the Face Description Language: sandboxed Lua storyboards."""

from facelib.fdl.storyboard import (
    ExpressionCue,
    GazeCue,
    SpeechSpec,
    Storyboard,
    VisemeCue,
)

__all__ = ["ExpressionCue", "GazeCue", "SpeechSpec", "Storyboard", "VisemeCue"]
