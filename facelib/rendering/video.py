"""Writing rendered frames: PNG stills, PNG frame folders, MP4 (H.264 + audio) and GIF.

Every writer is atomic: frames go to a temporary file or folder beside the target, which is
renamed onto the target only when all frames were written; on any error the temporary is
removed and the target is left as it was. MP4 and GIF go through the ffmpeg binary shipped
by the ``imageio-ffmpeg`` wheel, fed raw RGB frames on a pipe (nothing held in memory).
"""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import tempfile
import zlib
from collections.abc import Iterable
from pathlib import Path
from typing import Protocol

import numpy as np

from facelib.atomic import atomic_path, publish, temp_beside
from facelib.checks import check_fps, check_sample_rate
from facelib.errors import ParameterError, RenderError
from facelib.optional import require

__all__ = [
    "FrameWriter",
    "encode_png",
    "ffmpeg_exe",
    "open_writer",
    "probe_video",
    "save_png",
    "write_video",
]

_FRAME_NAME = "frame_{:06d}.png"


# -- PNG ---------------------------------------------------------------------------------


def _check_image(image: np.ndarray) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] not in (3, 4) or image.dtype != np.uint8:
        raise ParameterError(
            f"an image must be (H, W, 3 or 4) uint8, got {image.shape} {image.dtype}"
        )
    return np.ascontiguousarray(image)


def encode_png(image: np.ndarray, *, level: int = 6) -> bytes:
    """PNG bytes of an ``(H, W, 3|4) uint8`` RGB(A) image (zlib ``level`` 0-9)."""
    image = _check_image(image)
    height, width, channels = image.shape
    rows = np.zeros((height, 1 + width * channels), np.uint8)  # filter byte 0 per row
    rows[:, 1:] = image.reshape(height, -1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", width, height, 8, 6 if channels == 4 else 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
            + chunk(b"IDAT", zlib.compress(rows.tobytes(), level)) + chunk(b"IEND", b""))


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _publish(tmp: Path, *, directory: bool = False) -> None:
    """Give a temporary from ``mkstemp``/``mkdtemp`` (private 0600/0700) the permissions a
    normally created file or folder would have under the current umask."""
    tmp.chmod((0o777 if directory else 0o666) & ~_umask())


def save_png(image: np.ndarray, path: str | os.PathLike[str]) -> Path:
    """Write an ``(H, W, 3|4) uint8`` image to ``path`` as PNG, atomically; returns the path."""
    data = encode_png(image)
    with atomic_path(path) as temp:
        temp.write_bytes(data)
    return Path(path)


# -- ffmpeg ------------------------------------------------------------------------------


def ffmpeg_exe() -> str:
    """Path of the ffmpeg binary shipped by ``imageio-ffmpeg``."""
    imageio_ffmpeg = require("ffmpeg_render")
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as exc:
        raise RenderError(f"imageio-ffmpeg has no ffmpeg binary for this platform: {exc}") from exc


def probe_video(path: str | os.PathLike[str]) -> dict[str, object]:
    """``{'frames': int, 'duration': float seconds, 'audio': bool}`` of a video file.

    Frames are counted by decoding (exact); ``audio`` says whether an audio stream exists.
    """
    import imageio_ffmpeg

    frames, duration = imageio_ffmpeg.count_frames_and_secs(str(path))
    info = subprocess.run(
        [ffmpeg_exe(), "-hide_banner", "-i", str(path)], capture_output=True, text=True,
        check=False,
    ).stderr
    audio = any("Stream #" in line and "Audio:" in line for line in info.splitlines())
    return {"frames": int(frames), "duration": float(duration), "audio": audio}


# -- writers -----------------------------------------------------------------------------


class FrameWriter(Protocol):
    """Receives frames one by one; ``commit`` makes the output appear, ``abort`` drops it."""

    path: Path

    def write(self, frame: np.ndarray) -> None: ...
    def commit(self) -> Path: ...
    def abort(self) -> None: ...


