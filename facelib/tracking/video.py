"""Video in: frames decoded by the bundled ffmpeg (``imageio-ffmpeg``), faces tracked with
MediaPipe, and the whole path from a video file to a FapStream.

Frames where no face is found are NaN in the landmark track (interpolated later and named in
a :class:`~facelib.errors.TrackingWarning`), and so are the two either side of a longer loss
(the face leaving or entering the picture); frames with several faces follow the face
tracked before (the largest at first) and are named too.
"""

from __future__ import annotations

import logging
import os
import re
import subprocess
import tempfile
import warnings
from collections.abc import Generator, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import suppress
from dataclasses import dataclass
from functools import partial
from itertools import chain, islice
from pathlib import Path
from typing import Any

import numpy as np

from facelib.checks import check_count
from facelib.errors import TrackingError, TrackingWarning
from facelib.optional import require
from facelib.tracking.browimage import track_brows
from facelib.tracking.faps import TrackedFaps, find_neutral, frame_spans, measure_faps
from facelib.tracking.headframe import face_found
from facelib.tracking.mediapipe import (
    N_LANDMARKS,
    FaceCounter,
    FaceLandmarks,
    FaceMeshTracker,
)
from facelib.tracking.neutral import NeutralChoice, neutral_news
from facelib.tracking.observation import ObservationModel, default_observation
from facelib.tracking.overlap import InOrder, read_ahead

log = logging.getLogger("facelib.tracking")

__all__ = ["VideoInfo", "VideoTrack", "extract_audio", "read_video", "track_video",
           "track_video_faps", "video_brows"]


@dataclass(frozen=True)
class VideoInfo:
    """A video's frame rate as :func:`read_video` reads it (whole frames a second), frame
    size in pixels as shown (turned as the file says) and whether it has sound."""

    fps: float
    width: int
    height: int
    audio: bool


@dataclass(frozen=True)
class VideoTrack:
    """Landmarks of one video.

    Attributes
    ----------
    path: the video.
    info: its frame rate and size.
    landmarks: ``(n_frames, 478, 3) float64`` pixels (column, row, depth); NaN where no
        face was found, and in the two frames either side of a loss of five or more (the
        face leaving or entering the picture, read with a wrong pose).
    n_faces: ``(n_frames,) int16`` faces seen per frame.
    light: ``(n_frames,) float64`` the mean grey level (0-255) inside each frame's face
        box; NaN where no face was found.
    """

    path: Path
    info: VideoInfo
    landmarks: np.ndarray
    n_faces: np.ndarray
    light: np.ndarray

    @property
    def lost_frames(self) -> tuple[int, ...]:
        """Frames with no face (NaN landmarks)."""
        return tuple(int(i) for i in np.flatnonzero(~self._found))

    @property
    def _found(self) -> np.ndarray:
        return face_found(self.landmarks)

    @property
    def first_lit_face(self) -> int:
        """The first frame whose face is at least 0.8 times as bright as the median face:
        the default neutral (MediaPipe reads the dim faces of a fade-in poorly)."""
        found = np.flatnonzero(self._found)
        light = self.light[found]
        if np.isfinite(light).any():
            found = found[light >= 0.8 * np.nanmedian(light)]
        return int(found[0])

    def default_neutral(self) -> NeutralChoice:
        """The neutral frames when the user names none: :attr:`first_lit_face` unless
        :func:`~facelib.tracking.faps.find_neutral` finds it clearly not neutral (then
        the most neutral well-lit span, with a TrackingWarning)."""
        lit = np.isfinite(self.light)
        dim = np.flatnonzero(self.light < 0.8 * np.nanmedian(self.light)) if lit.any() else ()
        first = self.first_lit_face
        choice = find_neutral(self.landmarks, fps=self.info.fps, first=first, excluded=dim)
        if choice.searched:
            warnings.warn(TrackingWarning(neutral_news(choice, first)), stacklevel=2)
        return choice


