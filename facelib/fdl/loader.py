"""``load`` / ``loads``: run an FDL storyboard in the sandbox and build its ``Storyboard``.

One file may use the thesis's format (``FDL = {...}`` naming ``.sb`` sub-scripts, or the
``expressions`` / ``eyes`` / ``Sentence`` lists themselves), the modern storyboard functions
(``say``, ``show``, ``look``, ``define_expression``, ``define_gaze``), or both. Globals
``fps`` (default 25), ``seed`` (default 0) and ``output`` set the storyboard options.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

from facelib.checks import did_you_mean
from facelib.cues import ExpressionCue, GazeCue, SpeechSpec, Storyboard, VisemeCue
from facelib.errors import FdlError
from facelib.fdl.context import Context, line_of_name
from facelib.fdl.modern import FUNCTIONS, DraftCue, DraftSpeech, ModernParts, read_calls
from facelib.fdl.paths import read_text, resolve_inside
from facelib.fdl.sandbox import WHITELIST, ChunkResult, Sandbox
from facelib.fdl.thesis import SCRIPT_GLOBALS, check_fdl_table, sequence
from facelib.fdl.values import LuaTable, to_python
from facelib.fdl.visemes import check_viseme

__all__ = ["load", "loads"]

log = logging.getLogger("facelib.fdl")

DEFAULT_FPS = 25.0
SETTINGS = ("fps", "seed", "output", "FDL", "expressions", "eyes", "Sentence")
"""Globals a storyboard may set (besides its own helpers and variables)."""
_MIN_FPS = 1.0
_MAX_FPS = 1000.0


def load(
    path: str | Path,
    *,
    seed: int | None = None,
    sandbox: Sandbox | None = None,
) -> Storyboard:
    """Load the storyboard file ``path`` (``.fdl`` or ``.sb``).

    File names in the script resolve relative to the file's folder and may not leave it.
    ``seed`` overrides the script's ``seed``; ``sandbox`` reuses a :class:`Sandbox`
    (a fresh one by default). Raises FdlError with file and line on any problem.
    """
    file = Path(path)
    try:
        file = file.resolve(strict=True)
    except OSError:
        raise FdlError(f"storyboard {str(path)!r} not found") from None
    if not file.is_file():
        raise FdlError(f"storyboard {str(path)!r} is not a file")
    text = read_text(file, what="storyboard", path=str(file), line=None)
    return _load(text, name=str(file), base_dir=file.parent, seed=seed, file=file, sandbox=sandbox)


def loads(
    text: str,
    *,
    name: str = "<string>",
    base_dir: str | Path | None = None,
    seed: int | None = None,
    sandbox: Sandbox | None = None,
) -> Storyboard:
    """Load a storyboard from its text; ``name`` is shown in errors and cue origins.

    File names in the script resolve relative to ``base_dir`` (none allowed without it).
    """
    if not isinstance(text, str):
        raise FdlError(f"storyboard text must be a str, got {type(text).__name__}", path=name)
    folder = None if base_dir is None else Path(base_dir)
    if folder is not None and not folder.is_dir():
        raise FdlError(f"base_dir {str(base_dir)!r} is not a folder", path=name)
    return _load(text, name=name, base_dir=folder, seed=seed, file=None, sandbox=sandbox)


def _check_seed(value: object, *, path: str, line: int | None) -> int:
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**63:
        raise FdlError(
            f"seed must be an integer from 0 to 2^63-1; got {value!r}", path=path, line=line
        )
    return value


def _load(
    text: str,
    *,
    name: str,
    base_dir: Path | None,
    seed: int | None,
    file: Path | None,
    sandbox: Sandbox | None,
) -> Storyboard:
    box = sandbox or Sandbox()
    if seed is not None:
        seed = _check_seed(seed, path=name, line=None)
    first = seed if seed is not None else 0
    box.printed.clear()
    chunk = box.run(text, path=name, seed=first, functions=FUNCTIONS)
    script_seed = _global(chunk, "seed")
    if seed is None and script_seed is not None:
        wanted = _check_seed(script_seed, path=name, line=_line(text, "seed"))
        if wanted != first:  # run again so math.random follows the script's own seed
            box.printed.clear()
            chunk = box.run(text, path=name, seed=wanted, functions=FUNCTIONS)
        seed = wanted
    for message in box.printed:
        log.info("%s: %s", name, message)
    try:
        return _build(chunk, text, name=name, base_dir=base_dir, seed=seed or 0, file=file, box=box)
    finally:
        box.collect()


def _line(text: str, name: str) -> int | None:
    return line_of_name(text, name)


def _global(chunk: ChunkResult, key: str) -> Any:
    value = chunk.env[key]
    return None if value is None else to_python(value, chunk.lines, path=chunk.path)


def _check_globals(chunk: ChunkResult, text: str) -> None:
    from lupa import lua54

    known = {*WHITELIST, *FUNCTIONS, *SETTINGS}
    for key, value in chunk.env.items():
        if not isinstance(key, str) or key in known:
            continue
        if lua54.lua_type(value) == "function":
            continue
        hint = did_you_mean(key, SETTINGS, cutoff=0.75)
        if hint:
            raise FdlError(f"unknown setting {key!r}{hint}", path=chunk.path, line=_line(text, key))


def _build(
    chunk: ChunkResult,
    text: str,
    *,
    name: str,
    base_dir: Path | None,
    seed: int,
    file: Path | None,
    box: Sandbox,
) -> Storyboard:
    _check_globals(chunk, text)
    fps = _global(chunk, "fps")
    fps_line = _line(text, "fps")
    if fps is None:
        fps = DEFAULT_FPS
    if (
        isinstance(fps, bool)
        or not isinstance(fps, int | float)
        or not (math.isfinite(fps) and _MIN_FPS <= fps <= _MAX_FPS)
    ):
        raise FdlError(
            f"fps must be a number from {_MIN_FPS:g} to {_MAX_FPS:g}; got {fps!r}",
            path=name,
            line=fps_line,
        )
    ctx = Context(path=name, source=text, base_dir=base_dir, fps=float(fps))
    fdl_value = _global(chunk, "FDL")
    fdl = None if fdl_value is None else check_fdl_table(fdl_value, ctx, _line(text, "FDL"))
    fdl_line = fdl_value.line if isinstance(fdl_value, LuaTable) else None

    # Lists given in this file, or in the sub-scripts the FDL table names.
    lists: dict[str, tuple[Any, Context]] = {}
    for list_name in SCRIPT_GLOBALS.values():
        value = _global(chunk, list_name)
        if value is not None:
            lists[list_name] = (value, ctx)
    if fdl is not None:
        for field_name, list_name in SCRIPT_GLOBALS.items():
            script = fdl.get(field_name)
            if script is None:
                continue
            where = ctx.line_of(field_name, after=fdl_line)
            if list_name in lists:
                raise FdlError(
                    f"{list_name} is given twice: in this file and through FDL.{field_name}",
                    path=name,
                    line=where,
                )
            lists[list_name] = _sub_script(
                script, list_name, ctx, where, seed=seed, box=box
            )

    calls = []
    for i in range(1, len(chunk.calls) + 1):
        record = chunk.calls[i]
        line = record[3] if isinstance(record[3], int) and record[3] > 0 else None
        calls.append(
            (
                str(record[1]),
                to_python(record[2], chunk.lines, path=name, line=line),
                line,
                int(record[4]),
            )
        )
    parts = read_calls(calls, ctx)

    expressions = _schedule_expressions(lists.get("expressions"), parts.expressions, ctx)
    gaze = _schedule_gaze(lists.get("eyes"), parts.gaze, ctx)
    speech = _speech(fdl, fdl_line, lists.get("Sentence"), parts, ctx)
    output_value = _global(chunk, "output")
    output_line = _line(text, "output")
    if fdl is not None and "output" in fdl:
        if output_value is not None:
            raise FdlError(
                "output is given twice: as a global and in FDL", path=name, line=output_line
            )
        output_value, output_line = fdl["output"], ctx.line_of("output", after=fdl_line)
    elif isinstance(output_value, str) and output_value.strip().lower() == "none":
        output_value = None
    output = (
        None
        if output_value is None
        else resolve_inside(
            base_dir, output_value, what="output", path=name, line=output_line, must_exist=False
        )
    )
    if output is not None:
        _check_output(output, inputs=(file, *_inputs_of(speech)), path=name, line=output_line)
    return Storyboard(
        path=file,
        fps=float(fps),
        seed=seed,
        speech=speech,
        expressions=expressions,
        gaze=gaze,
        expression_defs=parts.expression_defs,
        gaze_defs=parts.gaze_defs,
        output=output,
        expression_mixes=parts.expression_mixes,
    )


OUTPUT_SUFFIXES = (".fap", ".mp4", ".gif")
"""What a storyboard's ``output`` may name: the files facelib writes."""


