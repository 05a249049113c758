"""Which frames of a track are its neutral face, when the user names none.

Every FAP is measured from the neutral, so a track whose first frame is already an
expression (the jaw open, the corners raised) would read every later frame off that
expression. A first pass measures the FAPs against the first frame; the jaw only opens from
neutral, so the frames with the first pass's jaw near its low are the candidates (pauses,
closures, the neutral itself), and each frame scores by how far its face FAPs lie from their
median over the candidates, plus its motion. The window of lowest mean score is the
neutral; the first frame stays the neutral, as it always was, unless it scores clearly worse
than that window (the rule's numbers and their sources: ``data/tracking/neutral.json``).
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from functools import cache

import numpy as np

from facelib.data import json_data
from facelib.errors import DataError

__all__ = ["NeutralChoice", "NeutralRule", "neutral_news", "neutral_rule", "neutral_scores",
           "neutral_window"]

_DATA = "tracking/neutral.json"


@dataclass(frozen=True)
class NeutralRule:
    """The numbers of the neutral search (the data file gives their sources); FAP
    distances in FAP units."""

    window_s: float
    jaw_below: float
    jaw_share: float
    jaw_percentile: float
    jaw_band: float
    face_faps: tuple[int, ...]


_NUMBERS = ("window_s", "jaw_below", "jaw_share", "jaw_percentile", "jaw_band")


@cache
def neutral_rule() -> NeutralRule:
    """The packaged rule."""
    raw = json_data(_DATA)
    try:
        rule = NeutralRule(**{name: float(raw[name]["value"]) for name in _NUMBERS},
                           face_faps=tuple(int(f) for f in raw["face_faps"]["value"]))
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"malformed neutral rule ({exc})", path=_DATA) from exc
    if not (rule.window_s > 0 and 0 < rule.jaw_share <= 1 and 0 <= rule.jaw_percentile <= 100
            and min(rule.jaw_below, rule.jaw_band) >= 0 and 3 in rule.face_faps
            and all(1 <= f <= 68 for f in rule.face_faps)):
        raise DataError("neutral rule: window_s > 0, jaw_share in (0, 1], jaw_percentile in "
                        "[0, 100], jaw_below and jaw_band >= 0, face_faps ids 1-68 with "
                        "open_jaw (3)", path=_DATA)
    return rule


@dataclass(frozen=True)
class NeutralChoice:
    """The neutral frames of a track.

    Attributes
    ----------
    span: the neutral frames (a slice of the track).
    jaw_below: how far under the first frame's the first pass read the jaw in the rule's
        share of the frames (FAP units; 0 when ``span`` is the first frame).
    """

    span: slice
    jaw_below: float = 0.0

    @property
    def searched(self) -> bool:
        """True when the first frame was not neutral and :attr:`span` was found instead."""
        return self.jaw_below > 0


def neutral_scores(values: np.ndarray, *, rule: NeutralRule | None = None) -> np.ndarray:
    """``(n,) float64`` how far each frame of a first pass's ``(n, 84)`` FAP values lies
    from the neutral face, in FAP units (the RMS over the rule's face FAPs of the distance
    from their median over the jaw-closed frames, plus the RMS motion from the frame
    before); inf for the frames whose jaw is not closed."""
    rule = rule or neutral_rule()
    face = values[:, [f - 1 for f in rule.face_faps]].astype(np.float64)
    jaw = face[:, rule.face_faps.index(3)]
    closed = jaw <= np.percentile(jaw, rule.jaw_percentile) + rule.jaw_band
    off = np.sqrt(((face - np.median(face[closed], axis=0)) ** 2).mean(axis=1))
    motion = np.zeros(len(face))
    motion[1:] = np.sqrt((np.diff(face, axis=0) ** 2).mean(axis=1))
    return np.where(closed, off + motion, np.inf)


def neutral_window(values: np.ndarray, *, fps: float, first: int = 0,
                   excluded: Collection[int] = (), rule: NeutralRule | None = None
                   ) -> NeutralChoice:
    """The neutral frames of a track from its first pass's ``(n, 84)`` FAP ``values`` at
    ``fps``, measured against frame ``first``: that frame, unless the jaw reads more than
    ``jaw_below`` under it in ``jaw_share`` of the frames; then the ``window_s`` window of
    lowest :func:`neutral_scores` from ``first`` on (no frame ``excluded``: no face, too
    dim)."""
    rule = rule or neutral_rule()
    allowed = np.ones(len(values), bool)
    allowed[:first] = False
    allowed[np.asarray(sorted(excluded), np.int64)] = False
    if not allowed.any():
        return NeutralChoice(slice(first, first + 1))
    below = -float(np.percentile(values[allowed, 2], 100 * rule.jaw_share))
    if below <= rule.jaw_below:
        return NeutralChoice(slice(first, first + 1))
    score = np.where(allowed, neutral_scores(values, rule=rule), np.inf)
    width = int(min(max(round(rule.window_s * fps), 1), len(score)))
    windows = np.convolve(score, np.ones(width) / width, mode="valid")  # inf stays inf
    best = int(np.argmin(windows))
    if not np.isfinite(windows[best]):  # no run of width closed frames: the best one
        best, width = int(np.argmin(score)), 1
    return NeutralChoice(slice(best, best + width), below)


def neutral_news(choice: NeutralChoice, first: int) -> str:
    """What to tell the user of a searched ``choice`` whose first frame was ``first``."""
    span = choice.span
    frames = f"frame {span.start}" if span.stop - span.start == 1 else (
        f"frames {span.start}-{span.stop - 1}")
    return (f"frame {first} is not a neutral face (measured from it, the jaw closes "
            f"{choice.jaw_below:.0f} units further in much of the track); {frames} are the "
            "neutral instead (--neutral, or neutral= in Python, chooses others)")
