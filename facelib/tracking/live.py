"""Live performance-driven animation: FAPs frame by frame as a camera delivers them (the
first seed's Virtual Mirror, section 5.2, live).

:func:`~facelib.tracking.faps.measure_faps` sees a whole recorded track: it fills lost
frames from both sides and filters both ways. Live, a frame's FAPs are due as soon as its
landmarks are, so :class:`LiveFaps` differs in four ways and measures alike otherwise
(the brows read off each frame's image too, when it is given):

- the neutral face is the first ``neutral_frames`` frames with a face (hold still for a
  second when the camera starts);
- a frame without a face repeats the last frame's FAPs;
- the One Euro filter runs forward only (a frame or two of lag on fast motion);
- the mouth state's hysteresis carries over from frame to frame.

:func:`run_camera` drives it from a camera (or any source OpenCV opens: a device path, a
stream address, a video file played as if live) and shows the mirror in a window.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from facelib.checks import check_count, check_fps
from facelib.errors import ParameterError, TrackingError
from facelib.tracking.browimage import BrowPatches, brow_features, brow_patches
from facelib.tracking.faps import (
    FilterBand,
    Model,
    checked_inputs,
    filter_bands,
    measure_frames,
    mouth_closed,
    settle_faps,
)
from facelib.tracking.headframe import Neutral, neutral_face
from facelib.tracking.layouts import LandmarkLayout
from facelib.tracking.mediapipe import N_LANDMARKS
from facelib.tracking.observation import ObservationModel
from facelib.tracking.smoothing import EuroState, one_euro_step

__all__ = ["LiveFaps", "LiveRecording", "run_camera"]


class LiveFaps:
    """FAPs of one frame at a time (:meth:`push`), measured as
    :func:`~facelib.tracking.faps.measure_faps` measures a track, causally.

    ``fps``: the frames' rate; ``neutral_frames``: how many of the first frames with a face
    make the neutral; ``layout``, ``rig``, ``smooth`` and ``close_lips``: as in
    :func:`~facelib.tracking.faps.measure_faps`.
    """

    def __init__(self, *, fps: float, neutral_frames: int = 25,
                 layout: str | LandmarkLayout = "mediapipe",
                 rig: Model | Literal["auto", "default", "observed"] | None = "auto",
                 smooth: bool = True, close_lips: bool = True) -> None:
        self.fps = check_fps(fps)
        self.neutral_frames = check_count("neutral_frames", neutral_frames, low=1)
        self._options: dict[str, Any] = {"layout": layout, "rig": rig}
        self._smooth = smooth
        self._close_lips = close_lips
        self._collected: list[np.ndarray] = []
        self._images: list[np.ndarray | None] = []
        self._patches: BrowPatches | None = None
        self._neutral: Neutral | None = None
        self._layout: LandmarkLayout | None = None
        self._model: Model | None = None
        self._bands: list[FilterBand] | None = None
        self._euro: list[EuroState | None] = []
        self._closed = False
        self._last: np.ndarray | None = None
        self.mask: np.ndarray | None = None
        """``(84,) bool`` the FAPs each frame's values hold (None until the first)."""
        self.brows: np.ndarray | None = None
        """``(4,)`` the last frame's brow image shifts (None when not read)."""
        self.neutral_brows: np.ndarray | None = None
        """``(neutral_frames, 4)`` the neutral frames' brow image shifts, once read."""

    @property
    def neutral(self) -> Neutral | None:
        """The neutral face, once its frames are in."""
        return self._neutral

    def push(self, landmarks: np.ndarray | None, image: np.ndarray | None = None, *,
             dt: float | None = None) -> np.ndarray | None:
        """The ``(84,) float64`` FAP values of the next frame from its ``(K, D)`` landmarks
        (image coordinates as for :func:`~facelib.tracking.faps.measure_faps`; None or
        NaN: no face): None while the neutral frames are being collected, the last values
        again for a frame without a face. With the frame's ``(H, W, 3) uint8`` RGB
        ``image`` (every frame's, the neutral ones' included), the brows are also read off
        the image (:mod:`~facelib.tracking.browimage`), as for a video. ``dt``: seconds
        since the previous frame, for the filter (default ``1 / fps``; a camera's frames
        come when they come)."""
        if landmarks is None or not np.isfinite(landmarks).all():
            return None if self._last is None else self._last.copy()
        frame = np.asarray(landmarks, np.float64)
        first = self._neutral.rest if self._neutral is not None else (
            self._collected[0] if self._collected else frame)
        if frame.shape != first.shape:
            raise TrackingError(f"landmarks of shape {frame.shape} after ones of {first.shape}")
        if self._neutral is None:
            self._collect(frame, image)
            return None
        assert self._layout is not None
        row = frame[None]
        lips = self._close_lips and self._model is not None and self._layout.name == "mediapipe"
        brows = None
        if self._patches is not None and image is not None:
            assert isinstance(self._model, ObservationModel)
            brows = brow_features([image], row, self._patches, self._neutral, self._model)
        self.brows = None if brows is None else brows[0]
        found = measure_frames(row, self._neutral, layout=self._layout, model=self._model,
                               lips=lips, brows=brows)
        values = found.values[0]
        if self._smooth:
            values = self._filter(values, found.mask[0], 1.0 / self.fps if dt is None else dt)
        state = None
        if found.aperture is not None:
            closed = mouth_closed(found.aperture, closed=self._closed)
            self._closed = bool(closed[-1])
            state = (found.aperture, closed)
        out, mask = settle_faps(values[None], found.mask, lips=state)
        self._last, self.mask = out[0], mask[0]
        return out[0].copy()

    def _collect(self, landmarks: np.ndarray, image: np.ndarray | None) -> None:
        """Keep a neutral frame (and its image); with the last one in, fix the neutral,
        layout and model, and the brow patches when every neutral frame had an image and
        the model reads them."""
        self._collected.append(landmarks)
        self._images.append(image)
        if len(self._collected) < self.neutral_frames:
            return
        data, self._layout, self._model = checked_inputs(np.stack(self._collected),
                                                         **self._options)
        self._neutral = neutral_face(data, layout=self._layout, span=slice(0, len(data)))
        images = [i for i in self._images if i is not None]
        if (isinstance(self._model, ObservationModel) and self._model.image_faps is not None
                and len(images) == len(data)):
            self._patches = brow_patches(images, data, self._neutral, self._model)
            self.neutral_brows = brow_features(images, data, self._patches, self._neutral,
                                               self._model)
        self._collected, self._images = [], []

    def _filter(self, values: np.ndarray, measured: np.ndarray, dt: float) -> np.ndarray:
        """``(84,)`` values through the causal One Euro filter over the ``(84,) bool``
        ``measured`` columns (the same every frame), band by band, ``dt`` seconds after the
        last frame."""
        if self._bands is None:
            self._bands = filter_bands(measured)
            self._euro = [None] * len(self._bands)
        out = values.copy()
        for i, band in enumerate(self._bands):
            state = one_euro_step(values[band.cols] * band.scale, self._euro[i],
                                  dt=dt, min_cutoff=band.min_cutoff,
                                  beta=band.beta, d_cutoff=band.d_cutoff)
            self._euro[i] = state
            out[band.cols] = state.value / band.scale
        return out


