"""'Did you mean ...' hints for misspelt FDL keywords, fields and names."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = ["did_you_mean"]


def did_you_mean(word: str, choices: Iterable[str], *, cutoff: float = 0.7) -> str:
    """Return ``"; did you mean 'x'?"`` for the closest of ``choices`` to ``word``, or ``""``.

    Case is ignored when comparing (``speaksound`` suggests ``speakSound``).
    """
    options = {c.lower(): c for c in choices if c != word}
    close = difflib.get_close_matches(word.lower(), list(options), n=1, cutoff=cutoff)
    return f"; did you mean '{options[close[0]]}'?" if close else ""
