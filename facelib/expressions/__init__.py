"""Facial expressions: the library of named FAP sets and their curves over time."""

from facelib.expressions.curves import animate, envelope
from facelib.expressions.library import Expression, ExpressionLibrary, default_library

__all__ = ["Expression", "ExpressionLibrary", "animate", "default_library", "envelope"]
