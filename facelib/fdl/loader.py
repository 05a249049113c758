"""``load`` / ``loads``: run an FDL storyboard in the sandbox and build its ``Storyboard``.

One file may use the thesis's format (``FDL = {...}`` naming ``.sb`` sub-scripts, or the
``expressions`` / ``eyes`` / ``Sentence`` lists themselves), the modern storyboard functions
(``say``, ``show``, ``look``, ``define_expression``, ``define_gaze``), or both. Globals
``fps`` (default 25), ``seed`` (default 0), ``output``, ``face`` (a face definition JSON,
e.g. one made by ``facelib face setup``, or a bundled character's name: ``face = "ben"``),
``hair`` (a hair style of that face; checked against the face's styles when the face is
loaded) and ``language`` (default English; the language of speech that names none) set the
storyboard options; every name is declared in
:mod:`facelib.fdl.functions`. Each syntax converts to cues in its own module
(:mod:`~facelib.fdl.thesis_cues`, :mod:`~facelib.fdl.modern_cues`); this module runs the
script, reads the settings and merges the two.
"""

from __future__ import annotations

import logging
import math
import re
import warnings
from pathlib import Path
from typing import TypeVar

from facelib.checks import did_you_mean, is_bare_name
from facelib.cues import Character, ExpressionCue, GazeCue, SpeechSpec, Storyboard
from facelib.errors import FdlError, FdlWarning, ParameterError
from facelib.fdl import modern_cues, thesis_cues
from facelib.fdl.camera import camera_cues
from facelib.fdl.cast import check_who, part_of, scene_camera, single_camera
from facelib.fdl.context import Context, line_of_name
from facelib.fdl.functions import SETTINGS, function_names, known_globals, read_calls
from facelib.fdl.modern import ModernParts
from facelib.fdl.moods import mood_cues
from facelib.fdl.paths import read_text, resolve_inside
from facelib.fdl.sandbox import WHITELIST, ChunkResult, Sandbox
from facelib.fdl.thesis import SCRIPT_GLOBALS, check_fdl_table
from facelib.fdl.thesis_cues import ThesisList
from facelib.fdl.values import LuaTable, LuaValue, to_python

__all__ = ["load", "loads"]

log = logging.getLogger("facelib.fdl")

DEFAULT_FPS = 25.0
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
        raise ParameterError(f"storyboard text must be a str, got {type(text).__name__}")
    folder = None if base_dir is None else Path(base_dir)
    if folder is not None and not folder.is_dir():
        raise ParameterError(f"base_dir {str(base_dir)!r} is not a folder")
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
    chunk = box.run(text, path=name, seed=first, functions=function_names())
    script_seed = _global(chunk, "seed")
    if seed is None and script_seed is not None:
        wanted = _check_seed(script_seed, path=name, line=_line(text, "seed"))
        if wanted != first:  # run again so math.random follows the script's own seed
            box.printed.clear()
            chunk = box.run(text, path=name, seed=wanted, functions=function_names())
        seed = wanted
    for message in box.printed:
        log.info("%s: %s", name, message)
    try:
        return _build(chunk, text, name=name, base_dir=base_dir, seed=seed or 0, file=file, box=box)
    finally:
        box.collect()


def _line(text: str, name: str) -> int | None:
    return line_of_name(text, name)


def _global(chunk: ChunkResult, key: str) -> LuaValue:
    value = chunk.env[key]
    return None if value is None else to_python(value, chunk.lines, path=chunk.path)


def _check_globals(chunk: ChunkResult, text: str) -> None:
    """An unknown global close to a setting (``fsp = 30``) is refused when it is very close
    (a misspelt setting would otherwise be silently ignored) and warned about otherwise;
    the script's own helpers (functions) and variables far from any name pass."""
    from lupa import lua54

    known = {*WHITELIST, *known_globals()}
    settings = (*SETTINGS, *SCRIPT_GLOBALS.values(), "FDL")
    for key, value in chunk.env.items():
        if not isinstance(key, str) or key in known or lua54.lua_type(value) == "function":
            continue
        line = _line(text, key)
        hint = did_you_mean(key, settings, cutoff=0.75)
        if hint:
            raise FdlError(f"unknown setting {key!r}{hint}", path=chunk.path, line=line)
        hint = did_you_mean(key, settings, cutoff=0.6)
        if hint:
            where = chunk.path if line is None else f"{chunk.path}:{line}"
            warnings.warn(f"{where}: global {key!r} is not a setting and is ignored{hint}",
                          FdlWarning, stacklevel=2)