def _face_light(image: np.ndarray, box: np.ndarray) -> float:
    """Mean grey level (0-255) of ``image`` ``(H, W, 3) uint8`` inside the face ``box``
    ``(left, top, right, bottom)`` pixels, clipped to the image."""
    height, width = image.shape[:2]
    left, right = (int(np.clip(v, 0, width)) for v in box[0::2])
    top, bottom = (int(np.clip(v, 0, height)) for v in box[1::2])
    if right <= left or bottom <= top:
        return float("nan")
    import cv2

    total = sum(cv2.sumElems(image[top:bottom, left:right])[:3])  # exact: whole numbers
    return float(total / ((bottom - top) * (right - left) * 3))


def _imageio_ffmpeg() -> Any:
    return require("ffmpeg_track")


_HEADER_TIMEOUT_S = 60
"""Seconds ffmpeg may take to read a video's header (and first frame)."""


def _probe(path: Path) -> dict[str, Any]:
    """What ffmpeg says of ``path``'s first video stream: ``fps`` (its average rate, 0 where
    it gives none), ``size`` (width, height of the frames as read: turned as the file says),
    ``source_size`` (as stored) and ``audio`` (whether the file has a sound stream).

    ffmpeg reads the header alone (about 20 ms, one process) unless the stream carries side
    data (a display matrix that turns the frames, say): then it also decodes the first frame
    on one thread, so that ``size`` is the one it reads the frames at. TrackingError when it
    finds no video stream."""
    exe = _imageio_ffmpeg().get_ffmpeg_exe()
    command = [exe, "-nostdin", "-hide_banner", "-threads", "1", "-i", str(path)]
    text = _ffmpeg_says(command)
    decoded = "side data" in text.lower()
    if decoded:
        text = _ffmpeg_says([*command, "-an", "-sn", "-dn", "-frames:v", "1", "-pix_fmt",
                             "rgb24", "-c:v", "rawvideo", "-f", "null", "-"])
    lines = text.splitlines()
    video = [line for line in lines
             if line.lstrip().startswith("Stream ") and " Video: " in line]
    if not video or (decoded and not any(line.startswith("Output ") for line in lines)):
        said = [line.strip() for line in lines if line.strip()] or ["no message"]
        opened = any(line.startswith("Input #") for line in lines)
        reason = "no video stream" if opened and not video else said[-1]
        raise TrackingError(f"ffmpeg cannot read a video stream from it ({reason})", path=path)
    rate = re.search(r" ([0-9]+\.?[0-9]*) fps", video[0])
    return {"fps": float(rate.group(1)) if rate else 0.0,
            "source_size": _frame_size(video[0]), "size": _frame_size(video[-1]),
            "audio": any(line.lstrip().startswith("Stream ") and " Audio: " in line
                         for line in lines)}


def _ffmpeg_says(command: list[str]) -> str:
    """What ffmpeg ``command`` writes to stderr (it may fail: ``-i`` alone always does)."""
    try:
        done = subprocess.run(command, stdin=subprocess.DEVNULL, capture_output=True,
                              timeout=_HEADER_TIMEOUT_S, check=False)
    except subprocess.TimeoutExpired as exc:
        raise TrackingError(f"ffmpeg took over {_HEADER_TIMEOUT_S} s to read its header",
                            path=Path(command[command.index("-i") + 1])) from exc
    return done.stderr.decode(errors="replace")


def _frame_size(line: str) -> tuple[int, int]:
    """The ``(width, height)`` an ffmpeg stream line gives (its first ``640x480``)."""
    found = re.search(r" ([0-9]+)x([0-9]+)[, ]", line)
    if found is None:
        raise TrackingError(f"ffmpeg gives no frame size: {line.strip()!r}")
    return int(found.group(1)), int(found.group(2))


