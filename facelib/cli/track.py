"""``facelib track``: performance-driven animation, a face video, a camera or landmark
files measured into a .fap file (and optionally the Virtual Mirror video)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from facelib.cli.console import EXIT_OK, Console
from facelib.cli.options import COMMON, FACE_HELP, chosen_face
from facelib.cli.outputs import check_suffix, emit_text
from facelib.errors import FacelibError
from facelib.mpeg4 import format_fap


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


def add(commands: Any) -> None:
    track = commands.add_parser(
        "track", help="performance-driven animation: a face video (or landmarks) to FAPs",
        parents=[COMMON])
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
    track.add_argument("--face", help=f"the avatar: {FACE_HELP} (default: bundled head)")
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
        span = track.default_neutral().span
        neutral = (span.start, span.stop)
        if span.start:
            console.status(f"neutral: frames {span.start}-{span.stop - 1} (--neutral "
                           "chooses others)")
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
    recording = run_camera(camera, face=chosen_face(args.face) if args.face else None,
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
    check_suffix(args.output, (".fap",), "track")
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
    stream = result.stream.at_whole_rate()  # a camera's measured rate, a landmark file's
    if abs(result.stream.fps - stream.fps) > 1e-3 * stream.fps:  # not timestamps' noise
        console.status(f"resampled from {result.stream.fps:.4g} to {stream.fps:g} frames "
                       "a second: a .fap holds whole rates")
    emit_text(format_fap(stream, dialect=args.dialect, name=Path(args.output).stem),
              args.output, console, f"({stream.n_frames} frames, {stream.duration:.2f} s)")
    if args.render and source.video is not None:
        from facelib.tracking.mirror import render_mirror

        out = render_mirror(source.video, result.stream, args.render,
                            face=chosen_face(args.face),
                            landmarks=landmarks if args.show_landmarks else None)
        console.status(f"wrote {out}")
    return EXIT_OK