class _FfmpegWriter:
    def __init__(self, path: Path, args: list[str], size: tuple[int, int], fps: float,
                 *, audio: Path | None = None, audio_offset: float = 0.0):
        self.path = path
        self._size = size
        self._tmp = temp_beside(path)
        self._wav = None
        inputs = []
        if audio is not None:
            self._wav = temp_beside(path, suffix=".wav")
            try:
                _decode_audio(audio, self._wav)
            except BaseException:
                self._tmp.unlink(missing_ok=True)
                self._wav.unlink(missing_ok=True)
                raise
            if audio_offset < 0:
                inputs += ["-ss", f"{-audio_offset:.6f}"]
            inputs += ["-f", "wav", "-i", str(self._wav)]
        width, height = size
        command = [
            ffmpeg_exe(), "-hide_banner", "-loglevel", "error", "-y",
            "-protocol_whitelist", "file,pipe",
            "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}",
            "-framerate", f"{fps:.6g}", "-i", "pipe:0", *inputs, *args, str(self._tmp),
        ]
        self._log = tempfile.TemporaryFile()  # noqa: SIM115 (closed in commit/abort)
        self._proc = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                      stderr=self._log)
        self.n_frames = 0

    def _error(self, what: str) -> RenderError:
        self._log.seek(0)
        log = self._log.read().decode("utf-8", "replace").strip()
        return RenderError(f"ffmpeg failed {what} {self.path}: {log or 'no message'}")

    def write(self, frame: np.ndarray) -> None:
        frame = _check_image(frame)[:, :, :3]
        if frame.shape[:2] != (self._size[1], self._size[0]):
            raise ParameterError(
                f"frame {self.n_frames} is {frame.shape[1]}x{frame.shape[0]}, the video is "
                f"{self._size[0]}x{self._size[1]}"
            )
        assert self._proc.stdin is not None  # opened with stdin=PIPE
        try:
            self._proc.stdin.write(np.ascontiguousarray(frame).tobytes())
        except BrokenPipeError:
            self._proc.wait()
            error = self._error("while writing")
            self.abort()
            raise error from None
        self.n_frames += 1

    def commit(self) -> Path:
        assert self._proc.stdin is not None  # opened with stdin=PIPE
        self._proc.stdin.close()
        if self._proc.wait() != 0:
            error = self._error("while encoding")
            self.abort()
            raise error
        self._log.close()
        if self._wav is not None:
            self._wav.unlink(missing_ok=True)
        publish(self._tmp, self.path)
        return self.path

    def abort(self) -> None:
        if self._proc.poll() is None:
            self._proc.kill()
            self._proc.wait()
        self._log.close()
        self._tmp.unlink(missing_ok=True)
        if self._wav is not None:
            self._wav.unlink(missing_ok=True)


def _decode_audio(audio: Path, wav: Path) -> None:
    """Decode ``audio`` with libsndfile (soundfile) into the 16-bit WAV ``wav``, in blocks.

    ffmpeg is only ever given this WAV: a playlist, concat list or URL named as "audio"
    never reaches its demuxers. ParameterError naming the file if it is not a regular file
    libsndfile decodes.
    """
    import soundfile

    if not audio.is_file():
        raise ParameterError(f"audio file {str(audio)!r} does not exist or is not a file")
    try:
        with soundfile.SoundFile(str(audio)) as source:
            check_sample_rate(source.samplerate, source=f"audio file {str(audio)!r}")
            with soundfile.SoundFile(str(wav), "w", samplerate=source.samplerate,
                                     channels=source.channels, subtype="PCM_16",
                                     format="WAV") as out:
                for block in source.blocks(blocksize=65536, dtype="float32"):
                    out.write(block)
    except (RuntimeError, soundfile.LibsndfileError) as exc:
        raise ParameterError(f"audio file {str(audio)!r} cannot be decoded: {exc}") from None