@dataclass(frozen=True)
class LiveRecording:
    """What :func:`run_camera` recorded.

    Attributes
    ----------
    landmarks: ``(n, 478, 3) float64`` MediaPipe landmarks per frame (NaN: no face).
    values: ``(n, 84) float64`` the FAPs shown live (NaN while the neutral was collected).
    brows: ``(n, 4) float64`` the brows' image shifts (NaN where not read).
    fps: the frames' rate: the source's, or for a camera (and a source that does not say)
        the rate frames were read at (30 for a single frame that does not say).
    """

    landmarks: np.ndarray
    values: np.ndarray
    brows: np.ndarray
    fps: float


_QUIT_KEYS = (ord("q"), 27)
"""Keys that end a live session in the window: q and Esc."""
_HOLD_STILL = "hold a neutral face"


def _mirror_image(camera: np.ndarray, avatar: np.ndarray | None, *, collecting: bool
                  ) -> np.ndarray:
    """The window's BGR image: the ``(H, W1, 3)`` BGR camera image and the ``(H, W2, 3)``
    RGB avatar (grey while there is none) joined as the recorded mirror joins them
    (:func:`~facelib.tracking.mirror.mirror_frames`, neither flipped)."""
    import cv2

    from facelib.tracking.mirror import mirror_frames

    height = camera.shape[0]
    right = (np.full((height, height * 4 // 3, 3), 40, np.uint8) if avatar is None
             else avatar[..., ::-1])
    image = next(mirror_frames(iter([camera]), iter([right])))
    if collecting:
        cv2.putText(image, _HOLD_STILL, (16, 36), cv2.FONT_HERSHEY_SIMPLEX, 1.0,
                    (60, 220, 60), 2, cv2.LINE_AA)
    return image


def run_camera(source: int | str = 0, *, face: Any = None, neutral_frames: int = 25,
               window: bool = True, max_frames: int | None = None) -> LiveRecording:
    """Track ``source`` live and show the mirror: the camera and ``face`` (default: the
    bundled head) moving with it, until the source ends, ``max_frames`` frames, q or Esc in
    the window, or Ctrl-C.

    ``source``: a camera index, or anything OpenCV's ``VideoCapture`` opens (a device path,
    a stream address, a video file, which is then read as fast as it is processed);
    ``neutral_frames``: the first frames with a face that make the neutral;
    ``window``: show the mirror (needs a display; False tracks without one).
    TrackingError if the source does not open or gives no frame; ParameterError for a
    window without a display.
    """
    import cv2

    from facelib.tracking.mediapipe import FaceMeshTracker

    if window:
        from facelib.rendering.viewer import has_display

        if not has_display():
            raise ParameterError("no display for the mirror's window (DISPLAY and "
                                 "WAYLAND_DISPLAY are unset); track without a window")
    limit = None if max_frames is None else check_count("max_frames", max_frames, low=1)
    capture = cv2.VideoCapture(source)
    if not capture.isOpened():
        raise TrackingError(f"cannot open the camera or stream {source!r}")
    nominal = float(capture.get(cv2.CAP_PROP_FPS) or 0.0)
    camera = isinstance(source, int) or str(source).startswith("/dev/")
    live = LiveFaps(fps=nominal if nominal > 0 else 30.0, neutral_frames=neutral_frames)
    record = _Recorder()
    try:
        with FaceMeshTracker(video=True, max_faces=1) as tracker, \
                _Avatar(face, enabled=window) as avatar:
            while limit is None or len(record.points) < limit:
                ok, bgr = capture.read()
                if not ok:
                    break
                record.times.append(time.perf_counter())
                image = np.ascontiguousarray(bgr[..., ::-1])
                found = tracker.detect(image)
                collecting = live.neutral is None
                values = live.push(None if found is None else found.points, image,
                                   dt=_since(record.times) if camera else None)
                record.add(None if found is None else found.points, values, live,
                           collecting=collecting)
                if window and not avatar.show(bgr, values, live):
                    break
    except KeyboardInterrupt:
        pass
    finally:
        capture.release()
    if not record.points:
        raise TrackingError(f"no frame from {source!r}")
    return record.finish(None if camera or nominal <= 0 else nominal)


def _since(times: list[float]) -> float | None:
    """Seconds between the last two frames read (None for the first)."""
    return times[-1] - times[-2] if len(times) > 1 and times[-1] > times[-2] else None


@dataclass
class _Recorder:
    """What a live session keeps frame by frame (mutated only by :func:`run_camera`)."""

    points: list[np.ndarray] = field(default_factory=list)
    shown: list[np.ndarray] = field(default_factory=list)
    brows: list[np.ndarray] = field(default_factory=list)
    neutral_rows: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)

    def add(self, points: np.ndarray | None, values: np.ndarray | None, live: LiveFaps, *,
            collecting: bool) -> None:
        """Keep a frame's landmarks (None: no face), the FAPs shown (None: none yet) and the
        brow shifts ``live`` read; while ``collecting`` the neutral, note its frames and
        fill in their shifts once it is in."""
        self.points.append(np.full((N_LANDMARKS, 3), np.nan) if points is None else points)
        self.shown.append(np.full(84, np.nan) if values is None else values)
        self.brows.append(np.full(4, np.nan) if collecting or points is None
                          or live.brows is None else live.brows)
        if collecting and points is not None:
            self.neutral_rows.append(len(self.brows) - 1)
            if live.neutral_brows is not None:
                for row, shifts in zip(self.neutral_rows, live.neutral_brows, strict=True):
                    self.brows[row] = shifts

    def finish(self, fps: float | None) -> LiveRecording:
        """The recording at ``fps``, or (None) at the rate the frames came at."""
        times = self.times
        if fps is None:
            fps = ((len(times) - 1) / (times[-1] - times[0])
                   if len(times) > 1 and times[-1] > times[0] else 30.0)
        return LiveRecording(np.stack(self.points), np.stack(self.shown),
                             np.stack(self.brows), fps)


class _Avatar:
    """The mirror window: renders ``face`` with each frame's FAPs and shows it beside the
    camera image (a no-op unless ``enabled``)."""

    def __init__(self, face: Any, *, enabled: bool) -> None:
        self.enabled = enabled
        self._face = face
        self._renderer: Any = None

    def __enter__(self) -> _Avatar:
        if self.enabled:
            from facelib.engine import default_face
            from facelib.rendering import FaceRenderer

            self._face = default_face() if self._face is None else self._face
            self._renderer = FaceRenderer(self._face, width=480, height=360)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._renderer is not None:
            import cv2

            self._renderer.close()
            cv2.destroyAllWindows()

    def show(self, bgr: np.ndarray, values: np.ndarray | None, live: LiveFaps) -> bool:
        """Show one frame; False once q or Esc was pressed or the window was closed."""
        import cv2

        from facelib.mpeg4 import FapStream

        image = None
        if values is not None and live.mask is not None:
            vertices = self._face.deform(FapStream(live.fps, values[None], live.mask[None]))
            image = self._renderer.frame(np.asarray(vertices[0], np.float32))
        scale = 360 / bgr.shape[0]
        small = cv2.resize(bgr, (round(bgr.shape[1] * scale), 360))
        cv2.imshow("facelib mirror", _mirror_image(small, image, collecting=values is None))
        key = cv2.waitKey(1) & 0xFF
        closed = cv2.getWindowProperty("facelib mirror", cv2.WND_PROP_VISIBLE) < 1
        return key not in _QUIT_KEYS and not closed
