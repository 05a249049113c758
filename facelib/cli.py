"""The ``facelib`` command. Every subcommand is a thin layer over the Python API."""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import facelib
from facelib.errors import FacelibError, FileError
from facelib.mpeg4 import DIALECTS, FapStream, fap, read_fap, read_fap_file, write_fap

if TYPE_CHECKING:
    from facelib.animation import Animation

__all__ = ["main"]

_Commands = argparse._SubParsersAction  # what add_subparsers returns


def _info(args: argparse.Namespace) -> int:
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
    return 0


def _check(args: argparse.Namespace) -> int:
    from facelib.fdl import describe, load

    print(describe(load(args.story, seed=args.seed)))
    return 0


def _animation(path: str, seed: int | None) -> Animation | FapStream:
    """A storyboard's Animation, or a .fap file's stream."""
    if Path(path).suffix.lower() == ".fap":
        return read_fap(path)
    from facelib.animation import run_fdl

    return run_fdl(path, seed=seed)


def _write_fap(stream: FapStream, out: str | Path, dialect: str) -> None:
    written = write_fap(stream, out, dialect=dialect)
    print(f"wrote {written} ({stream.n_frames} frames, {stream.duration:.2f} s)")


def _run(args: argparse.Namespace) -> int:
    from facelib.animation import run_fdl

    animation = run_fdl(args.story, seed=args.seed)
    out = args.output if args.output is not None else animation.storyboard.output
    if out is None:
        raise FacelibError(f"{args.story} names no output: give one with -o OUT.fap")
    _write_fap(animation.faps, out, args.dialect)
    return 0


def _render(args: argparse.Namespace) -> int:
    from facelib.engine import load_face
    from facelib.rendering.frames import render

    started = time.perf_counter()
    source = _animation(args.source, args.seed)
    if args.fap is not None:
        _write_fap(source if isinstance(source, FapStream) else source.faps, args.fap, "standard")
    out = render(source, face=load_face(args.face), out=args.output, width=args.width,
                 height=args.height, audio=args.audio, fps=args.fps)
    print(f"wrote {out} in {time.perf_counter() - started:.1f} s")
    return 0


def _view(args: argparse.Namespace) -> int:
    from facelib.engine import load_face
    from facelib.rendering.viewer import view

    view(_animation(args.source, args.seed), face=load_face(args.face), loop=args.loop)
    return 0


def _plot(args: argparse.Namespace) -> int:
    from facelib.plot import plot_curves

    out = plot_curves(_animation(args.source, args.seed), args.output, title=args.source)
    print(f"wrote {out}")
    return 0


def _align(args: argparse.Namespace) -> int:
    from facelib.visemes import align, write_timeline

    text = args.text
    if args.text_file is not None:
        try:
            text = Path(args.text_file).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise FileError(f"cannot read the transcript: {exc}", path=args.text_file) from exc
    out = write_timeline(align(args.audio, text), args.output, fps=args.fps)
    print(f"wrote {out}")
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    from facelib.evaluate import DEFORMERS, evaluate_deformers, evaluation_poses, write_evaluation

    names = tuple(n.strip() for n in args.deformers.split(",")) if args.deformers else DEFORMERS
    kinds = tuple(k.strip() for k in args.poses.split(","))
    ev = evaluate_deformers(names, group=args.region, poses=evaluation_poses(kinds),
                            face_path=args.face)
    for path in write_evaluation(ev, args.output, sheet=not args.no_sheet, stem=args.stem,
                                 face_path=args.face):
        print(f"wrote {path}")
    return 0


def _span(text: str) -> tuple[int, int]:
    """``"N"`` -> (N, N + 1); ``"A:B"`` -> (A, B)."""
    try:
        first, _, last = text.partition(":")
        return (int(first), int(last)) if last else (int(first), int(first) + 1)
    except ValueError:
        raise FacelibError(f"frames must be N or START:STOP, got {text!r}") from None


