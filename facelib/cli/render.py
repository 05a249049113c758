"""``facelib render`` (storyboards or .fap files to video, one or a batch) and ``facelib
play`` (a .fap file, with optional audio): the same options and the same one-source path."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_ERROR, EXIT_OK, Console, UsageError
from facelib.cli.options import (
    COMMON,
    FACE_HELP,
    add_hair,
    character_file,
    face_path,
    output_face,
    read_source,
)
from facelib.cli.outputs import RENDER_SUFFIXES, check_suffix, default_output
from facelib.clip import is_scene
from facelib.mpeg4 import FapStream, write_fap_complete


def _add_render_options(command: argparse.ArgumentParser, *, batch: bool) -> None:
    help_out = ("OUT.mp4, OUT.gif, OUT.png (one frame) or a folder for PNG frames"
                + ("; with several sources or -j, the folder for STEM.mp4 files" if batch
                   else ""))
    command.add_argument("-o", "--output", required=not batch, help=help_out)
    command.add_argument("--face", help=f"{FACE_HELP} (default: the storyboard's face, else "
                         "the bundled head)")
    add_hair(command)
    command.add_argument("--width", type=int, default=640)
    command.add_argument("--height", type=int, default=480)
    command.add_argument("--fps", type=float, help="resample to this frame rate")
    command.add_argument("--framing", choices=("face", "head", "bust"), default="face",
                         help="what the camera frames (default: face, brow to chin)")


def add(commands: Any) -> None:
    render = commands.add_parser("render", help="render storyboards (or .fap files) to video",
                                 parents=[COMMON])
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
                               parents=[COMMON])
    play.add_argument("source", metavar="FILE.fap")
    _add_render_options(play, batch=False)
    play.add_argument("--audio", help="speech audio to mux into the video")
    play.set_defaults(run=_play, fap=None, seed=None)


def _render_one(source_path: str, out: str, args: argparse.Namespace, console: Console) -> int:
    from facelib.rendering.frames import render

    started = time.perf_counter()
    source = read_source(source_path, args.seed, console, scenes=True)
    if is_scene(source):
        return _render_scene(source, out, args, console, started)
    if args.fap is not None:
        check_suffix(args.fap, (".fap",), "--fap")
        stream = source if isinstance(source, FapStream) else source.faps
        written_faps = write_fap_complete(stream, args.fap)
        console.status(f"wrote {' and '.join(map(str, written_faps))} ({stream.n_frames} "
                       f"frames, {stream.duration:.2f} s)")
    written = render(source, face=output_face(args, source), out=out, width=args.width,
                     framing=args.framing,
                     height=args.height, audio=args.audio, fps=args.fps,
                     progress=console.progress("rendering"))
    console.status(f"wrote {written} in {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def _render_scene(scene: Any, out: str, args: argparse.Namespace, console: Console,
                  started: float) -> int:
    """A storyboard with characters: one .fap per character (``--fap out/x.fap`` writes
    ``out/x.ada.fap``, ...) and the video cutting between them."""
    from facelib.rendering.shots import render_scene

    for option in ("face", "hair"):
        if getattr(args, option) is not None:
            raise UsageError(f"--{option}: the storyboard names characters; give each one's "
                             f"{option} in characters {{ ... }}")
    if args.fap is not None:
        check_suffix(args.fap, (".fap",), "--fap")
        for name, animation in scene.parts.items():
            written_faps = write_fap_complete(animation.faps, character_file(args.fap, name))
            console.status(f"wrote {' and '.join(map(str, written_faps))} ({name}, "
                           f"{animation.faps.n_frames} frames)")
    if args.fps is not None or args.audio is not None:
        raise UsageError("--fps and --audio are for one face; a storyboard with characters "
                         "plays at its own fps with its own speech")
    written = render_scene(scene, out=out, width=args.width, height=args.height,
                           framing=args.framing, progress=console.progress("rendering"))
    console.status(f"wrote {written} in {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def _render_output(source: str, args: argparse.Namespace) -> str:
    """The output of a one-source render: ``-o``, else the storyboard's ``output`` (a
    ``.fap`` output is written too, beside ``STEM.mp4``), else ``STEM.mp4`` here."""
    if args.output is not None:
        if Path(args.output).suffix:
            check_suffix(args.output, RENDER_SUFFIXES, "render")
        return str(args.output)
    if Path(source).suffix.lower() == ".fap":
        return str(Path.cwd() / (Path(source).stem + ".mp4"))
    from facelib.fdl import load

    wanted = load(source).output
    out = default_output(source, wanted, ".mp4")
    if out.suffix.lower() == ".fap":
        if args.fap is None:
            args.fap = str(out)
        out = out.with_suffix(".mp4")
    check_suffix(str(out), RENDER_SUFFIXES, "render")
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
        face=face_path(args.face), hair=args.hair,
        progress=console.progress("batch", unit="files"),
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
        check_suffix(args.output, RENDER_SUFFIXES, "play")
    return _render_one(args.source, args.output, args, console)