class _PngFolderWriter:
    def __init__(self, path: Path):
        self.path = path
        if path.exists() and not path.is_dir():
            raise ParameterError(f"{path} exists and is not a folder; cannot write PNG frames")
        if path.is_dir():
            strangers = [p.name for p in path.iterdir() if not _is_frame_name(p.name)]
            if strangers:
                raise RenderError(
                    f"{path} already holds files other than frames (e.g. {strangers[0]!r}); "
                    "give an empty or new folder"
                )
        path.parent.mkdir(parents=True, exist_ok=True)
        self._tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", dir=path.parent))
        self.n_frames = 0

    def write(self, frame: np.ndarray) -> None:
        (self._tmp / _FRAME_NAME.format(self.n_frames)).write_bytes(encode_png(frame, level=3))
        self.n_frames += 1

    def commit(self) -> Path:
        _publish(self._tmp, directory=True)
        old = None
        if self.path.exists():
            old = self.path.with_name(f".{self.path.name}.old-{os.getpid()}")
            self.path.replace(old)
        self._tmp.replace(self.path)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return self.path

    def abort(self) -> None:
        shutil.rmtree(self._tmp, ignore_errors=True)


def _is_frame_name(name: str) -> bool:
    return name.startswith("frame_") and name.endswith(".png") and name[6:-4].isdigit()


def open_writer(
    path: str | os.PathLike[str],
    *,
    fps: float,
    width: int,
    height: int,
    audio: str | os.PathLike[str] | None = None,
    audio_offset: float = 0.0,
    duration: float | None = None,
    crf: int = 18,
) -> FrameWriter:
    """A writer for ``path`` chosen by its suffix.

    ``.mp4``: H.264 (yuv420p, ``crf`` quality 0-51, lower is better), with ``audio`` (a
    sound file libsndfile decodes: WAV, FLAC, Ogg, MP3, ...) muxed as AAC, starting
    ``audio_offset`` seconds into the video (negative skips the audio's beginning) and cut
    at ``duration`` seconds; ``.gif``: an
    optimised-palette animated GIF (no audio); no suffix or an existing folder: one
    ``frame_NNNNNN.png`` per frame.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    check_fps(fps)
    if audio is not None and suffix != ".mp4":
        raise ParameterError(f"audio can only be muxed into .mp4, not {path.name!r}")
    if suffix == ".mp4":
        if width % 2 or height % 2:
            raise ParameterError(
                f"H.264 needs an even width and height, got {width}x{height}"
            )
        args = ["-map", "0:v:0"]
        if audio is not None:
            args += ["-map", "1:a:0", "-c:a", "aac", "-b:a", "160k"]
            if audio_offset > 0:
                delay = round(audio_offset * 1000)
                args += ["-af", f"adelay={delay}:all=1"]
        args += ["-c:v", "libx264", "-preset", "medium", "-crf", str(int(crf)),
                 "-pix_fmt", "yuv420p", "-movflags", "+faststart"]
        if duration is not None:
            args += ["-t", f"{duration:.6f}"]
        return _FfmpegWriter(path, args, (width, height), fps,
                             audio=None if audio is None else Path(audio),
                             audio_offset=audio_offset)
    if suffix == ".gif":
        palette = "split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=bayer"
        return _FfmpegWriter(path, ["-vf", palette, "-loop", "0"], (width, height), fps)
    if suffix == "" or path.is_dir():
        return _PngFolderWriter(path)
    raise ParameterError(
        f"cannot tell what to write from {path.name!r}: use .mp4, .gif or a folder for PNG frames"
    )


def write_video(
    frames: Iterable[np.ndarray],
    path: str | os.PathLike[str],
    *,
    fps: float,
    width: int,
    height: int,
    audio: str | os.PathLike[str] | None = None,
    audio_offset: float = 0.0,
    duration: float | None = None,
) -> Path:
    """Write ``frames`` (each ``(height, width, 3) uint8``) through :func:`open_writer`
    (same options) and return the path; a failure removes what was written."""
    writer = open_writer(path, fps=fps, width=width, height=height, audio=audio,
                         audio_offset=audio_offset, duration=duration)
    try:
        for image in frames:
            writer.write(image)
    except BaseException:
        writer.abort()
        raise
    return writer.commit()
