"""The ``facelib`` command. Every subcommand is a thin layer over the Python API.

Layout: the shared conventions first (console, outputs, exit codes, signals), then one
self-contained block per subcommand: ``_add_NAME(commands)`` declares its arguments next to
``_NAME(args, console)``, which does the work. A new subcommand is one more block plus one
line in :data:`_COMMANDS`.

Exit codes (also in ``docs/getting-started.md``): 0 success; 1 an input or a job failed
(the message names file, line or clip); 2 usage error; 130 interrupted (Ctrl-C); 141 the
reader of stdout went away (``| head``); 143 terminated (SIGTERM). Interrupted and
terminated runs leave no temporary files behind.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import time
import traceback
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import facelib
from facelib.errors import FacelibError, FileError
from facelib.mpeg4 import (
    FapStream,
    fap,
    format_fap,
    read_fap,
    read_fap_file,
    write_fap_complete,
)
from facelib.progress import ConsoleProgress, ProgressCallback

__all__ = ["EXIT_ERROR", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_PIPE", "EXIT_TERMINATED",
           "EXIT_USAGE", "main"]

EXIT_OK = 0
EXIT_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT
EXIT_PIPE = 141  # 128 + SIGPIPE
EXIT_TERMINATED = 143  # 128 + SIGTERM

STDOUT = "-"
RENDER_SUFFIXES = (".mp4", ".gif", ".png")


class Terminated(BaseException):
    """Raised in the main thread when SIGTERM arrives, so ``finally`` blocks and atomic
    writers clean up exactly as for Ctrl-C."""


class UsageError(FacelibError):
    """A command line that cannot work (wrong suffix, missing output): exit status 2."""


@dataclass
class Signals:
    """The stopping signal a command received (SIGINT or SIGTERM), or None."""

    received: int | None = None

    def check(self) -> None:
        """Raise KeyboardInterrupt (SIGINT) or :class:`Terminated` once one was received."""
        if self.received == signal.SIGINT:
            raise KeyboardInterrupt
        if self.received is not None:
            raise Terminated


@dataclass(frozen=True)
class Console:
    """Where a command's messages go: data to stdout, status and progress to stderr.

    quiet: only errors; verbose: also log messages (``facelib.*`` loggers) and tracebacks.
    signals: the Ctrl-C / SIGTERM received, checked again at every progress step.
    """

    quiet: bool = False
    verbose: bool = False
    signals: Signals = field(default_factory=Signals)

    def status(self, message: str) -> None:
        if not self.quiet:
            print(message, file=sys.stderr, flush=True)

    def progress(self, label: str, *, unit: str = "frames", show: bool = True,
                 ) -> ProgressCallback:
        """A progress callback (silent with ``quiet``) that also stops the job at its next
        step once a signal came, should the signal's exception have been swallowed where
        it landed (a destructor, a callback from C)."""
        bar = None if self.quiet or not show else ConsoleProgress(label, unit=unit)

        def report(done: int, total: int) -> None:
            self.signals.check()
            if bar is not None:
                bar(done, total)

        return report


# -- outputs ---------------------------------------------------------------------------


def _check_suffix(out: str, allowed: Sequence[str], what: str) -> None:
    """Refuse an output whose suffix does not match the format the command writes."""
    if out == STDOUT:
        return
    suffix = Path(out).suffix.lower()
    if suffix not in allowed:
        raise UsageError(
            f"{what} writes {' or '.join(allowed)}, not {Path(out).name!r}: "
            f"name the output {Path(out).with_suffix(allowed[0]).name!r} or '-' for stdout"
        )


def _emit_text(text: str, out: str, console: Console, summary: str) -> None:
    """Write ``text`` to the file ``out`` (atomically) or to stdout for ``-``."""
    if out == STDOUT:
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    from facelib.atomic import write_text_atomic

    write_text_atomic(out, text)
    console.status(f"wrote {out} {summary}".rstrip())


def _default_output(story: str, storyboard_output: Path | None, suffix: str) -> Path:
    """Where a storyboard's product goes without ``-o``: its ``output`` (the loader resolved
    it inside the storyboard's folder, like every file a storyboard names), else
    ``STEM{suffix}`` in the current directory."""
    if storyboard_output is None:
        return Path.cwd() / (Path(story).stem + suffix)
    return storyboard_output


def _face_path(face: str | None) -> Path | None:
    """``--face``: a face definition JSON, or the folder ``facelib face setup`` wrote."""
    if face is None:
        return None
    path = Path(face)
    return path / "face.json" if path.is_dir() else path


def _face(face: str | None) -> Any:
    """The Face ``--face`` names, else the default head."""
    from facelib.engine import default_face, load_face

    path = _face_path(face)
    return default_face() if path is None else load_face(path)


def _source(path: str, seed: int | None, console: Console) -> Any:
    """A storyboard's Animation, or a .fap file's stream."""
    if Path(path).suffix.lower() == ".fap":
        return read_fap(path)
    from facelib.animation import run_fdl

    return run_fdl(path, seed=seed,
                   progress=console.progress("animating", unit="stages", show=console.verbose))


# -- info --------------------------------------------------------------------------------


def _add_info(commands: Any) -> None:
    info = commands.add_parser("info", help="summarise a .fap file", parents=[_COMMON])
    info.add_argument("file", help="the .fap file")
    info.add_argument("--strict", action="store_true", help="accept only the standard profile")
    info.set_defaults(run=_info)


def _info(args: argparse.Namespace, console: Console) -> int:
    file = read_fap_file(args.file, strict=args.strict)
    stream = file.stream
    print(f"file:      {args.file}")
    print(f"name:      {file.name}   (version {file.version}, dialect {file.dialect})")
    print(f"fps:       {stream.fps:g}")
    print(f"frames:    {stream.n_frames}")
    print(f"duration:  {stream.duration:.3f} s")
    if file.missing_frames:
        print(f"missing:   {len(file.missing_frames)} frames held from the previous frame")
    active = [f for f in stream.active_faps() if f > 2]
    print(f"active:    {len(active)} FAPs")
    if active:
        print(f"  {'id':>3}  {'name':<22} {'unit':<6} {'min':>8} {'max':>8}  frames set")
    for fid in active:
        column = stream.mask[:, fid - 1]
        values = stream.values[column, fid - 1]
        info = fap(fid)
        print(f"  {fid:>3}  {info.name:<22} {info.fapu:<6} {values.min():>8g} "
              f"{values.max():>8g}  {int(column.sum())}")
    for slot, label in ((0, "viseme"), (1, "expression")):
        if stream.mask[:, slot].any():
            print(f"  FAP {slot + 1} ({label}) set in {int(stream.mask[:, slot].sum())} frames")
    return EXIT_OK


# -- check -------------------------------------------------------------------------------


def _add_check(commands: Any) -> None:
    check = commands.add_parser(
        "check", parents=[_COMMON],
        help="check a storyboard (every generator, no rendering) and list its cues")
    check.add_argument("story", help="the .fdl storyboard")
    check.add_argument("--seed", type=int)
    check.set_defaults(run=_check)


def _check(args: argparse.Namespace, console: Console) -> int:
    from facelib.animation import animate
    from facelib.fdl import describe, load

    storyboard = load(args.story, seed=args.seed)
    animation = animate(storyboard, seed=args.seed)  # what run rejects, check rejects
    print(describe(storyboard))
    target = _default_output(args.story, storyboard.output, ".fap")
    console.status(f"ok: {animation.faps.n_frames} frames at {animation.faps.fps:g} fps "
                   f"({animation.faps.duration:.2f} s); 'facelib run' without -o writes "
                   f"{target}")
    return EXIT_OK


# -- run ---------------------------------------------------------------------------------


def _add_run(commands: Any) -> None:
    run = commands.add_parser("run", help="animate a storyboard into a .fap file",
                              parents=[_COMMON])
    run.add_argument("story", help="the .fdl storyboard")
    run.add_argument("-o", "--output", help="OUT.fap, or - for stdout (default: the "
                     "storyboard's output, else STEM.fap in the current directory)")
    run.add_argument("--seed", type=int, help="seed of the random processes")
    run.add_argument("--dialect", default="standard",
                     choices=("standard", "xface", "greta", "extended"))
    run.set_defaults(run=_run)


def _run(args: argparse.Namespace, console: Console) -> int:
    from facelib.animation import run_fdl

    if args.output is not None:
        _check_suffix(args.output, (".fap",), "run")
    animation = run_fdl(args.story, seed=args.seed,
                        progress=console.progress("animating", unit="stages", show=False))
    out = args.output or str(_default_output(args.story, animation.storyboard.output, ".fap"))
    _check_suffix(out, (".fap",), "run")
    stream = animation.faps
    name = Path(args.story).stem if out == STDOUT else Path(out).stem
    _emit_text(format_fap(stream, dialect=args.dialect, name=name), out, console,
               f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    return EXIT_OK


# -- render and play (one source, or a batch) -------------------------------------------


def _add_render_options(command: argparse.ArgumentParser, *, batch: bool) -> None:
    help_out = ("OUT.mp4, OUT.gif, OUT.png (one frame) or a folder for PNG frames"
                + ("; with several sources or -j, the folder for STEM.mp4 files" if batch
                   else ""))
    command.add_argument("-o", "--output", required=not batch, help=help_out)
    command.add_argument("--face", help="a face definition JSON or a `facelib face setup` "
                         "folder (default: the storyboard's face, else the bundled head)")
    command.add_argument("--width", type=int, default=640)
    command.add_argument("--height", type=int, default=480)
    command.add_argument("--fps", type=float, help="resample to this frame rate")
    command.add_argument("--framing", choices=("face", "head", "bust"), default="face",
                         help="what the camera frames (default: face, brow to chin)")


def _add_render(commands: Any) -> None:
    render = commands.add_parser("render", help="render storyboards (or .fap files) to video",
                                 parents=[_COMMON])
    render.add_argument("sources", nargs="+", metavar="SOURCE", help="STORY.fdl or FILE.fap")
    _add_render_options(render, batch=True)
    render.add_argument("--fap", help="also write the animation's .fap here (one source)")
    render.add_argument("--seed", type=int)
    render.add_argument("-j", "--jobs", type=int,
                        help="render a batch with this many processes (default: CPU count)")
    render.add_argument("--format", default="mp4", choices=("mp4", "gif"),
                        help="what a batch writes per source (default mp4)")
    render.set_defaults(run=_render, audio=None)

    play = commands.add_parser("play", help="render a .fap file, with optional audio",
                               parents=[_COMMON])
    play.add_argument("source", metavar="FILE.fap")
    _add_render_options(play, batch=False)
    play.add_argument("--audio", help="speech audio to mux into the video")
    play.set_defaults(run=_play, fap=None, seed=None)


def _render_one(source_path: str, out: str, args: argparse.Namespace, console: Console) -> int:
    from facelib.rendering.frames import render

    started = time.perf_counter()
    source = _source(source_path, args.seed, console)
    if args.fap is not None:
        _check_suffix(args.fap, (".fap",), "--fap")
        stream = source if isinstance(source, FapStream) else source.faps
        written_faps = write_fap_complete(stream, args.fap)
        console.status(f"wrote {' and '.join(map(str, written_faps))} ({stream.n_frames} "
                       f"frames, {stream.duration:.2f} s)")
    written = render(source, face=_face_path(args.face), out=out, width=args.width,
                     framing=args.framing,
                     height=args.height, audio=args.audio, fps=args.fps,
                     progress=console.progress("rendering"))
    console.status(f"wrote {written} in {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def _render_output(source: str, args: argparse.Namespace) -> str:
    """The output of a one-source render: ``-o``, else the storyboard's ``output`` (a
    ``.fap`` output is written too, beside ``STEM.mp4``), else ``STEM.mp4`` here."""
    if args.output is not None:
        if Path(args.output).suffix:
            _check_suffix(args.output, RENDER_SUFFIXES, "render")
        return str(args.output)
    if Path(source).suffix.lower() == ".fap":
        return str(Path.cwd() / (Path(source).stem + ".mp4"))
    from facelib.fdl import load

    wanted = load(source).output
    out = _default_output(source, wanted, ".mp4")
    if out.suffix.lower() == ".fap":
        if args.fap is None:
            args.fap = str(out)
        out = out.with_suffix(".mp4")
    _check_suffix(str(out), RENDER_SUFFIXES, "render")
    return str(out)


def _render(args: argparse.Namespace, console: Console) -> int:
    if len(args.sources) == 1 and args.jobs is None:
        source = args.sources[0]
        return _render_one(source, _render_output(source, args), args, console)
    if args.output is None:
        raise UsageError("a batch needs an output folder: -o OUT_DIR/")
    if Path(args.output).suffix.lower() in RENDER_SUFFIXES or args.fap is not None:
        raise UsageError(f"a batch writes one file per source into a folder; -o "
                         f"{args.output!r} is a file name (and --fap is for one source)")
    from facelib.batch import render_batch

    results = render_batch(
        args.sources, args.output, jobs=args.jobs, suffix="." + args.format,
        width=args.width, height=args.height, fps=args.fps, seed=args.seed,
        face=_face_path(args.face), progress=console.progress("batch", unit="files"),
    )
    for result in results:
        if result.ok:
            console.status(f"wrote {result.output} in {result.seconds:.1f} s")
        else:
            where = "" if str(Path(result.source).name) in str(result.error) else (
                f"{result.source}: ")
            print(f"facelib: error: {where}{result.error}", file=sys.stderr)
    failed = sum(not r.ok for r in results)
    if failed:
        print(f"facelib: {failed} of {len(results)} failed", file=sys.stderr)
    return EXIT_ERROR if failed else EXIT_OK


def _play(args: argparse.Namespace, console: Console) -> int:
    if Path(args.output).suffix:
        _check_suffix(args.output, RENDER_SUFFIXES, "play")
    return _render_one(args.source, args.output, args, console)


# -- view --------------------------------------------------------------------------------


def _add_view(commands: Any) -> None:
    view = commands.add_parser(
        "view", parents=[_COMMON],
        help="play a .fap or storyboard in a window (space: pause, arrows: step, q: quit)")
    view.add_argument("source", help="STORY.fdl or FILE.fap")
    view.add_argument("--face", help="a face definition JSON or a `facelib face setup` "
                      "folder (default: the storyboard's face, else the bundled head)")
    view.add_argument("--loop", action="store_true", help="replay until the window is closed")
    view.add_argument("--mute", action="store_true", help="do not play the speech audio")
    view.add_argument("--seed", type=int)
    view.set_defaults(run=_view)


def _view(args: argparse.Namespace, console: Console) -> int:
    from facelib.rendering.viewer import view

    view(_source(args.source, args.seed, console), face=_face_path(args.face), loop=args.loop,
         sound=not args.mute)
    return EXIT_OK


# -- plot --------------------------------------------------------------------------------


def _add_plot(commands: Any) -> None:
    plot = commands.add_parser("plot", help="plot FAP curves of a storyboard or .fap",
                               parents=[_COMMON])
    plot.add_argument("source", help="STORY.fdl or FILE.fap")
    plot.add_argument("-o", "--output", required=True, help="curves.png (or .svg, .pdf)")
    plot.add_argument("--seed", type=int)
    plot.set_defaults(run=_plot)


def _plot(args: argparse.Namespace, console: Console) -> int:
    from facelib.plot import plot_curves

    _check_suffix(args.output, (".png", ".svg", ".pdf"), "plot")
    out = plot_curves(_source(args.source, args.seed, console), args.output,
                      title=args.source)
    console.status(f"wrote {out}")
    return EXIT_OK


# -- align -------------------------------------------------------------------------------


def _add_align(commands: Any) -> None:
    align = commands.add_parser("align", help="align speech audio to visemes",
                                parents=[_COMMON])
    align.add_argument("audio", help="speech audio (any format soundfile reads)")
    align.add_argument("--text", help="the transcript (omit for phone-loop recognition)")
    align.add_argument("--text-file", help="a file holding the transcript")
    align.add_argument("-o", "--output", required=True,
                       help="OUT.json, OUT.tsv or OUT.sb; - writes --format to stdout")
    align.add_argument("--format", choices=("json", "tsv", "sb"), default="json",
                       help="the format written to stdout by -o - (default json)")
    align.add_argument("--fps", type=float, default=25.0, help="frame rate of a .sb script")
    align.add_argument("--lang", default="en",
                       help="language of the speech (en: pocketsphinx; others: DTW against "
                            "espeak-ng, which needs --text)")
    align.set_defaults(run=_align)


def _align(args: argparse.Namespace, console: Console) -> int:
    import json

    from facelib.visemes import align, align_dtw
    from facelib.visemes.scripts import (
        timeline_to_json,
        timeline_to_sentence,
        timeline_to_tsv,
    )

    _check_suffix(args.output, (".json", ".tsv", ".sb", ".lua", ".fdl"), "align")
    kind = args.format if args.output == STDOUT else Path(args.output).suffix[1:].lower()
    kind = "sb" if kind in ("lua", "fdl") else kind
    text = args.text
    if args.text_file is not None:
        try:
            text = Path(args.text_file).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise FileError(f"cannot read the transcript: {exc}", path=args.text_file) from exc
    if args.lang.lower().startswith("en"):
        timeline = align(args.audio, text)
    elif text is None:
        raise UsageError(f"aligning speech in {args.lang!r} needs its transcript (--text)")
    else:
        timeline = align_dtw(args.audio, text, lang=args.lang)
    formatted = {
        "json": lambda: json.dumps(timeline_to_json(timeline), indent=1) + "\n",
        "tsv": lambda: timeline_to_tsv(timeline),
        "sb": lambda: timeline_to_sentence(timeline, fps=args.fps),
    }[kind]()
    _emit_text(formatted, args.output, console, "")
    return EXIT_OK


# -- list --------------------------------------------------------------------------------


def _add_list(commands: Any) -> None:
    from facelib.catalog import KINDS

    listing = commands.add_parser(
        "list", parents=[_COMMON],
        help="list the names a storyboard may use: " + ", ".join(KINDS))
    listing.add_argument("kind", choices=KINDS)
    listing.add_argument("--lang", help="voices: only those of this language (e.g. de)")
    listing.set_defaults(run=_list)


def _list(args: argparse.Namespace, console: Console) -> int:
    from facelib.catalog import catalog

    entries = catalog(args.kind, lang=args.lang)
    width = max((len(e.name) for e in entries), default=0)
    for entry in entries:
        extra = f"  [{entry.image}]" if entry.image else ""
        print(f"{entry.name:<{width}}  {entry.description}{extra}")
    return EXIT_OK


# -- dataset -----------------------------------------------------------------------------


def _add_dataset(commands: Any) -> None:
    dataset = commands.add_parser(
        "dataset", parents=[_COMMON],
        help="generate a synthetic face dataset from a SPEC.toml, locally or on Dask")
    dataset.add_argument("spec", help="the dataset spec (TOML, see docs/batch.md)")
    dataset.add_argument("-o", "--output", required=True, help="the dataset folder")
    dataset.add_argument("-j", "--jobs", type=int,
                         help="local processes (default: CPU count)")
    dataset.add_argument("--scheduler", metavar="ADDRESS",
                         help="a Dask scheduler, e.g. tcp://HOST:8786 (needs facelib[scale])")
    dataset.set_defaults(run=_dataset)


def _dataset(args: argparse.Namespace, console: Console) -> int:
    from facelib.dataset import generate, load_spec

    spec = load_spec(args.spec)
    report = generate(spec, args.output, jobs=args.jobs, scheduler=args.scheduler,
                      progress=console.progress("dataset", unit="clips"))
    console.status(f"{args.output}: {report.written} clips written, {report.skipped} already "
                   f"there, {len(report.failed)} failed")
    for clip, error in report.failed:
        print(f"facelib: error: clip {clip}: {error}", file=sys.stderr)
    return EXIT_ERROR if report.failed else EXIT_OK


# -- the parser and main -----------------------------------------------------------------

# -- evaluate ----------------------------------------------------------------------------


def _add_evaluate(commands: Any) -> None:
    evaluate = commands.add_parser(
        "evaluate", help="compare deformers by lip roughness (CSV, Markdown, contact sheet)",
        parents=[_COMMON])
    evaluate.add_argument("-o", "--output", required=True, help="folder for the results")
    evaluate.add_argument("--deformers", help="comma-separated names (default: all seven)")
    evaluate.add_argument("--region", default="lips", help="region or group to switch")
    evaluate.add_argument("--poses", default="viseme,expression,syllable",
                          help="comma-separated pose kinds: viseme, expression, syllable")
    evaluate.add_argument("--face", help="a face definition JSON (default: the bundled head)")
    evaluate.add_argument("--stem", default="deformers", help="file name stem")
    evaluate.add_argument("--no-sheet", action="store_true", help="skip the mouth contact sheet")
    evaluate.set_defaults(run=_evaluate)


def _evaluate(args: argparse.Namespace, console: Console) -> int:
    from facelib.evaluate import DEFORMERS, evaluate_deformers, evaluation_poses, write_evaluation

    names = tuple(n.strip() for n in args.deformers.split(",")) if args.deformers else DEFORMERS
    kinds = tuple(k.strip() for k in args.poses.split(","))
    ev = evaluate_deformers(names, group=args.region, poses=evaluation_poses(kinds),
                            face_path=args.face)
    for path in write_evaluation(ev, args.output, sheet=not args.no_sheet, stem=args.stem,
                                 face_path=args.face):
        console.status(f"wrote {path}")
    return EXIT_OK


# -- track -------------------------------------------------------------------------------


def _neutral(args: argparse.Namespace) -> tuple[int, int] | None:
    """``facelib track``'s ``--neutral``; None: the first frame with a face."""
    return None if args.neutral is None else _span(args.neutral)