def _inputs_of(speech: SpeechSpec | None) -> tuple[Path, ...]:
    if speech is None or speech.audio is None:
        return ()
    return (Path(speech.audio),)


def _check_output(output: Path, *, inputs: tuple[Path | None, ...], path: str,
                  line: int | None) -> None:
    """A storyboard may only name an output facelib writes: a known suffix, not a hidden
    file, not the storyboard itself or a file it reads."""
    if output.suffix.lower() not in OUTPUT_SUFFIXES:
        raise FdlError(f"output {output.name!r} must end in one of {', '.join(OUTPUT_SUFFIXES)}",
                       path=path, line=line)
    if output.name.startswith("."):
        raise FdlError(f"output {output.name!r} must not be a hidden file", path=path, line=line)
    if any(source is not None and output == source.resolve() for source in inputs):
        raise FdlError(f"output {output.name!r} would overwrite one of the storyboard's inputs",
                       path=path, line=line)


def _sub_script(
    value: str, list_name: str, ctx: Context, line: int | None, *, seed: int, box: Sandbox
) -> tuple[Any, Context]:
    file = resolve_inside(
        ctx.base_dir, value, what=f"script for {list_name}", path=ctx.path, line=line
    )
    text = read_text(file, what="script", path=ctx.path, line=line)
    box.printed.clear()
    chunk = box.run(text, path=str(file), seed=seed)
    for message in box.printed:
        log.info("%s: %s", file, message)
    sub_ctx = Context(path=str(file), source=text, base_dir=ctx.base_dir, fps=ctx.fps)
    found = chunk.env[list_name]
    if found is None:
        names = [k for k in chunk.env if isinstance(k, str) and k not in WHITELIST]
        raise FdlError(
            f"script does not define the list {list_name!r}{did_you_mean(list_name, names)}",
            path=str(file),
        )
    return to_python(found, chunk.lines, path=str(file)), sub_ctx