def _fps(chunk: ChunkResult, text: str, name: str) -> float:
    fps = _global(chunk, "fps")
    if fps is None:
        return DEFAULT_FPS
    if (
        isinstance(fps, bool)
        or not isinstance(fps, int | float)
        or not (math.isfinite(fps) and _MIN_FPS <= fps <= _MAX_FPS)
    ):
        raise FdlError(
            f"fps must be a number from {_MIN_FPS:g} to {_MAX_FPS:g}; got {fps!r}",
            path=name,
            line=_line(text, "fps"),
        )
    return float(fps)


def _hair(chunk: ChunkResult, text: str, name: str) -> tuple[str | None, dict[str, int]]:
    """The ``hair`` global (a style name, or None) and ``{"hair": line}`` when it is set."""
    hair = _global(chunk, "hair")
    line = _line(text, "hair")
    if hair is None:
        return None, {}
    if not (isinstance(hair, str) and hair.strip()):
        raise FdlError(f'hair must be a hair style name like "long" (or "none"); got {hair!r}',
                       path=name, line=line)
    return hair.strip(), {} if line is None else {"hair": line}


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
    fps = _fps(chunk, text, name)
    ctx = Context(path=name, source=text, base_dir=base_dir, fps=fps)
    fdl_value = _global(chunk, "FDL")
    fdl = None if fdl_value is None else check_fdl_table(fdl_value, ctx, _line(text, "FDL"))
    fdl_line = fdl_value.line if isinstance(fdl_value, LuaTable) else None
    lists = _thesis_lists(chunk, fdl, fdl_line, ctx, seed=seed, box=box)
    parts = read_calls(_calls(chunk), ctx)
    check_who(parts, ctx)
    if parts.characters:
        return _cast(chunk, parts, has_thesis=bool(lists) or fdl is not None, fdl=fdl,
                     fdl_line=fdl_line, ctx=ctx, seed=seed, file=file)
    # thesis lists run from 0; the modern syntax's cues without ``at`` follow on
    expressions = thesis_cues.expression_cues(lists.get("expressions"))
    gaze = thesis_cues.gaze_cues(lists.get("eyes"))
    speech = _speech(fdl, fdl_line, lists.get("Sentence"), parts, ctx)
    output = _output(chunk, fdl, fdl_line, ctx)
    language = _language(chunk, ctx)
    if output is not None:
        _check_output(output, inputs=(file, *_inputs_of(speech)), ctx=ctx)
    face_value = _global(chunk, "face")
    face_line = _line(text, "face")
    face = (None if face_value is None
            else _face_file(face_value, ctx, what="face", line=face_line))
    hair, lines = _hair(chunk, text, name)
    lines = {**lines, **({} if face is None or face_line is None else {"face": face_line})}
    return Storyboard(
        path=file,
        fps=fps,
        language=language,
        seed=seed,
        speech=speech,
        expressions=_by_start((*expressions, *modern_cues.expression_cues(
            parts.expressions, ctx, after_ms=_end(expressions)))),
        gaze=_by_start((*gaze, *modern_cues.gaze_cues(parts.gaze, ctx, after_ms=_end(gaze)))),
        expression_defs=parts.expression_defs,
        gaze_defs=parts.gaze_defs,
        output=output,
        expression_mixes=parts.expression_mixes,
        face=face,
        hair=hair,
        setting_lines=lines,
        camera=single_camera(camera_cues(parts.camera, ctx), ctx),
        moods=mood_cues(parts.moods, ctx),
    )


def _face_file(value: object, ctx: Context, *, what: str, line: int | None) -> Path | str:
    """The face definition a storyboard names (``face = ...``, a character's ``face``):
    a file inside the storyboard's folder, played through :func:`facelib.clip.styled_face`;
    or a bundled character's name (a bare word naming no file there: ``face = "ben"``), kept
    as the string and resolved, with a did-you-mean at this line, when the face is loaded
    (:func:`facelib.clip.storyboard_definition`)."""
    if (isinstance(value, str) and is_bare_name(value)
            and (ctx.base_dir is None or not (ctx.base_dir / value).exists())):
        return value
    return resolve_inside(ctx.base_dir, value, what=what, path=ctx.path, line=line)


def _part_seed(seed: int, index: int) -> int:
    """The seed of the ``index``-th character's part: the storyboard's for the first, the
    next ones after it (so two characters never blink together by construction)."""
    return (seed + index) % 2**63