def _track(args: argparse.Namespace) -> int:
    import numpy as np

    from facelib.tracking.faps import measure_faps

    source = Path(args.source)
    states = None
    options: dict[str, Any] = {"neutral": _span(args.neutral), "smooth": not args.no_smooth}
    if source.is_dir() or source.suffix.lower() in (".csv", ".json", ".pts"):
        from facelib.tracking.files import read_landmarks

        file = read_landmarks(source)
        fps = args.fps or file.fps
        layout = args.layout or file.layout
        if fps is None or layout is None:
            raise FacelibError(f"{source}: give --fps and --layout (the file does not say)")
        landmarks, video = file.landmarks, None
    else:
        from facelib.tracking.video import track_video

        track = track_video(source, max_frames=args.max_frames)
        landmarks, fps, layout, video = track.landmarks, track.info.fps, "mediapipe", source
        print(f"tracked {len(landmarks)} frames of {source} ({track.info.width}x"
              f"{track.info.height}, {fps:g} fps); no face in {len(track.lost_frames)}")
    if args.pucker:
        mask = np.zeros(len(landmarks), bool)
        for text in args.pucker:
            start, stop = _span(text)
            mask[start:stop] = True
        states = {"pucker": mask}
    result = measure_faps(landmarks, fps=fps, layout=layout, states=states, **options)
    print("user FAPU (pixels): " + ", ".join(f"{k}0={v * 1024:.1f}"
                                             for k, v in result.fapu.items() if k != "AU"))
    _write_fap(result.stream, args.output, args.dialect)
    if args.landmarks_out:
        from facelib.tracking.files import write_landmarks_csv

        print(f"wrote {write_landmarks_csv(args.landmarks_out, landmarks, fps=fps)}")
    if args.render:
        if video is None:
            raise FacelibError("--render needs a video source (the mirror shows it)")
        from facelib.engine import load_face
        from facelib.tracking.mirror import render_mirror

        out = render_mirror(video, result.stream, args.render, face=load_face(args.face),
                            landmarks=landmarks if args.show_landmarks else None)
        print(f"wrote {out}")
    return 0


def _add_track_command(commands: _Commands) -> None:
    track = commands.add_parser(
        "track", help="performance-driven animation: a face video (or landmarks) to FAPs")
    track.add_argument("source", help="a video, or landmarks: .csv (facelib/generic, "
                       "OpenFace), .json, .pts or a folder of .pts")
    track.add_argument("-o", "--output", required=True, help="the .fap file to write")
    track.add_argument("--landmarks-out", help="also write the landmarks as CSV")
    track.add_argument("--render", help="also write the Virtual Mirror video (source | avatar)")
    track.add_argument("--face", help="the avatar's face definition (default: bundled head)")
    track.add_argument("--show-landmarks", action="store_true",
                       help="draw the tracked landmarks on the mirror's source side")
    track.add_argument("--neutral", default="0", help="neutral frame N or span START:STOP")
    track.add_argument("--pucker", action="append", metavar="START:STOP",
                       help="frames labelled pucker (eq. 4.17 high-level state); repeatable")
    track.add_argument("--no-smooth", action="store_true", help="skip the One Euro filter")
    track.add_argument("--layout", choices=("mediapipe", "ibug68"),
                       help="landmark files: the point layout (default: by point count)")
    track.add_argument("--fps", type=float, help="landmark files: their frame rate")
    track.add_argument("--max-frames", type=int, help="videos: track at most this many frames")
    track.add_argument("--dialect", default="extended",
                       choices=("standard", "xface", "greta", "extended"))
    track.set_defaults(run=_track)