def read_video(path: str | os.PathLike[str]) -> tuple[VideoInfo, Iterator[np.ndarray]]:
    """The video's :class:`VideoInfo` and an iterator of ``(H, W, 3) uint8`` RGB frames.

    The frames come evenly spaced in time at the whole rate nearest the video's average (a
    .fap holds whole rates: 30 for NTSC's 29.97): ffmpeg repeats or drops frames by their
    timestamps, which also evens out a variable-rate video (as phones record), so frame
    ``i`` shows time ``i / fps``. TrackingError if the file is missing or ffmpeg finds no
    video stream in it.
    """
    path = Path(path)
    if not path.is_file():
        raise TrackingError(f"video {str(path)!r} does not exist")
    meta = _probe(path)
    average = float(meta.get("fps") or 0)
    if not average > 0:
        raise TrackingError("the video has no frame rate", path=path)
    fps = float(max(1, round(average)))
    if fps != average:
        log.info("%s: read at %g frames a second (the video's average is %g)", path, fps,
                 average)
    if meta["source_size"] != meta["size"]:
        log.info("%s: stored %s, read %s: ffmpeg turns the frames as the file says", path,
                 "x".join(map(str, meta["source_size"])), "x".join(map(str, meta["size"])))
    width, height = (int(v) for v in meta["size"])
    info = VideoInfo(fps, width, height, meta["audio"])
    return info, _decode(path, fps, width, height)


def _decode(path: Path, fps: float, width: int, height: int) -> Iterator[np.ndarray]:
    """``(height, width, 3) uint8`` RGB frames of ``path`` at ``fps`` from one ffmpeg, read
    from a pipe that holds a whole frame (Linux: with the default 64 KiB one the switches
    between ffmpeg and this process cost an eighth of ffmpeg's own decoding time), decoding
    on one thread (ffmpeg's frame threads took the core MediaPipe runs on in bursts: the
    whole path ran at 0.64 of MediaPipe's speed with them, 0.72 without)."""
    size = width * height * 3
    command = [_imageio_ffmpeg().get_ffmpeg_exe(), "-nostdin", "-hide_banner", "-loglevel",
               "error", "-threads", "1", "-i", str(path), "-vf", f"fps={fps!r}", "-f",
               "rawvideo", "-pix_fmt", "rgb24", "-"]
    with tempfile.TemporaryFile() as errors, subprocess.Popen(
            command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=errors) as ffmpeg:
        assert ffmpeg.stdout is not None
        _widen(ffmpeg.stdout.fileno(), size)
        _behind(ffmpeg.pid)
        try:
            while raw := ffmpeg.stdout.read(size):
                if len(raw) < size:
                    errors.seek(0)
                    said = errors.read().decode(errors="replace").strip().splitlines()
                    raise TrackingError(f"ffmpeg stopped within a frame ({(said or [''])[-1]})",
                                        path=path)
                yield np.frombuffer(raw, np.uint8).reshape(height, width, 3)
        finally:
            if ffmpeg.poll() is None:
                ffmpeg.kill()


_DECODER_NICE = 5
"""How much nicer than this process the decoding ffmpeg runs: it has frames in hand (the
pipe's and :func:`~facelib.tracking.overlap.read_ahead`'s), so where the two share a core,
the tracker's threads come first."""


def _behind(pid: int) -> None:
    """Run process ``pid`` :data:`_DECODER_NICE` steps nicer than this one (at most 19);
    where that cannot be done (not POSIX, refused) it runs as it is."""
    with suppress(AttributeError, OSError):
        here = os.getpriority(os.PRIO_PROCESS, 0)
        os.setpriority(os.PRIO_PROCESS, pid, min(19, here + _DECODER_NICE))


_PIPE_MAX = 1 << 20
"""The largest pipe Linux lets a process ask for by default (``/proc/sys/fs/pipe-max-size``)."""


def _widen(pipe: int, size: int) -> None:
    """Ask for the pipe ``pipe`` (a file descriptor) to hold ``size`` bytes, at most
    :data:`_PIPE_MAX`; where that cannot be asked (not Linux) or is refused, it stays."""
    with suppress(ImportError, AttributeError, OSError):
        import fcntl

        fcntl.fcntl(pipe, fcntl.F_SETPIPE_SZ, min(size, _PIPE_MAX))