def _cast(
    chunk: ChunkResult, parts: ModernParts, *, has_thesis: bool,
    fdl: dict[str, str | None] | None, fdl_line: int | None, ctx: Context, seed: int,
    file: Path | None,
) -> Storyboard:
    """The storyboard of ``characters { ... }``: one part per character (see
    :mod:`facelib.fdl.cast`), the camera cutting between them."""
    first = parts.characters[0].line
    if has_thesis:
        raise FdlError("the thesis's FDL table and lists have no characters; with characters "
                       "use say, show, look and mood with who = ...", path=ctx.path, line=first)
    for setting in ("face", "hair"):
        if _global(chunk, setting) is not None:
            raise FdlError(f"{setting}: with characters, give each character's {setting} in "
                           f'characters {{ name = {{ {setting} = "..." }} }}',
                           path=ctx.path, line=_assignment_line(ctx.source, setting))
    language = _language(chunk, ctx)
    characters = []
    for index, draft in enumerate(parts.characters):
        own = part_of(parts, draft.name, ctx)
        face = (None if draft.face is None else _face_file(
            draft.face, ctx, what=f"characters: {draft.name}: face", line=draft.line))
        part = Storyboard(
            path=file, fps=ctx.fps, language=language, seed=_part_seed(seed, index),
            speech=None if own.speech is None else modern_cues.speech_spec(own.speech, ctx),
            turns=tuple(modern_cues.speech_spec(t, ctx) for t in own.turns),
            expressions=_by_start(modern_cues.expression_cues(own.expressions, ctx)),
            gaze=_by_start(modern_cues.gaze_cues(own.gaze, ctx)),
            expression_defs=parts.expression_defs, gaze_defs=parts.gaze_defs,
            expression_mixes=parts.expression_mixes, face=face, hair=draft.hair,
            setting_lines={} if draft.line is None else {
                k: draft.line for k, v in (("hair", draft.hair), ("face", face)) if v},
            moods=mood_cues(own.moods, ctx))
        characters.append(Character(draft.name, part, face=face, hair=draft.hair,
                                    origin=ctx.origin(draft.line)))
    output = _output(chunk, fdl, fdl_line, ctx)
    if output is not None:
        inputs = [file, *(p for c in characters for s in (c.part.speech, *c.part.turns)
                          for p in _inputs_of(s))]
        _check_output(output, inputs=tuple(inputs), ctx=ctx)
    return Storyboard(
        path=file, fps=ctx.fps, seed=seed, language=language, output=output,
        expression_defs=parts.expression_defs, gaze_defs=parts.gaze_defs,
        expression_mixes=parts.expression_mixes,
        camera=scene_camera(camera_cues(parts.camera, ctx), ctx),
        characters=tuple(characters))


def _assignment_line(text: str, name: str) -> int | None:
    """The line of a top-level ``name = ...`` (one that starts a line, not a table field
    such as a character's ``hair = ...``), else the first ``name =`` anywhere."""
    pattern = re.compile(rf"^\s*{re.escape(name)}\s*=(?!=)")
    for number, line in enumerate(text.splitlines(), start=1):
        if pattern.match(line):
            return number
    return _line(text, name)


def _language(chunk: ChunkResult, ctx: Context) -> str | None:
    """The ``language`` setting, stripped (None when absent)."""
    language = _global(chunk, "language")
    if language is not None and not (isinstance(language, str) and language.strip()):
        raise FdlError(f"language must be a language code like \"pt\"; got {language!r}",
                       path=ctx.path, line=_line(ctx.source, "language"))
    return language.strip() if isinstance(language, str) else None


OUTPUT_SUFFIXES = (".fap", ".mp4", ".gif")
"""What a storyboard's ``output`` may name: the files facelib writes."""


def _inputs_of(speech: SpeechSpec | None) -> tuple[Path, ...]:
    if speech is None or speech.audio is None:
        return ()
    return (Path(speech.audio),)


def _check_output(output: Path, *, inputs: tuple[Path | None, ...], ctx: Context) -> None:
    """A storyboard may only name an output facelib writes: a known suffix, not a hidden
    file, not the storyboard itself or a file it reads, in a folder that exists (a
    storyboard never makes folders)."""
    line = _line(ctx.source, "output")
    if not output.parent.is_dir():
        base = ctx.base_dir.resolve() if ctx.base_dir is not None else output.parent
        shown = (output.parent.relative_to(base).as_posix()
                 if output.parent.is_relative_to(base) else str(output.parent))
        raise FdlError(f"output {output.name!r}: the folder {shown!r} does not exist in the "
                       "storyboard's folder (a storyboard never makes folders)",
                       path=ctx.path, line=line)
    if output.suffix.lower() not in OUTPUT_SUFFIXES:
        raise FdlError(f"output {output.name!r} must end in one of {', '.join(OUTPUT_SUFFIXES)}",
                       path=ctx.path, line=line)
    if output.name.startswith("."):
        raise FdlError(f"output {output.name!r} must not be a hidden file", path=ctx.path,
                       line=line)
    if any(source is not None and output == source.resolve() for source in inputs):
        raise FdlError(f"output {output.name!r} would overwrite one of the storyboard's inputs",
                       path=ctx.path, line=line)