def _span(text: str) -> tuple[int, int]:
    """``"N"`` -> (N, N + 1); ``"A:B"`` -> (A, B)."""
    try:
        first, _, last = text.partition(":")
        return (int(first), int(last)) if last else (int(first), int(first) + 1)
    except ValueError:
        raise FacelibError(f"frames must be N or START:STOP, got {text!r}") from None


def _add_track(commands: Any) -> None:
    track = commands.add_parser(
        "track", help="performance-driven animation: a face video (or landmarks) to FAPs",
        parents=[_COMMON])
    track.add_argument("source", nargs="?", help="a video, or landmarks: .csv "
                       "(facelib/generic, OpenFace), .json, .pts or a folder of .pts")
    track.add_argument("--camera", nargs="?", const="0", metavar="CAMERA",
                       help="track live instead: a camera index (default 0), device or "
                       "stream address, or a video read as if live; the mirror shows in a "
                       "window until q or Esc, the .fap is measured on the whole recording")
    track.add_argument("--no-window", action="store_true",
                       help="--camera: record without showing the mirror")
    track.add_argument("--neutral-frames", type=int, default=25,
                       help="--camera: the first frames with a face that make the neutral "
                       "(default 25; hold still)")
    track.add_argument("-o", "--output", required=True,
                       help="the .fap file to write, or - for stdout")
    track.add_argument("--landmarks-out", help="also write the landmarks as CSV")
    track.add_argument("--render", help="also write the Virtual Mirror video (source | avatar)")
    track.add_argument("--face", help="the avatar's face definition (default: bundled head)")
    track.add_argument("--show-landmarks", action="store_true",
                       help="draw the tracked landmarks on the mirror's source side")
    track.add_argument("--neutral", help="neutral frame N or span START:STOP (default: the "
                       "first frame with a face; in a video, with a well-lit face)")
    track.add_argument("--pucker", action="append", metavar="START:STOP",
                       help="frames labelled pucker (eq. 4.17 high-level state); repeatable")
    track.add_argument("--no-smooth", action="store_true",
                       help="skip the One Euro filter and the jaw drawn across brief lip "
                       "closures")
    track.add_argument("--layout", choices=("mediapipe", "ibug68"),
                       help="landmark files: the point layout (default: by point count)")
    track.add_argument("--fps", type=float, help="landmark files: their frame rate")
    track.add_argument("--max-frames", type=int,
                       help="videos and cameras: track at most this many frames")
    track.add_argument("--dialect", default="extended",
                       choices=("standard", "xface", "greta", "extended"))
    track.set_defaults(run=_track)


