"""FAP curves over time, one panel per face region, with the storyboard's cues shaded.

Needs matplotlib (the ``plot`` extra); it is imported on first use.
"""

from __future__ import annotations

import os
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from facelib.atomic import atomic_path
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap, fap_groups, fap_table
from facelib.optional import require

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from facelib.animation import Animation
    from facelib.cues import Storyboard

__all__ = ["REGIONS", "plot_curves"]

def _regions() -> tuple[tuple[str, tuple[int, ...]], ...]:
    """One panel per FAP group of the standard (``fap_groups``) that moves the face: group
    1 (visemes and expressions) is expanded into the others."""
    groups = fap_groups()
    return tuple(
        (name, tuple(f.id for f in fap_table() if f.group == group))
        for group, name in groups.items()
        if group != 1
    )


REGIONS: tuple[tuple[str, tuple[int, ...]], ...] = _regions()
"""Panels: a title (the FAP group's name) and the FAP ids it shows."""


def plot_curves(
    source: FapStream | Animation,
    out: str | os.PathLike[str],
    *,
    title: str | None = None,
    width: float = 12.0,
) -> Path:
    """Plot every FAP of ``source`` that moves over time to an image file (PNG, SVG, PDF).

    source: a FapStream, or an Animation (then its expression and eye cues are shaded and
        labelled, and the spoken span is marked).
    out: the file to write (atomically). Returns its path.
    """
    mpl = require("matplotlib")
    mpl.use("Agg")
    plt = require("pyplot")
    if not isinstance(source, FapStream) and not isinstance(getattr(source, "faps", None),
                                                            FapStream):
        raise ParameterError(f"plot_curves takes a FapStream or an Animation, not "
                             f"{type(source).__name__}")
    stream: FapStream = source if isinstance(source, FapStream) else source.faps
    storyboard = getattr(source, "storyboard", None)
    moving = set(np.flatnonzero(stream.values.any(axis=0)) + 1)
    active = [f for f in stream.active_faps() if f > 2 and f in moving]
    panels = [(name, [f for f in active if f in ids]) for name, ids in REGIONS]
    panels = [(name, faps) for name, faps in panels if faps] or [("no active FAPs", [])]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, squeeze=False,
                             figsize=(width, 1.9 * len(panels) + 0.8))
    t = stream.times
    for ax, (name, faps) in zip(axes[:, 0], panels, strict=True):
        if storyboard is not None:
            _shade_cues(ax, storyboard)
        for f in faps:
            info = fap(f)
            ax.plot(t, stream.values[:, f - 1], lw=1.1, label=f"{f} {info.name} ({info.fapu})")
        ax.set_ylabel(textwrap.fill(name, 24), fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
        if faps:
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    axes[-1, 0].set_xlabel("time (s)")
    axes[-1, 0].set_xlim(0, max(stream.duration, 1e-3))
    fig.suptitle(title or f"FAP curves: {stream.n_frames} frames at {stream.fps:g} fps")
    fig.tight_layout()
    with atomic_path(out) as temp:
        fig.savefig(temp, dpi=110, format=Path(out).suffix.lstrip(".") or "png")
    plt.close(fig)
    return Path(out)


def _shade_cues(ax: Axes, storyboard: Storyboard) -> None:
    labelled = [("tab:orange", 0.95, c.start_ms, c.end_ms, c.name) for c in storyboard.expressions]
    labelled += [("tab:blue", 0.05, c.start_ms, c.end_ms, c.behaviour) for c in storyboard.gaze]
    for colour, y, start_ms, end_ms, label in labelled:
        start, end = start_ms / 1000, end_ms / 1000
        ax.axvspan(start, end, color=colour, alpha=0.07, lw=0)
        ax.text(start, y, label, transform=ax.get_xaxis_transform(), fontsize=6,
                color=colour, va="top" if y > 0.5 else "bottom")
    speech = storyboard.speech
    if speech is not None and speech.visemes:
        ax.axvspan(speech.visemes[0].start_ms / 1000, speech.visemes[-1].end_ms / 1000,
                   color="tab:green", alpha=0.05, lw=0)