def extract_audio(video: str | os.PathLike[str], wav: str | os.PathLike[str]) -> Path:
    """Decode the first audio stream of ``video`` into the 16-bit PCM WAV ``wav`` with the
    bundled ffmpeg (for muxing it into the mirror video). TrackingError if it fails."""
    exe = _imageio_ffmpeg().get_ffmpeg_exe()
    done = subprocess.run(
        [exe, "-nostdin", "-hide_banner", "-loglevel", "error", "-y", "-i", str(video),
         "-map", "0:a:0", "-vn", "-c:a", "pcm_s16le", "-f", "wav", str(wav)],
        capture_output=True, text=True, check=False)
    if done.returncode != 0:
        message = (done.stderr.strip().splitlines() or ["ffmpeg failed"])[-1]
        raise TrackingError(f"cannot extract its audio: {message}", path=Path(video))
    return Path(wav)


class _BrowPass:
    """The brows' image shifts (:mod:`~facelib.tracking.browimage`) read in the tracking
    pass itself, so the video is decoded once: against a provisional neutral (the frames
    asked for, or the first with a face), the frames up to its end held until its
    templates are made. :meth:`result` gives them when the track's final neutral is the
    same frames, else None (then :func:`video_brows` reads the video again)."""

    HOLD = 64
    """Frames held at most while waiting for the neutral's end (64 MB at 640x480)."""
    BATCH = 32
    """Frames registered at a time after it (their poses are fitted together)."""

    def __init__(self, neutral: int | tuple[int, int] | None, model: ObservationModel):
        self.model = model
        self.asked = neutral
        self.span: slice | None = None
        self.held: list[tuple[np.ndarray, np.ndarray]] = []
        self.shifts: list[np.ndarray] = []
        self.failed = False
        self.patches: Any = None
        self.rest: Any = None
        self.frames = np.zeros(0, np.int64)
        self.pending: list[tuple[np.ndarray, np.ndarray]] = []

    def _flush(self) -> None:
        from facelib.tracking.browimage import brow_features

        if self.pending:
            self.shifts.extend(brow_features((image for image, _ in self.pending),
                                             np.stack([p for _, p in self.pending]),
                                             self.patches, self.rest, self.model))
            self.pending = []

    def add(self, image: np.ndarray, points: np.ndarray) -> None:
        """Take the next frame and its ``(478, 3)`` landmarks (NaN: no face)."""
        if self.failed:
            return
        if self.patches is not None:
            self.pending.append((image, points))
            if len(self.pending) == self.BATCH:
                self._flush()
            return
        self.held.append((image, points))
        if self.span is None:
            if self.asked is None:
                if np.isfinite(points).all():
                    self.span = slice(len(self.held) - 1, len(self.held))
            else:
                start, stop = ((self.asked, self.asked + 1) if isinstance(self.asked, int)
                               else self.asked)
                self.span = slice(start, stop)
        if (self.span is not None and self.span.stop > self.HOLD) or len(self.held) > self.HOLD:
            self.failed, self.held = True, []
        elif self.span is not None and len(self.held) == self.span.stop:
            self._start()

    def _start(self) -> None:
        from facelib.tracking.browimage import brow_features, brow_patches
        from facelib.tracking.headframe import neutral_face, neutral_frames
        from facelib.tracking.layouts import landmark_layout

        assert self.span is not None
        points = np.stack([p for _, p in self.held])
        lost = np.flatnonzero(~face_found(points)).tolist()
        try:
            frames = neutral_frames(self.span, lost)
        except TrackingError:
            self.failed, self.held = True, []
            return
        filled = points.copy()
        filled[lost] = points[frames[0]]  # the neutral face reads the neutral frames alone
        self.rest = neutral_face(filled, layout=landmark_layout("mediapipe"), span=self.span,
                                 lost=lost)
        self.frames = frames
        self.patches = brow_patches((self.held[i][0] for i in frames), filled[frames],
                                    self.rest, self.model)
        self.shifts = list(brow_features((image for image, _ in self.held), points,
                                         self.patches, self.rest, self.model))
        self.held = []

    def result(self, neutral: tuple[int, int], landmarks: np.ndarray) -> np.ndarray | None:
        """``(n, 4)`` shifts when the final ``neutral`` span of the ``(n, 478, 3)`` final
        ``landmarks`` (NaN: lost) is the provisional one's frames, else None."""
        from facelib.tracking.headframe import neutral_frames

        if not self.failed and self.patches is not None:
            self._flush()
        if self.failed or self.patches is None or len(self.shifts) != len(landmarks):
            return None
        lost = np.flatnonzero(~face_found(landmarks)).tolist()
        try:
            frames = neutral_frames(slice(*neutral), lost)
        except TrackingError:
            return None
        if not np.array_equal(frames, self.frames):
            return None
        out = np.stack(self.shifts)
        out[~face_found(landmarks)] = np.nan
        return out