def _calls(chunk: ChunkResult) -> list[tuple[str, LuaValue, int | None, int]]:
    """The storyboard-function calls the sandbox recorded: (function, argument, line,
    number of arguments)."""
    calls = []
    for i in range(1, len(chunk.calls) + 1):
        record = chunk.calls[i]
        line = record[3] if isinstance(record[3], int) and record[3] > 0 else None
        argument = to_python(record[2], chunk.lines, path=chunk.path, line=line)
        calls.append((str(record[1]), argument, line, int(record[4])))
    return calls


def _thesis_lists(
    chunk: ChunkResult, fdl: dict[str, str | None] | None, fdl_line: int | None, ctx: Context,
    *, seed: int, box: Sandbox,
) -> dict[str, ThesisList]:
    """The thesis lists given in this file, or in the sub-scripts the FDL table names."""
    lists: dict[str, ThesisList] = {}
    for list_name in SCRIPT_GLOBALS.values():
        value = _global(chunk, list_name)
        if value is not None:
            lists[list_name] = ThesisList(value, ctx)
    for field_name, list_name in SCRIPT_GLOBALS.items():
        script = None if fdl is None else fdl.get(field_name)
        if script is None:
            continue
        where = ctx.line_of(field_name, after=fdl_line)
        if list_name in lists:
            raise FdlError(
                f"{list_name} is given twice: in this file and through FDL.{field_name}",
                path=ctx.path,
                line=where,
            )
        lists[list_name] = _sub_script(script, list_name, ctx, where, seed=seed, box=box)
    return lists


def _end(cues: tuple[ExpressionCue, ...] | tuple[GazeCue, ...]) -> int:
    """End (ms) of the last of sequential cues, 0 for none."""
    return cues[-1].end_ms if cues else 0


_Cue = TypeVar("_Cue", ExpressionCue, GazeCue)


def _by_start(cues: tuple[_Cue, ...]) -> tuple[_Cue, ...]:
    """Cues in start order; cues starting together keep their order."""
    return tuple(sorted(cues, key=lambda c: c.start_ms))


def _sub_script(
    value: str, list_name: str, ctx: Context, line: int | None, *, seed: int, box: Sandbox
) -> ThesisList:
    """Run the ``.sb`` sub-script ``value`` and return the list ``list_name`` it defines."""
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
    return ThesisList(to_python(found, chunk.lines, path=str(file)), sub_ctx)


def _speech(
    fdl: dict[str, str | None] | None,
    fdl_line: int | None,
    sentence: ThesisList | None,
    parts: ModernParts,
    ctx: Context,
) -> SpeechSpec | None:
    """The speech of ``say`` or of the thesis's FDL table and Sentence list (not both)."""
    thesis = thesis_cues.speech_spec(fdl, fdl_line, sentence, ctx)
    said = parts.speech
    if said is None:
        return thesis
    if thesis is not None:
        raise FdlError(
            "speech is given twice: by say and by the FDL table / Sentence list",
            path=ctx.path,
            line=said.line,
        )
    return modern_cues.speech_spec(said, ctx)


def _output(
    chunk: ChunkResult, fdl: dict[str, str | None] | None, fdl_line: int | None, ctx: Context
) -> Path | None:
    """The ``.fap`` file to write: global ``output`` or ``FDL.output`` (``"none"``: no
    file), inside the storyboard's folder."""
    value = _global(chunk, "output")
    line = _line(ctx.source, "output")
    if fdl is not None and "output" in fdl:
        if value is not None:
            raise FdlError("output is given twice: as a global and in FDL", path=ctx.path,
                           line=line)
        value, line = fdl["output"], ctx.line_of("output", after=fdl_line)
    elif isinstance(value, str) and value.strip().lower() == "none":
        value = None
    if value is None:
        return None
    return resolve_inside(ctx.base_dir, value, what="output", path=ctx.path, line=line,
                          must_exist=False)
