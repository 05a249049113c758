"""Moods: a baseline expression and motion style that lasts until the next mood.

``facelib/data/moods/moods.csv`` defines each mood: the library expression held underneath
the explicit ones (and at what level), and scales for head motion, speech-time brows, idle
motion and blinks. :func:`mood_curves` turns a storyboard's mood cues into per-frame curves;
:func:`facelib.expressions.animate` blends the baseline under the explicit expressions.
Pure functions of the cues: the same cues give the same curves, whatever the seed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib import data
from facelib.checks import check_count, check_fps, check_items, did_you_mean
from facelib.cues import MoodCue
from facelib.errors import DataError, FdlError
from facelib.expressions.library import ExpressionLibrary, default_library
from facelib.mpeg4.tables import N_FAPS

__all__ = ["Mood", "MoodCurves", "mood_curves", "moods"]

_FILE = "moods/moods.csv"
_SCALES = ("head_motion_scale", "speech_brow", "idle_amplitude", "blink_rate_scale")


@dataclass(frozen=True)
class Mood:
    """One row of ``moods.csv`` (values at mood intensity 1).

    expression: the library expression underneath ("" for none), at cue intensity ``level``.
    head_motion_scale, idle_amplitude, blink_rate_scale: factors (1 = as without a mood).
    speech_brow: brow raise on a stressed syllable, ENS units (negative lowers).
    ease_ms: settling time when a cue gives none.
    """

    name: str
    expression: str
    level: float
    head_motion_scale: float
    speech_brow: float
    idle_amplitude: float
    blink_rate_scale: float
    ease_ms: int


def _mood_row(line: int, row: Mapping[str, str]) -> Mood:
    try:
        numbers = {k: float(row[k]) for k in ("level", *_SCALES, "ease_ms")}
    except ValueError as exc:
        raise DataError(f"mood {row['mood']!r}: {exc}", path=str(data.path(_FILE)),
                        line=line) from None
    bad = [k for k, v in numbers.items()
           if not np.isfinite(v) or (k != "speech_brow" and v < 0)]
    if bad:
        raise DataError(f"mood {row['mood']!r}: {bad[0]} must be a finite number >= 0",
                        path=str(data.path(_FILE)), line=line)
    return Mood(row["mood"], row["expression"], numbers["level"],
                numbers["head_motion_scale"], numbers["speech_brow"],
                numbers["idle_amplitude"], numbers["blink_rate_scale"],
                int(numbers["ease_ms"]))


@cache
def moods() -> Mapping[str, Mood]:
    """The moods of ``moods.csv`` by name (read once); each expression must be in the
    default library."""
    out = {}
    library = default_library()
    for line, row in data.csv_rows(_FILE):
        mood = _mood_row(line, row)
        if mood.expression and mood.expression not in library:
            raise DataError(f"mood {mood.name!r}: unknown expression {mood.expression!r}",
                            path=str(data.path(_FILE)), line=line)
        out[mood.name] = mood
    return MappingProxyType(out)


def _get(cue: MoodCue) -> Mood:
    found = moods().get(cue.name.lower())
    if found is None:
        path, line = cue.origin if cue.origin else (None, None)
        raise FdlError(f"unknown mood {cue.name!r}{did_you_mean(cue.name, tuple(moods()))} "
                       f"(known: {', '.join(moods())})", path=path, line=line)
    return found


@dataclass(frozen=True)
class MoodCurves:
    """The moods of a storyboard frame by frame.

    values: ``(n_frames, 84) float64`` the baseline FAP values (the moods' expressions);
    mask: ``(n_frames, 84) float64`` in [0, 1], how strongly the baseline drives each FAP;
    scales: name -> ``(n_frames,) float64`` per-frame ``head_motion_scale``,
        ``speech_brow``, ``idle_amplitude`` and ``blink_rate_scale`` (1, 0, 1, 1 with no mood).
    """

    values: np.ndarray
    mask: np.ndarray
    scales: Mapping[str, np.ndarray]


def _shares(cues: Sequence[MoodCue], times_ms: np.ndarray) -> list[np.ndarray]:
    """Per cue ``(n,)`` its share of each frame: it rises over its ease from its start and
    hands over to the next cue as that one rises, so the shares sum to at most 1."""
    rises: list[np.ndarray] = []
    for cue in cues:
        ease = _get(cue).ease_ms if cue.ease_ms is None else cue.ease_ms
        if ease > 0:
            rises.append(np.clip((times_ms - cue.start_ms) / ease, 0.0, 1.0))
        else:
            rises.append((times_ms >= cue.start_ms).astype(np.float64))
    return [rise * (1.0 - rises[k + 1]) if k + 1 < len(rises) else rise
            for k, rise in enumerate(rises)]


def mood_curves(
    cues: Sequence[MoodCue], *, fps: float, n_frames: int,
    library: ExpressionLibrary | None = None,
) -> MoodCurves:
    """The mood cues (in time order; each lasts until the next) as per-frame curves.

    A mood cue's share of a frame eases from 0 to 1 over its ``ease_ms`` while the mood
    before it eases out; its expression is held at ``share(level * intensity)`` (the
    expression's intensity curve), its scales move from 1 (0 for ``speech_brow``) towards
    the mood's value in proportion to ``share * intensity``.
    """
    cues = sorted(check_items("moods", cues, MoodCue), key=lambda c: c.start_ms)
    fps = check_fps(fps)
    n_frames = check_count("n_frames", n_frames)
    library = library or default_library()
    times = np.arange(n_frames) * (1000.0 / fps)
    values = np.zeros((n_frames, N_FAPS))
    mask = np.zeros((n_frames, N_FAPS))
    scales = {k: np.full(n_frames, 0.0 if k == "speech_brow" else 1.0) for k in _SCALES}
    for cue, share in zip(cues, _shares(cues, times), strict=True):
        mood = _get(cue)
        amount = share * float(np.clip(cue.intensity, 0.0, 1.0))
        for key in _SCALES:
            rest = 0.0 if key == "speech_brow" else 1.0
            scales[key] += amount * (getattr(mood, key) - rest)
        if mood.expression and mood.level > 0:
            expression = library.get(mood.expression, origin=cue.origin)
            strength = expression.share(mood.level * float(np.clip(cue.intensity, 0.0, 1.0)))
            values += share[:, None] * strength * expression.values
            mask += share[:, None] * expression.mask
    for array in (values, mask, *scales.values()):
        array.flags.writeable = False
    return MoodCurves(values, np.clip(mask, 0.0, 1.0), MappingProxyType(scales))