def _is_landmark_file(source: Path) -> bool:
    """Whether ``facelib track`` reads ``source`` as landmarks rather than a video."""
    return source.is_dir() or source.suffix.lower() in (".csv", ".json", ".pts")


@dataclass(frozen=True)
class _Tracked:
    """What ``facelib track`` measures: ``(n, K, D)`` landmarks at ``fps`` in ``layout``,
    the ``neutral`` span (None: the first frame with a face), the ``video`` (None for files
    and cameras) and the brows' ``(n, 4)`` image shifts (None for landmark files)."""

    landmarks: Any
    fps: float
    layout: str
    neutral: tuple[int, int] | None
    video: Path | None = None
    brows: Any = None


def _track_source(args: argparse.Namespace, console: Console) -> _Tracked:
    """The landmarks of ``facelib track``'s source and what goes with them."""
    if args.camera is not None:
        return _track_camera(args, console)
    source = Path(args.source)
    if _is_landmark_file(source):
        from facelib.tracking.files import read_landmarks

        file = read_landmarks(source)
        fps = file.fps if args.fps is None else args.fps
        layout = args.layout or file.layout
        if fps is None or layout is None:
            missing = [f"--{name} ({why})" for name, value, why in (
                ("fps", fps, "the file does not say its frame rate"),
                ("layout", layout, f"no packaged layout has {file.landmarks.shape[1]} points"))
                if value is None]
            raise FacelibError(f"{source}: give " + " and ".join(missing))
        return _Tracked(file.landmarks, fps, layout, _neutral(args))
    from facelib.tracking.video import track_video, video_brows

    track = track_video(source, max_frames=args.max_frames)
    console.status(f"tracked {len(track.landmarks)} frames of {source} ({track.info.width}x"
                   f"{track.info.height}, {track.info.fps:g} fps); no face in "
                   f"{len(track.lost_frames)}")
    neutral = _neutral(args)
    if neutral is None:
        first = track.first_lit_face
        neutral = (first, first + 1)
        if first:
            console.status(f"neutral: frame {first}, the first with a well-lit face "
                           "(--neutral chooses another)")
    return _Tracked(track.landmarks, track.info.fps, "mediapipe", neutral, source,
                    video_brows(source, track.landmarks, neutral=neutral))


