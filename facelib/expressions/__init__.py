"""Facial expressions: the library of named FAP sets, their curves over time, and moods."""

from facelib.expressions.curves import animate, envelope
from facelib.expressions.library import Expression, ExpressionLibrary, default_library
from facelib.expressions.moods import Mood, MoodCurves, mood_curves, moods

__all__ = [
    "Expression", "ExpressionLibrary", "Mood", "MoodCurves", "animate", "default_library",
    "envelope", "mood_curves", "moods",
]