def _origin(ctx: Context, line: int | None) -> tuple[str, int] | None:
    return None if line is None else (ctx.path, int(line))


def _schedule(
    given: tuple[Any, Context] | None,
    drafts: list[DraftCue],
    ctx: Context,
    *,
    list_name: str,
    min_len: int,
    max_len: int | None,
) -> list[tuple[DraftCue, Context, int]]:
    """Thesis entries from 0 one after another, then drafts (open starts follow on)."""
    out: list[tuple[DraftCue, Context, int]] = []
    cursor = 0
    if given is not None:
        value, sub_ctx = given
        for e in sequence(
            value,
            sub_ctx,
            list_name=list_name,
            min_len=min_len,
            max_len=max_len,
            line=value.line if isinstance(value, LuaTable) else None,
        ):
            draft = DraftCue(
                name=e.name, args=e.args, at_ms=e.start_ms, duration_ms=e.duration_ms, line=e.line
            )
            out.append((draft, sub_ctx, e.start_ms))
            cursor = e.start_ms + e.duration_ms
    for d in drafts:
        start = cursor if d.at_ms is None else d.at_ms
        out.append((d, ctx, start))
        cursor = start + d.duration_ms
    out.sort(key=lambda item: item[2])
    return out


def _schedule_expressions(
    given: tuple[Any, Context] | None, drafts: list[DraftCue], ctx: Context
) -> tuple[ExpressionCue, ...]:
    return tuple(
        ExpressionCue(
            name=d.name,
            start_ms=start,
            duration_ms=d.duration_ms,
            intensity=d.intensity,
            ramp_in_ms=d.ramp_in_ms,
            ramp_out_ms=d.ramp_out_ms,
            origin=_origin(c, d.line),
        )
        for d, c, start in _schedule(
            given, drafts, ctx, list_name="expressions", min_len=2, max_len=2
        )
    )