_COUNT_EVERY = 10
"""Frames apart at which faces are counted while the face mesh looks for one."""


class _Faces:
    """The face of a video tracked by MediaPipe's face mesh looking for one face, with the
    faces counted (:class:`~facelib.tracking.mediapipe.FaceCounter`) on every tenth frame,
    on each after one with several, back over the frames since the last count when one finds
    several, and where the face is found after none; the same landmarks, at about three
    quarters of the cost of the face mesh looking for two faces in every frame. Where the
    face is found beside others the rest is tracked looking for ``max_faces``, keeping the
    largest face or
    the one overlapping the face kept before most (:mod:`~facelib.tracking.mediapipe`), as
    one face mesh looking for several would throughout. ``max_faces`` 1: no counting."""

    def __init__(self, max_faces: int) -> None:
        self.max_faces = max_faces
        self.counts: list[int] = []
        """Faces seen per frame so far (0: no face found)."""
        self.mesh = FaceMeshTracker(video=True, max_faces=1)
        self.counter = FaceCounter() if max_faces > 1 else None
        self.held: list[tuple[int, np.ndarray]] = []  # the frames since the last count
        self.several = False  # the last count found several faces
        self.kept: np.ndarray | None = None  # the box of the face kept last

    def detect(self, image: np.ndarray, beside: InOrder) -> FaceLandmarks | None:
        """The next frame's face (:meth:`FaceMeshTracker.detect`); its faces are counted on
        ``beside``'s thread, or here, after the calls before, where the face is found after
        none (the count decides whether to look for several from this frame on)."""
        found = self.mesh.detect(image)
        index = len(self.counts)
        self.counts.append(0 if found is None else found.n_faces)
        if self.counter is not None:
            if found is not None and (index == 0 or not self.counts[index - 1]):
                beside.wait()
                found = self._acquired(image, found)
            else:
                beside.submit(partial(self._count, index, image))
        if found is not None:
            self.kept = found.box
        return found

    def _acquired(self, image: np.ndarray, found: FaceLandmarks) -> FaceLandmarks | None:
        """Count the faces of the last frame, where the face is found after none: beside
        others, the face mesh looks for several from here on."""
        assert self.counter is not None
        n = self.counter.count(image)
        if n < 2:
            self._counted(len(self.counts) - 1, n)
            return found
        self.counter.close()
        self.counter = None
        self.mesh.close()
        self.mesh = FaceMeshTracker(video=True, max_faces=self.max_faces, follow=self.kept)
        again = self.mesh.detect(image)
        self.counts[-1] = 0 if again is None else again.n_faces
        return again

    def _count(self, index: int, image: np.ndarray) -> None:
        """Frame ``index`` (``image``): counted if due (ten frames on, or after one with
        several), else held until the next count."""
        if self.counter is None:  # looking for several since
            return
        if self.several or len(self.held) + 1 >= _COUNT_EVERY:
            self._counted(index, self.counter.count(image))
        else:
            self.held.append((index, image))

    def _counted(self, index: int, n: int) -> None:
        """Frame ``index`` has ``n`` faces: so have those held before it that also have
        several (counted back to one that has not)."""
        assert self.counter is not None
        if n > 1 and not self.several:
            for earlier, held in reversed(self.held):
                found = self.counter.count(held)
                if found < 2:
                    break
                self._set(earlier, found)
        self._set(index, n)
        self.several, self.held = n > 1, []

    def finish(self) -> None:
        """Count the last frame if it was not (the video ended between counts)."""
        if self.counter is not None and self.held:
            index, image = self.held.pop()
            self._counted(index, self.counter.count(image))

    def _set(self, frame: int, n: int) -> None:
        """Count ``n`` faces in ``frame`` where the face mesh found one."""
        if self.counts[frame]:
            self.counts[frame] = min(max(n, 1), self.max_faces)

    def close(self) -> None:
        """Release MediaPipe's graphs."""
        self.mesh.close()
        if self.counter is not None:
            self.counter.close()