def _add_render_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("-o", "--output", required=True,
                         help="OUT.mp4, OUT.gif, or a folder for PNG frames")
    command.add_argument("--face", help="a face definition JSON (default: the bundled head)")
    command.add_argument("--width", type=int, default=640)
    command.add_argument("--height", type=int, default=480)
    command.add_argument("--fps", type=float, help="resample to this frame rate")


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="facelib", description="Scriptable MPEG-4 facial animation."
    )
    parser.add_argument("--version", action="version", version=f"facelib {facelib.__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    info = commands.add_parser("info", help="summarise a .fap file")
    info.add_argument("file", help="the .fap file")
    info.add_argument("--strict", action="store_true", help="accept only the standard profile")
    info.set_defaults(run=_info)

    check = commands.add_parser("check", help="check a storyboard and list its cues")
    check.add_argument("story", help="the .fdl storyboard")
    check.add_argument("--seed", type=int)
    check.set_defaults(run=_check)

    run = commands.add_parser("run", help="animate a storyboard into a .fap file")
    run.add_argument("story", help="the .fdl storyboard")
    run.add_argument("-o", "--output", help="the .fap file (default: the storyboard's output)")
    run.add_argument("--seed", type=int, help="seed of the random processes")
    run.add_argument("--dialect", default="standard", choices=DIALECTS)
    run.set_defaults(run=_run)

    render = commands.add_parser("render", help="render a storyboard (or .fap) to video")
    render.add_argument("source", help="STORY.fdl or FILE.fap")
    _add_render_options(render)
    render.add_argument("--fap", help="also write the animation's .fap here")
    render.add_argument("--seed", type=int)
    render.set_defaults(run=_render, audio=None)

    play = commands.add_parser("play", help="render a .fap file, with optional audio")
    play.add_argument("source", metavar="FILE.fap")
    _add_render_options(play)
    play.add_argument("--audio", help="speech audio to mux into the video")
    play.set_defaults(run=_render, fap=None, seed=None)

    view = commands.add_parser("view", help="play a .fap or storyboard in a window")
    view.add_argument("source", help="STORY.fdl or FILE.fap")
    view.add_argument("--face", help="a face definition JSON (default: the bundled head)")
    view.add_argument("--loop", action="store_true")
    view.add_argument("--seed", type=int)
    view.set_defaults(run=_view)

    plot = commands.add_parser("plot", help="plot FAP curves of a storyboard or .fap")
    plot.add_argument("source", help="STORY.fdl or FILE.fap")
    plot.add_argument("-o", "--output", required=True, help="curves.png (or .svg, .pdf)")
    plot.add_argument("--seed", type=int)
    plot.set_defaults(run=_plot)

    _add_tool_commands(commands)
    _add_track_command(commands)
    return parser


def _add_tool_commands(commands: _Commands) -> None:
    """The ``align`` and ``evaluate`` commands."""
    align = commands.add_parser("align", help="align speech audio to visemes")
    align.add_argument("audio", help="speech audio (any format soundfile reads)")
    align.add_argument("--text", help="the transcript (omit for phone-loop recognition)")
    align.add_argument("--text-file", help="a file holding the transcript")
    align.add_argument("-o", "--output", required=True, help="OUT.json, OUT.tsv or OUT.sb")
    align.add_argument("--fps", type=float, default=25.0, help="frame rate of a .sb script")
    align.set_defaults(run=_align)

    evaluate = commands.add_parser(
        "evaluate", help="compare deformers by lip roughness (CSV, Markdown, contact sheet)")
    evaluate.add_argument("-o", "--output", required=True, help="folder for the results")
    evaluate.add_argument("--deformers", help="comma-separated names (default: all seven)")
    evaluate.add_argument("--region", default="lips", help="region or group to switch")
    evaluate.add_argument("--poses", default="viseme,expression,syllable",
                          help="comma-separated pose kinds: viseme, expression, syllable")
    evaluate.add_argument("--face", help="a face definition JSON (default: the bundled head)")
    evaluate.add_argument("--stem", default="deformers", help="file name stem")
    evaluate.add_argument("--no-sheet", action="store_true", help="skip the mouth contact sheet")
    evaluate.set_defaults(run=_evaluate)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 facelib error, 2 usage)."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    run: Callable[[argparse.Namespace], int] | None = getattr(args, "run", None)
    if run is None:
        parser.print_help()
        return 2
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", facelib.FacelibWarning)
        try:
            status = run(args)
        except FacelibError as exc:
            print(f"facelib: error: {exc}", file=sys.stderr)
            status = 1
    for warning in caught:
        print(f"facelib: warning: {warning.message}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