def _schedule_gaze(
    given: tuple[Any, Context] | None, drafts: list[DraftCue], ctx: Context
) -> tuple[GazeCue, ...]:
    return tuple(
        GazeCue(
            behaviour=d.name,
            args=d.args,
            start_ms=start,
            duration_ms=d.duration_ms,
            origin=_origin(c, d.line),
        )
        for d, c, start in _schedule(given, drafts, ctx, list_name="eyes", min_len=2, max_len=None)
    )


def _speech(
    fdl: dict[str, str | None] | None,
    fdl_line: int | None,
    sentence: tuple[Any, Context] | None,
    parts: ModernParts,
    ctx: Context,
) -> SpeechSpec | None:
    said: DraftSpeech | None = parts.speech
    fdl_speech = fdl is not None and (
        fdl.get("speakSound") is not None or fdl.get("speakText") is not None
    )
    if said is not None and (fdl_speech or sentence is not None):
        raise FdlError(
            "speech is given twice: by say and by the FDL table / Sentence list",
            path=ctx.path,
            line=said.line,
        )
    visemes: tuple[VisemeCue, ...] | None = None
    if said is not None:
        start = said.at_ms
        if said.visemes is not None:
            cues = []
            cursor = start
            for viseme, duration, line in said.visemes:
                check_viseme(viseme, path=ctx.path, line=line)
                cues.append(
                    VisemeCue(
                        viseme=viseme,
                        start_ms=cursor,
                        duration_ms=duration,
                        origin=_origin(ctx, line),
                    )
                )
                cursor += duration
            visemes = tuple(cues)
        audio = (
            None
            if said.audio is None
            else resolve_inside(
                ctx.base_dir, said.audio, what="say: audio", path=ctx.path, line=said.line
            )
        )
        text = said.text
        if said.transcript is not None:
            transcript = resolve_inside(
                ctx.base_dir, said.transcript, what="say: transcript", path=ctx.path, line=said.line
            )
            text = read_text(transcript, what="transcript", path=ctx.path, line=said.line)
        return SpeechSpec(
            audio=audio, text=text, visemes=visemes, start_ms=start, origin=_origin(ctx, said.line)
        )
    if not fdl_speech and sentence is None:
        return None
    if sentence is not None:
        value, sub_ctx = sentence
        cues = []
        for e in sequence(
            value,
            sub_ctx,
            list_name="Sentence",
            min_len=2,
            max_len=2,
            line=value.line if isinstance(value, LuaTable) else None,
        ):
            check_viseme(e.name, path=sub_ctx.path, line=e.line)
            cues.append(
                VisemeCue(
                    viseme=e.name,
                    start_ms=e.start_ms,
                    duration_ms=e.duration_ms,
                    origin=_origin(sub_ctx, e.line),
                )
            )
        visemes = tuple(cues)
    audio = text = None
    if fdl is not None and fdl.get("speakSound") is not None:
        audio = resolve_inside(
            ctx.base_dir,
            fdl["speakSound"],
            what="FDL.speakSound",
            path=ctx.path,
            line=ctx.line_of("speakSound", after=fdl_line),
        )
    if fdl is not None and fdl.get("speakText") is not None:
        where = ctx.line_of("speakText", after=fdl_line)
        file = resolve_inside(
            ctx.base_dir, fdl["speakText"], what="FDL.speakText", path=ctx.path, line=where
        )
        text = read_text(file, what="FDL.speakText", path=ctx.path, line=where).strip()
    return SpeechSpec(
        audio=audio,
        text=text,
        visemes=visemes,
        start_ms=0,
        origin=_origin(ctx, fdl_line)
        if fdl is not None
        else (visemes[0].origin if visemes else None),
    )