def _after_landmarks(image: np.ndarray, points: np.ndarray, box: np.ndarray | None,
                     light: list[float], brows: _BrowPass | None) -> None:
    """A frame's work after its ``(478, 3)`` landmarks: the brows' registration and the
    face's light (appended to ``light``; NaN where ``box`` is None: no face)."""
    if brows is not None:
        brows.add(image, points)
    light.append(float("nan") if box is None else _face_light(image, box))


def _opened(path: str | os.PathLike[str]
            ) -> tuple[VideoInfo, Generator[np.ndarray, None, None], np.ndarray | None]:
    """:func:`read_video` with the frames read ahead (:func:`read_ahead`) and the first of
    them decoded (None: the video has none): ffmpeg's start and first frame while
    MediaPipe's graphs load. Close the generator when done."""
    info, decoded = read_video(path)
    ahead = read_ahead(decoded)
    try:
        return info, ahead, next(ahead, None)
    except BaseException:
        ahead.close()
        raise


def _faces_and_video(
    path: str | os.PathLike[str], wanted: int,
) -> tuple[_Faces, tuple[VideoInfo, Generator[np.ndarray, None, None], np.ndarray | None]]:
    """MediaPipe's graphs for ``wanted`` faces and the opened video (:func:`_opened`),
    ffmpeg probing and decoding while the graphs load; neither is left open on an error."""
    with ThreadPoolExecutor(1) as pool:
        opening = pool.submit(_opened, path)
        try:
            faces = _Faces(wanted)
        except BaseException:
            with suppress(BaseException):
                opening.result()[1].close()
            raise
        try:
            return faces, opening.result()
        except BaseException:
            faces.close()
            raise


def track_video(path: str | os.PathLike[str], *, max_frames: int | None = None,
                max_faces: int = 2, _brows: _BrowPass | None = None) -> VideoTrack:
    """Track a face through a video with MediaPipe's face mesh (the largest at first, then
    the one overlapping it most: :mod:`~facelib.tracking.mediapipe`), ``max_faces`` looked
    for (2: a second person is noticed; faces are counted on some frames only, so one seen
    for under ten frames may go unnoticed, see :class:`_Faces`).

    Raises TrackingError if the video has no frames or no face in any frame; warns
    (:class:`TrackingWarning`) naming the frames with several faces.
    """
    limit = None if max_frames is None else check_count("max_frames", max_frames, low=1)
    faces, (info, ahead, first) = _faces_and_video(
        path, check_count("max_faces", max_faces, low=1))
    points: list[np.ndarray] = []
    light: list[float] = []
    lost = np.full((N_LANDMARKS, 3), np.nan)
    frames = ahead if first is None else chain([first], ahead)
    try:
        with InOrder() as beside:  # the work after the landmarks, beside the next frame's
            for i, image in enumerate(frames):
                if limit is not None and i >= limit:
                    break
                found = faces.detect(image, beside)
                points.append(lost if found is None else found.points)
                beside.submit(partial(_after_landmarks, image, points[-1],
                                      None if found is None else found.box, light, _brows))
            beside.submit(faces.finish)
    finally:
        ahead.close()
        faces.close()
    if not points:
        raise TrackingError("the video has no frames", path=Path(path))
    n_faces = np.array(faces.counts, np.int16)
    if not n_faces.any():
        raise TrackingError(f"no face found in any of its {len(points)} frames",
                            path=Path(path))
    several = np.flatnonzero(n_faces > 1)
    if several.size:
        warnings.warn(TrackingWarning(
            f"{Path(path).name}: several faces in frames {frame_spans(several)}; followed "
            "the one tracked before (the largest at first)"), stacklevel=2)
    landmarks = np.stack(points)
    edges = np.flatnonzero(_beside_losses(n_faces > 0))
    if edges.size == np.count_nonzero(n_faces):
        raise TrackingError(f"the face is seen only in frames {frame_spans(edges)} of "
                            f"{len(points)}, as it enters or leaves the picture",
                            path=Path(path))
    if edges.size:
        landmarks[edges] = np.nan
        warnings.warn(TrackingWarning(
            f"{Path(path).name}: frames {frame_spans(edges)} taken as lost too: the face "
            "leaves or enters the picture beside them"), stacklevel=2)
    return VideoTrack(Path(path), info, landmarks, n_faces, np.array(light))