def _track_camera(args: argparse.Namespace, console: Console) -> _Tracked:
    """``facelib track --camera``: record live; the neutral span the live run used."""
    import numpy as np

    from facelib.tracking.headframe import face_found
    from facelib.tracking.live import run_camera

    camera = int(args.camera) if args.camera.isdigit() else args.camera
    console.status(f"tracking {camera!r} live; hold a neutral face for "
                   f"{args.neutral_frames} frames" + ("" if args.no_window else
                                                      ", then q or Esc in the window ends"))
    recording = run_camera(camera, face=_face(args.face) if args.face else None,
                           neutral_frames=args.neutral_frames, window=not args.no_window,
                           max_frames=args.max_frames)
    faces = np.flatnonzero(face_found(recording.landmarks))
    if len(faces) < args.neutral_frames:
        raise FacelibError(f"{camera!r}: a face in {len(faces)} of {len(recording.landmarks)} "
                           f"frames, fewer than the {args.neutral_frames} neutral frames")
    console.status(f"recorded {len(recording.landmarks)} frames at {recording.fps:.3g} fps; "
                   f"no face in {len(recording.landmarks) - len(faces)}")
    neutral = (int(faces[0]), int(faces[args.neutral_frames - 1]) + 1)
    return _Tracked(recording.landmarks, recording.fps, "mediapipe", neutral,
                    brows=recording.brows)


