"""Frame-based deformers of the second seed (filled in below)."""

from __future__ import annotations

DEFORMERS: tuple = ()