_LONG_LOSS = 5
"""Frames without a face that make a loss (the face left the picture), not a dropout."""
_BESIDE_LOSS = 2
"""Frames either side of a loss taken as lost too."""


def _beside_losses(found: np.ndarray) -> np.ndarray:
    """``(n,) bool`` the frames with a face (``found``) within two frames of a loss of at
    least five: MediaPipe follows a face that leaves or enters the picture quickly with a
    wrong pose (a gaping jaw, a sideways look) for a frame or two, which would otherwise be
    held through the loss."""
    beside = np.zeros(len(found), bool)
    edges = np.flatnonzero(np.diff(np.concatenate([[1], found.astype(np.int8), [1]])))
    for start, stop in zip(edges[::2], edges[1::2], strict=True):  # runs of lost frames
        if stop - start >= _LONG_LOSS:
            beside[max(0, start - _BESIDE_LOSS):start] = True
            beside[stop:stop + _BESIDE_LOSS] = True
    return beside & found


def video_brows(path: str | os.PathLike[str], landmarks: np.ndarray, *,
                neutral: int | tuple[int, int] | None = None,
                model: ObservationModel | None = None) -> np.ndarray:
    """``(n, 4)`` the brows' image shifts (:mod:`~facelib.tracking.browimage`) of the
    video's first ``n`` frames, tracked as ``(n, 478, 3)`` ``landmarks`` with the neutral
    frame(s) as for :func:`~facelib.tracking.faps.measure_faps`; ``model``: the
    observation model whose pose correction the brows are sampled with (default: the
    packaged one). Reads the video twice more."""
    def frames() -> Iterator[np.ndarray]:
        return islice(read_video(path)[1], len(landmarks))

    return track_brows(frames, landmarks, neutral=neutral,
                       model=default_observation() if model is None else model)


def track_video_faps(path: str | os.PathLike[str], *, max_frames: int | None = None,
                     **options: Any) -> tuple[VideoTrack, TrackedFaps]:
    """:func:`track_video`, then :func:`~facelib.tracking.faps.measure_faps` at the video's
    frame rate (``options`` go to it: ``neutral``, by default the first frame with a
    well-lit face, :meth:`VideoTrack.default_neutral`; ``fapu``, ``smooth``, ``states``) with
    the brows' image shifts (:func:`video_brows`) for the learned model (``rig``
    ``"auto"``, ``"observed"`` or an observation model) unless ``brows=None`` is given."""
    rig = options.get("rig", "auto")
    wanted = "brows" not in options and (rig in ("auto", "observed")
                                         or isinstance(rig, ObservationModel))
    model = rig if isinstance(rig, ObservationModel) else default_observation()
    asked = options.get("neutral")
    brow_pass = _BrowPass(asked, model) if wanted else None
    track = track_video(path, max_frames=max_frames, _brows=brow_pass)
    if asked is None:
        span = track.default_neutral().span
        options["neutral"] = (span.start, span.stop)
    if brow_pass is not None:
        neutral = options["neutral"]
        start, stop = (neutral, neutral + 1) if isinstance(neutral, int) else neutral
        shifts = brow_pass.result((start, stop), track.landmarks)
        options["brows"] = (shifts if shifts is not None else
                            video_brows(path, track.landmarks, neutral=neutral, model=model))
    return track, measure_faps(track.landmarks, fps=track.info.fps, layout="mediapipe",
                               **options)