def _track(args: argparse.Namespace, console: Console) -> int:
    import numpy as np

    from facelib.tracking.faps import measure_faps

    if (args.source is None) == (args.camera is None):
        raise FacelibError("give a source (a video or landmark file) or --camera" + (
            ", not both" if args.source is not None else ""))
    _check_suffix(args.output, (".fap",), "track")
    if args.render and (args.camera is not None or _is_landmark_file(Path(args.source))):
        raise FacelibError("--render needs a video source (the mirror shows it; live, the "
                           "window is the mirror)")
    source = _track_source(args, console)
    landmarks, fps = source.landmarks, source.fps
    if args.landmarks_out:  # first: a live session's landmarks survive a failed measure
        from facelib.tracking.files import write_landmarks_csv

        console.status(f"wrote {write_landmarks_csv(args.landmarks_out, landmarks, fps=fps)}")
    states = None
    if args.pucker:
        mask = np.zeros(len(landmarks), bool)
        for text in args.pucker:
            start, stop = _span(text)
            mask[start:stop] = True
        states = {"pucker": mask}
    result = measure_faps(landmarks, fps=fps, layout=source.layout, states=states,
                          neutral=source.neutral, smooth=not args.no_smooth,
                          brows=source.brows)
    console.status("user FAPU (pixels): " + ", ".join(f"{k}0={v * 1024:.1f}"
                                             for k, v in result.fapu.items() if k != "AU"))
    stream = result.stream
    if stream.fps != round(stream.fps):  # a camera's measured rate, a landmark file's
        stream = stream.resample(max(1, round(stream.fps)))
        if abs(result.stream.fps - stream.fps) > 1e-3 * stream.fps:  # not timestamps' noise
            console.status(f"resampled from {result.stream.fps:.4g} to {stream.fps:g} frames "
                           "a second: a .fap holds whole rates")
    _emit_text(format_fap(stream, dialect=args.dialect, name=Path(args.output).stem),
               args.output, console, f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    if args.render and source.video is not None:
        from facelib.tracking.mirror import render_mirror

        out = render_mirror(source.video, result.stream, args.render, face=_face(args.face),
                            landmarks=landmarks if args.show_landmarks else None)
        console.status(f"wrote {out}")
    return EXIT_OK


# -- export and import-arkit -------------------------------------------------------------


def _add_export(commands: Any) -> None:
    export = commands.add_parser(
        "export", parents=[_COMMON],
        help="export to glTF (.glb), ARKit curves (.csv/.json) or a web page")
    export.add_argument("source", help="STORY.fdl or FILE.fap")
    export.add_argument("-o", "--output",
                        help="OUT.glb (glTF), or with --arkit OUT.csv (Live Link Face) / OUT.json")
    export.add_argument("--arkit", action="store_true",
                        help="write ARKit-52 blendshape curves instead of glTF")
    export.add_argument("--html", metavar="DIR", help="also write a web player into DIR")
    export.add_argument("--face", help="a face definition JSON (default: the bundled head)")
    export.add_argument("--audio", help="speech audio to put beside the .glb / in the page")
    export.add_argument("--seed", type=int)
    export.set_defaults(run=_export)

    imp = commands.add_parser(
        "import-arkit", parents=[_COMMON],
        help="turn an ARKit capture (Live Link Face CSV) into a .fap")
    imp.add_argument("capture", help="the Live Link Face .csv (or facelib's ARKit .json)")
    imp.add_argument("-o", "--output", required=True, help="OUT.fap, or - for stdout")
    imp.add_argument("--fps", type=float,
                     help="frame base of the timecodes (default: read; the app counts at 60)")
    imp.add_argument("--resample", type=float, help="resample to this frame rate (e.g. 25)")
    imp.add_argument("--dialect", default="standard",
                     choices=("standard", "xface", "greta", "extended"))
    imp.set_defaults(run=_import_arkit)


def _export(args: argparse.Namespace, console: Console) -> int:
    import numpy as np

    from facelib import export

    if args.output is None and args.html is None:
        raise UsageError("give -o OUT.glb (or OUT.csv / OUT.json with --arkit), --html DIR, "
                         "or both")
    if args.output is not None:
        _check_suffix(args.output, (".csv", ".json") if args.arkit else
                      (".glb", ".csv", ".json"), "export")
    face = _face(args.face)
    source = _source(args.source, args.seed, console)
    if args.output is not None:
        suffix = Path(args.output).suffix.lower()
        if args.arkit or suffix in (".csv", ".json"):
            curves = export.export_arkit(source, args.output, face=face)
            moving = curves.relative[curves.relative > 0]
            fit = (f"; fit residual RMS {1000 * float(curves.residual.mean()):.2f} mm, "
                   f"median relative {float(np.median(moving)):.2f}" if moving.size else "")
            console.status(f"wrote {args.output} ({curves.n_frames} frames of 52 ARKit "
                           f"weights{fit})")
        else:
            result = export.export_gltf(source, args.output, face=face, audio=args.audio)
            audio = f", audio {result.audio}" if result.audio else ""
            console.status(f"wrote {result.path} ({len(result.targets)} morph targets, "
                           f"{result.n_frames} frames{audio})")
    if args.html is not None:
        page = export.export_html(source, args.html, face=face, audio=args.audio)
        console.status(f"wrote {page.page} (open it in a browser)")
    return EXIT_OK


def _import_arkit(args: argparse.Namespace, console: Console) -> int:
    from facelib.export import import_arkit

    _check_suffix(args.output, (".fap",), "import-arkit")
    stream = import_arkit(args.capture, fps=args.fps)
    if args.resample is not None:
        stream = stream.resample(args.resample)
    _emit_text(format_fap(stream, dialect=args.dialect, name=Path(args.capture).stem),
               args.output, console, f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    return EXIT_OK


# -- face setup --------------------------------------------------------------------------


def _add_face(commands: Any) -> None:
    face = commands.add_parser("face", help="make your own head mesh animatable",
                               parents=[_COMMON])
    face_commands = face.add_subparsers(dest="face_command", metavar="ACTION", required=True)
    setup = face_commands.add_parser(
        "setup", help="transfer the default face definition onto a head mesh",
        parents=[_COMMON])
    setup.add_argument("mesh", help="head mesh: .obj, .ply, .glb/.gltf, .off or .stl")
    setup.add_argument("--landmarks", help="JSON of feature point -> vertex index or [x, y, z]")
    setup.add_argument("--auto", action="store_true",
                       help="find the landmarks automatically (MediaPipe on a front view of "
                            "the mesh; needs the track and render extras)")
    setup.add_argument("-o", "--output", required=True, help="folder for face.json + face.npz")
    setup.add_argument("--unit", choices=("m", "dm", "cm", "mm", "in"),
                       help="the mesh's length unit (default: guessed from the landmarks)")
    for axis, default in (("up", "+y"), ("forward", "+z")):
        setup.add_argument(f"--{axis}", choices=("+x", "-x", "+y", "-y", "+z", "-z"),
                           help=f"the mesh's {axis} axis (default: guessed from the "
                                f"landmarks; {default} for --auto)")
    setup.add_argument("--part", action="append", default=[], metavar="PART=OBJECT",
                       help="name the file's object for a part (eye_l, eye_r, teeth_upper, "
                            "teeth_lower, tongue), e.g. --part eye_l=LeftEye")
    setup.set_defaults(run=_face_setup)


def _write_found(found: Any, folder: Path, console: Console) -> None:
    """The automatic landmarks as an editable JSON and a picture of where they are."""
    import json

    from facelib.atomic import write_text_atomic
    from facelib.rendering.video import save_png
    from facelib.tracking.head_landmarks import draw_landmarks

    write_text_atomic(folder / "landmarks.json",
                      json.dumps({"landmarks": found.as_json()}, indent=1) + "\n")
    save_png(draw_landmarks(found), folder / "landmarks.png")
    console.status(f"found:     {len(found.points)} feature points (see "
                   f"{folder / 'landmarks.png'}; edit {folder / 'landmarks.json'} and rerun "
                   "with --landmarks to correct them)")


def _face_setup(args: argparse.Namespace, console: Console) -> int:
    from facelib.engine.headmesh import axes_rotation, load_head_mesh
    from facelib.engine.setup import set_up_face
    from facelib.engine.writer import write_face

    if (args.landmarks is None) == (not args.auto):
        raise UsageError("give either --landmarks L.json or --auto (see docs/own-head.md)")
    bad = [item for item in args.part if "=" not in item]
    if bad:
        raise UsageError(f"--part {bad[0]!r} must be PART=OBJECT, e.g. eye_l=LeftEye")
    started = time.perf_counter()
    parts = dict(item.split("=", 1) for item in args.part)
    mesh = load_head_mesh(args.mesh, parts=parts)
    landmarks: Any = args.landmarks
    axes = {"up": args.up, "forward": args.forward}
    found = None
    if args.auto:
        from facelib.tracking.head_landmarks import detect_head_landmarks

        if args.up is not None or args.forward is not None:  # upright before looking
            mesh = mesh.rotated(axes_rotation(args.up or "+y", args.forward or "+z"))
            axes = {"up": None, "forward": None}
        found = detect_head_landmarks(mesh)
        landmarks = found.as_json()
    result = set_up_face(mesh, landmarks=landmarks, unit=args.unit, **axes)
    out = write_face(result.face, Path(args.output) / "face.json", name=Path(args.mesh).stem,
                     source=f"facelib face setup {Path(args.mesh).name}")
    if found is not None:
        _write_found(found, Path(args.output), console)
    _report_setup(args.mesh, mesh, result, console)
    console.status(f"wrote {out} in {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def _report_setup(name: str, mesh: Any, result: Any, console: Console) -> None:
    import numpy as np

    from facelib.mpeg4.tables import FAPU_SCALE

    face = result.face
    console.status(f"mesh:      {name} ({len(mesh.vertices)} vertices, unit {result.unit})")
    if mesh.repairs:
        console.status(f"repaired:  {'; '.join(mesh.repairs)}")
    if not np.allclose(result.rotation, np.eye(3)):
        console.status("oriented:  turned upright (+y up, looking along +z)")
    console.status(f"landmarks: {len(result.landmarks)}, off the surface by at most "
                   f"{result.residual.max() * 1000:.2f} mm")
    own = [p for p in face.parts if p not in result.carried]
    console.status(f"parts:     {', '.join(own)} from the mesh"
                   + (f"; {', '.join(result.carried)} warped into place from the default head"
                      if result.carried else ""))
    console.status("FAPU0 (mm): " + "  ".join(f"{k} {v * FAPU_SCALE * 1000:.2f}"
                                             for k, v in face.fapu.items() if k != "AU"))


_COMMON = argparse.ArgumentParser(add_help=False)
_COMMON.add_argument("-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
                     help="print only errors")
_COMMON.add_argument("-v", "--verbose", action="store_true", default=argparse.SUPPRESS,
                     help="also print log messages, progress of every stage and tracebacks")

_COMMANDS: tuple[Callable[[Any], None], ...] = (
    _add_info, _add_check, _add_run, _add_render, _add_view, _add_plot, _add_align,
    _add_list, _add_dataset, _add_evaluate, _add_track, _add_export,
    _add_face,
)


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="facelib", description="Scriptable MPEG-4 facial animation.", parents=[_COMMON],
        epilog="exit status: 0 ok, 1 error, 2 usage, 130 Ctrl-C, 141 closed pipe, "
               "143 SIGTERM",
    )
    parser.add_argument("--version", action="version", version=f"facelib {facelib.__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    for add in _COMMANDS:
        add(commands)
    return parser


@contextlib.contextmanager
def _stopping_signals(signals: Signals) -> Iterator[None]:
    """While inside, SIGINT raises KeyboardInterrupt and SIGTERM :class:`Terminated`, and
    ``signals`` remembers which came (main thread only)."""
    def stop(signum: int, frame: object) -> None:
        signals.received = signum
        signals.check()

    try:
        previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread: leave signals alone
        yield
        return
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _stdout_gone() -> int:
    """The reader of stdout went away: point stdout at /dev/null so the interpreter's
    final flush does not fail again, and end quietly."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    return EXIT_PIPE


def _stopped(signum: int) -> int:
    """One line and the exit status for a command stopped by ``signum``."""
    if signum == signal.SIGINT:
        print("facelib: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    print("facelib: terminated", file=sys.stderr)
    return EXIT_TERMINATED


def _dispatch(run: Callable[[argparse.Namespace, Console], int], args: argparse.Namespace,
              console: Console) -> int:
    try:
        with _stopping_signals(console.signals):
            status = run(args, console)
            console.signals.check()  # a signal whose exception was swallowed on the way
            return status
    except BrokenPipeError:
        return _stdout_gone()
    except KeyboardInterrupt:
        return _stopped(signal.SIGINT)
    except Terminated:
        return _stopped(signal.SIGTERM)
    except Exception as exc:
        if console.signals.received is not None:  # a library turned the signal into an error
            return _stopped(console.signals.received)  # (ctypes: into an ArgumentError)
        if not isinstance(exc, FacelibError):
            raise
        if console.verbose:
            traceback.print_exc()
        print(f"facelib: error: {exc}", file=sys.stderr)
        return EXIT_USAGE if isinstance(exc, UsageError) else EXIT_ERROR


def _axis_values_joined(argv: Sequence[str]) -> list[str]:
    """``argv`` with ``--up -y`` written ``--up=-y`` (and ``--forward`` alike): argparse
    takes a value starting with '-' for an option of its own and refuses the documented
    spelling otherwise."""
    out: list[str] = []
    for item in argv:
        if out and out[-1] in ("--up", "--forward") and item in ("-x", "-y", "-z"):
            out[-1] = f"{out[-1]}={item}"
        else:
            out.append(item)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (see the module docstring)."""
    parser = _build_parser()
    args = parser.parse_args(_axis_values_joined(sys.argv[1:] if argv is None else argv))
    run: Callable[[argparse.Namespace, Console], int] | None = getattr(args, "run", None)
    if run is None:
        parser.print_help()
        return EXIT_USAGE
    console = Console(quiet=getattr(args, "quiet", False), verbose=getattr(args, "verbose", False))
    if console.verbose:
        logging.basicConfig(level=logging.INFO, format="facelib: %(name)s: %(message)s")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", facelib.FacelibWarning)
        status = _dispatch(run, args, console)
    for warning in caught:
        if not console.quiet and issubclass(warning.category, facelib.FacelibWarning):
            print(f"facelib: warning: {warning.message}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
