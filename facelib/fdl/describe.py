"""A plain-text listing of a storyboard's cues (what ``facelib check`` prints)."""

from __future__ import annotations

from facelib.cues import Origin, SpeechSpec, Storyboard

__all__ = ["describe"]


def _where(origin: Origin | None) -> str:
    return "" if origin is None else f"  ({origin[0]}:{origin[1]})"


def _span(start_ms: int, duration_ms: int) -> str:
    return f"{start_ms / 1000:8.3f}s +{duration_ms / 1000:.3f}s"


def describe(sb: Storyboard) -> str:
    """Lines listing fps, seed, output, speech, stored visemes, definitions and every cue
    with its time span (seconds) and origin ``file:line``; each character of a storyboard
    with characters, then its own speech and cues."""
    out = [
        f"storyboard: {sb.path or '<string>'}",
        f"fps: {sb.fps:g}  seed: {sb.seed}  output: {sb.output or 'none'}"
        + (f"  face: {sb.face}" if sb.face is not None else "")
        + (f"  hair: {sb.hair}" if sb.hair is not None else ""),
    ]
    out.extend(_speech(sb))
    for name, values in sb.expression_defs.items():
        out.append(f"define expression {name}: {dict(values)}")
    for name, mix in sb.expression_mixes.items():
        out.append(f"define expression {name}: mix {dict(mix)}")
    for name, params in sb.gaze_defs.items():
        out.append(f"define gaze {name}: {dict(params)}")
    out.extend(_cues(sb))
    for c in sb.camera:
        shot = c.framing if c.who is None else f"{c.who} ({c.framing or 'render framing'})"
        out.append(f"  camera   {_span(c.start_ms, c.duration_ms)}  {shot}"
                   f"{' (cut)' if c.duration_ms == 0 else ''}{_where(c.origin)}")
    for character in sb.characters:
        out.append(f"character {character.name}: face {character.face or 'bundled'}, hair "
                   f"{character.hair or 'its own'}{_where(character.origin)}")
        out.extend(_speech(character.part))
        out.extend(_cues(character.part))
    return "\n".join(out)


def _speech(sb: Storyboard) -> list[str]:
    """The speech (and the turns after it) with stored visemes, one per line."""
    return [line for s in (sb.speech, *sb.turns) if s is not None for line in _said(s)]


def _said(s: SpeechSpec) -> list[str]:
    """One speech and its stored visemes, one per line."""
    text = "" if s.text is None else repr(s.text if len(s.text) < 60 else s.text[:57] + "...")
    out = [(f"speech at {s.start_ms / 1000:.3f}s: audio={s.audio or 'none'} "
            f"text={text or 'none'}{_where(s.origin)}")]
    out.extend(
        f"  viseme   {_span(v.start_ms, v.duration_ms)}  {v.viseme}{_where(v.origin)}"
        for v in s.visemes or ()
    )
    return out


def _cues(sb: Storyboard) -> list[str]:
    """The expression and gaze cues, one per line."""
    out = []
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
    return out
