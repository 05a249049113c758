"""The modern syntax's drafts (see :mod:`facelib.fdl.modern`) as timed cues.

A ``show`` or ``look`` without ``at`` starts where the previous cue of its kind ended; the
first one starts where the thesis list of its kind (if any) ended.
"""

from __future__ import annotations

from collections.abc import Sequence

from facelib.cues import ExpressionCue, GazeCue, SpeechSpec, VisemeCue
from facelib.fdl.context import Context
from facelib.fdl.modern import DraftCue, DraftSpeech
from facelib.fdl.paths import read_text, resolve_inside
from facelib.fdl.visemes import check_viseme

__all__ = ["expression_cues", "gaze_cues", "speech_spec"]


def _starts(drafts: Sequence[DraftCue], after_ms: int) -> list[int]:
    """Start (ms) of each draft: its ``at``, or the end of the draft before it."""
    starts = []
    cursor = after_ms
    for d in drafts:
        start = cursor if d.at_ms is None else d.at_ms
        starts.append(start)
        cursor = start + d.duration_ms
    return starts


def expression_cues(
    drafts: Sequence[DraftCue], ctx: Context, *, after_ms: int = 0
) -> tuple[ExpressionCue, ...]:
    """``show`` drafts as expression cues; open starts follow on from ``after_ms``."""
    return tuple(
        ExpressionCue(name=d.name, start_ms=start, duration_ms=d.duration_ms,
                      intensity=d.intensity, ramp_in_ms=d.ramp_in_ms, ramp_out_ms=d.ramp_out_ms,
                      origin=ctx.origin(d.line))
        for d, start in zip(drafts, _starts(drafts, after_ms), strict=True)
    )


def gaze_cues(
    drafts: Sequence[DraftCue], ctx: Context, *, after_ms: int = 0
) -> tuple[GazeCue, ...]:
    """``look`` drafts as gaze cues; open starts follow on from ``after_ms``."""
    return tuple(
        GazeCue(behaviour=d.name, args=d.args, start_ms=start, duration_ms=d.duration_ms,
                origin=ctx.origin(d.line))
        for d, start in zip(drafts, _starts(drafts, after_ms), strict=True)
    )


def speech_spec(said: DraftSpeech, ctx: Context) -> SpeechSpec:
    """The ``say`` call as speech: files resolved inside the storyboard's folder, stored
    visemes checked and laid one after the other from its start."""
    visemes: tuple[VisemeCue, ...] | None = None
    if said.visemes is not None:
        cues = []
        cursor = said.at_ms
        for viseme, duration, line in said.visemes:
            check_viseme(viseme, path=ctx.path, line=line)
            cues.append(VisemeCue(viseme=viseme, start_ms=cursor, duration_ms=duration,
                                  origin=ctx.origin(line)))
            cursor += duration
        visemes = tuple(cues)
    audio = None
    if said.audio is not None:
        audio = resolve_inside(ctx.base_dir, said.audio, what="say: audio", path=ctx.path,
                               line=said.line)
    text = said.text
    if said.transcript is not None:
        transcript = resolve_inside(ctx.base_dir, said.transcript, what="say: transcript",
                                    path=ctx.path, line=said.line)
        text = read_text(transcript, what="transcript", path=ctx.path, line=said.line)
    return SpeechSpec(audio=audio, text=text, visemes=visemes, start_ms=said.at_ms,
                      origin=ctx.origin(said.line), lang=said.lang, voice=said.voice,
                      rate=said.rate, pitch=said.pitch, style=said.style)
