"""A plain-text listing of a storyboard's cues (what ``facelib check`` prints)."""

from __future__ import annotations

from facelib.cues import Origin, Storyboard

__all__ = ["describe"]


def _where(origin: Origin | None) -> str:
    return "" if origin is None else f"  ({origin[0]}:{origin[1]})"


def _span(start_ms: int, duration_ms: int) -> str:
    return f"{start_ms / 1000:8.3f}s +{duration_ms / 1000:.3f}s"


def describe(sb: Storyboard) -> str:
    """Lines listing fps, seed, output, speech, stored visemes, definitions and every cue
    with its time span (seconds) and origin ``file:line``."""
    out = [
        f"storyboard: {sb.path or '<string>'}",
        f"fps: {sb.fps:g}  seed: {sb.seed}  output: {sb.output or 'none'}"
        + (f"  face: {sb.face}" if sb.face is not None else "")
        + (f"  hair: {sb.hair}" if sb.hair is not None else ""),
    ]
    s = sb.speech
    if s is not None:
        text = "" if s.text is None else repr(s.text if len(s.text) < 60 else s.text[:57] + "...")
        out.append(
            f"speech at {s.start_ms / 1000:.3f}s: audio={s.audio or 'none'} text={text or 'none'}"
            f"{_where(s.origin)}"
        )
        out.extend(
            f"  viseme   {_span(v.start_ms, v.duration_ms)}  {v.viseme}{_where(v.origin)}"
            for v in s.visemes or ()
        )
    for name, values in sb.expression_defs.items():
        out.append(f"define expression {name}: {dict(values)}")
    for name, mix in sb.expression_mixes.items():
        out.append(f"define expression {name}: mix {dict(mix)}")
    for name, params in sb.gaze_defs.items():
        out.append(f"define gaze {name}: {dict(params)}")
    for c in sb.expressions:
        ramps = ""
        if c.ramp_in_ms is not None or c.ramp_out_ms is not None:
            ramps = f" ease {c.ramp_in_ms or 0}/{c.ramp_out_ms or 0} ms"
        out.append(
            f"  express  {_span(c.start_ms, c.duration_ms)}  {c.name} x{c.intensity:g}{ramps}"
            f"{_where(c.origin)}"
        )
    for g in sb.gaze:
        args = ", ".join(repr(a) for a in g.args)
        out.append(
            f"  gaze     {_span(g.start_ms, g.duration_ms)}  {g.behaviour}({args})"
            f"{_where(g.origin)}"
        )
    out.extend(
        f"  camera   {_span(c.start_ms, c.duration_ms)}  {c.framing}"
        f"{' (cut)' if c.duration_ms == 0 else ''}{_where(c.origin)}"
        for c in sb.camera
    )
    return "\n".join(out)
