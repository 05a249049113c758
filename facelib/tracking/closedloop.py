"""The closed loop: render a face with a known FAP stream, track the render, compare.

The check of the whole performance-driven path on any face (the default head, or your own
face definition): MediaPipe sees the rendered video as it would see a person, and the
recovered FAPs are compared with the ones that drove the render, curve by curve (Pearson
correlation and least-squares gain), blink by blink and lip closure by lip closure.
Needs the ``render`` and ``track`` extras.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from facelib.checks import check_count
from facelib.engine import Face, default_face
from facelib.errors import ParameterError
from facelib.mpeg4 import ANGLE_UNIT, FAPU_SCALE, N_FAPS, FapStream
from facelib.rendering import FaceRenderer, iter_frames
from facelib.tracking.browimage import track_brows
from facelib.tracking.faps import TrackedFaps, measure_faps
from facelib.tracking.mediapipe import N_LANDMARKS, FaceMeshTracker
from facelib.tracking.observation import default_observation
from facelib.tracking.pose import HEAD_FAP_IDS

__all__ = ["LIPS_TOUCH", "PROBE_PLAN", "ClosedLoop", "bilabial_closures", "closed_loop",
           "closure_events", "closure_recall", "curve_correlation", "curve_gain",
           "event_recall", "false_closures", "lip_closures", "lip_gap", "probe_stream",
           "still_face", "with_head_turns", "with_neutral_lead"]

LIPS_TOUCH = 0.1
"""Inner-lip gap (:func:`lip_gap`, in MNS0) under which the lips count as touching."""
BLINK_FAPS = (19, 20)
"""Upper-lid FAPs whose peaks are blinks."""


@dataclass(frozen=True)
class ClosedLoop:
    """The outcome of :func:`closed_loop`.

    Attributes
    ----------
    truth: the stream that drove the render.
    tracked: what tracking recovered (same frame count).
    landmarks: ``(n, 478, 3)`` MediaPipe landmarks of the render.
    frames: ``(n, H, W, 3) uint8`` the rendered frames (None unless ``keep_frames``).
    lead: ``(k, 478, 3)`` landmarks of the neutral lead frames (cut from ``landmarks``).
    brows: ``(k + n, 4)`` the brows' image shifts of the lead and the stream's frames
        (None when not read).
    """

    truth: FapStream
    tracked: TrackedFaps
    landmarks: np.ndarray
    frames: np.ndarray | None
    lead: np.ndarray | None = None
    brows: np.ndarray | None = None

    def remeasure(self, **options: Any) -> TrackedFaps:
        """The same landmarks measured again with other ``options`` of
        :func:`~facelib.tracking.faps.measure_faps` (e.g. ``rig="default"``), lead cut."""
        if self.lead is None or not len(self.lead):
            raise ParameterError("this closed loop kept no neutral lead frames")
        k = len(self.lead)
        options.setdefault("brows", self.brows)
        found = measure_faps(np.concatenate([self.lead, self.landmarks]), fps=self.truth.fps,
                             neutral=(0, k), **options)
        return _trim(found, k)

    def correlation(self, fap_id: int) -> float:
        """:func:`curve_correlation` of the true and recovered curves of FAP ``fap_id``."""
        return curve_correlation(self.truth.values[:, fap_id - 1],
                                 self.tracked.stream.values[:, fap_id - 1])

    def gain(self, fap_id: int) -> float:
        """:func:`curve_gain` of the recovered curve of FAP ``fap_id`` on the true one."""
        return curve_gain(self.truth.values[:, fap_id - 1],
                          self.tracked.stream.values[:, fap_id - 1])


def curve_correlation(truth: np.ndarray, found: np.ndarray) -> float:
    """Pearson correlation of two ``(n,)`` curves; NaN if either is constant."""
    a, b = np.asarray(truth, np.float64), np.asarray(found, np.float64)
    if a.std() == 0 or b.std() == 0:
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def curve_gain(truth: np.ndarray, found: np.ndarray) -> float:
    """Least-squares slope of the ``(n,)`` curve ``found`` on ``truth`` (1 = the right
    amplitude); NaN if ``truth`` is constant."""
    a, b = np.asarray(truth, np.float64), np.asarray(found, np.float64)
    a = a - a.mean()
    return float((a @ (b - b.mean())) / (a @ a)) if a @ a > 0 else float("nan")


def with_head_turns(stream: FapStream, *, frames: int | None = None) -> FapStream:
    """``stream`` (cut to ``frames``) with head pitch/yaw/roll replaced by slow sweeps that
    grow over the first second to 10, 20 and 8 degrees (periods 3.1, 4.0, 5.3 s)."""
    values = np.array(stream.values[:frames])
    mask = np.array(stream.mask[:frames])
    t = np.arange(len(values)) / stream.fps
    ramp = np.clip(t, 0, 1)
    for fap_id, degrees, period in ((48, 10, 3.1), (49, 20, 4.0), (50, 8, 5.3)):
        sweep = np.radians(degrees) * np.sin(2 * np.pi * t / period)
        values[:, fap_id - 1] = ramp * sweep / ANGLE_UNIT
        mask[:, fap_id - 1] = True
    return FapStream(stream.fps, values, mask)


PROBE_PLAN: tuple[tuple[tuple[int, float], ...], ...] = (
    ((3, 400.0),), ((59, 250.0), (60, 250.0)), ((12, 400.0), (13, 400.0)),
    ((31, 320.0), (32, 320.0), (33, 320.0), (34, 320.0), (35, 300.0), (36, 300.0)),
    ((3, 300.0), (12, 300.0), (13, 300.0)), ((59, -200.0), (60, -200.0)),
    ((19, 1000.0), (20, 1000.0)), ((3, 500.0),),
    ((31, -120.0), (32, -120.0), (37, 100.0), (38, 100.0)), ((53, 150.0), (54, 150.0)))
"""The probe stream's bumps, one after the other (FAP id, peak in FAP units), the eyes
looking ahead throughout: the jaw alone (so a gaze it leaks into shows), the outer lip
corners' raise apart from the inner ones and lowered, the brows raised to 300-320 (past
facelib's library, as people raise them), the jaw with a smile, a blink, a frown, the outer
corners' stretch. No storyboard moves FAPs one group at a time like this; the model never
trained on it (issue 37's closed loop)."""


def probe_stream(*, fps: float = 25.0, segment: int = 30, turns: bool = True,
                 plan: tuple[tuple[tuple[int, float], ...], ...] = PROBE_PLAN) -> FapStream:
    """Each bump of ``plan`` as a raised cosine over ``segment`` frames (2 frames of rest at
    either end), one after the other; with ``turns``, head sweeps of yaw 25, pitch 8 and
    roll 6 degrees (periods 4.5, 3.3 and 5.7 s, grown over the first second)."""
    check_count("segment", segment, low=5)
    n = segment * len(plan)
    values = np.zeros((n, N_FAPS))
    t = np.arange(n)
    for k, bump in enumerate(plan):
        a, b = k * segment + 2, (k + 1) * segment - 2
        inside = (t >= a) & (t < b)
        shape = np.where(inside, 0.5 - 0.5 * np.cos(2 * np.pi * (t - a) / (b - a)), 0.0)
        for fap_id, peak in bump:
            values[:, fap_id - 1] += peak * shape
    if turns:
        seconds = t / fps
        ramp = np.clip(seconds, 0, 1)
        for fap_id, degrees, period in ((48, 8, 3.3), (49, 25, 4.5), (50, 6, 5.7)):
            values[:, fap_id - 1] = (ramp * np.radians(degrees)
                                     * np.sin(2 * np.pi * seconds / period) / ANGLE_UNIT)
    return FapStream(fps, values.astype(np.float32))


def still_face(stream: FapStream) -> FapStream:
    """``stream`` with every FAP but the head's (48-50) at 0: the still face whose
    recovered curves measure the *wobble* head motion alone reads as expression
    (:mod:`facelib.tracking.agreement`)."""
    values = np.zeros_like(stream.values)
    heads = [f - 1 for f in HEAD_FAP_IDS]
    values[:, heads] = stream.values[:, heads]
    return FapStream(stream.fps, values)


def with_neutral_lead(stream: FapStream, frames: int) -> FapStream:
    """``stream`` with ``frames`` neutral frames (all FAPs 0) in front: the neutral span."""
    check_count("frames", frames)
    lead = FapStream(stream.fps, np.zeros((frames, N_FAPS), np.float32),
                     np.zeros((frames, N_FAPS), bool))
    body = FapStream(stream.fps, stream.values, stream.mask)
    return FapStream.concat([lead, body])


def closed_loop(stream: FapStream, *, face: Face | None = None, neutral_frames: int = 8,
                width: int = 640, height: int = 480, keep_frames: bool = False,
                framing: str = "head", brow_image: bool = True, **options: Any) -> ClosedLoop:
    """Render ``face`` (default head, framed as ``framing``: the whole head by default, as a
    webcam sees a person) driven by ``stream`` after ``neutral_frames`` neutral
    frames, track it with MediaPipe and recover the FAPs (``options`` go to
    :func:`~facelib.tracking.faps.measure_faps`), the brows' image shifts read off the
    frames as a video's are (:mod:`~facelib.tracking.browimage`) unless not
    ``brow_image``. The lead frames are cut from the result. The rendered frames are kept
    in memory while the brows are read (0.9 MB each at 640x480): a check of short clips.
    """
    face = default_face() if face is None else face
    full = with_neutral_lead(stream, neutral_frames)
    rendered: list[np.ndarray] = []
    points = np.full((full.n_frames, N_LANDMARKS, 3), np.nan)
    with FaceRenderer(face, width=width, height=height, framing=framing) as renderer, \
            FaceMeshTracker(video=True, max_faces=1) as tracker:
        for i, image in enumerate(iter_frames(renderer, face, full)):
            found = tracker.detect(image)
            if found is not None:
                points[i] = found.points
            if keep_frames or brow_image:
                rendered.append(image)
    neutral = (0, max(neutral_frames, 1))
    brows = (track_brows(lambda: iter(rendered), points, neutral=neutral,
                         model=default_observation()) if brow_image else None)
    tracked = measure_faps(points, fps=stream.fps, neutral=neutral, brows=brows, **options)
    cut = slice(neutral_frames, None)
    return ClosedLoop(FapStream(stream.fps, stream.values, stream.mask),
                      _trim(tracked, neutral_frames), points[cut],
                      np.stack(rendered)[cut] if keep_frames else None,
                      points[:neutral_frames], brows)


def _trim(tracked: TrackedFaps, lead: int) -> TrackedFaps:
    """``tracked`` without its first ``lead`` frames."""
    return TrackedFaps(tracked.stream[lead:], tracked.fapu, tracked.pose,
                       tuple(f - lead for f in tracked.filled_frames if f >= lead))


def closure_events(signal: np.ndarray, threshold: float) -> list[tuple[int, int]]:
    """Runs ``[start, stop)`` of frames where ``signal`` ``(n,)`` is above ``threshold``."""
    above = np.concatenate([[False], np.asarray(signal) > threshold, [False]])
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist(), strict=True))


def event_recall(events: list[tuple[int, int]], recovered: np.ndarray, *,
                 slack: int = 2) -> float:
    """Share of ``events`` during which ``recovered`` ``(n,)`` rises above half its own
    range above its median (within ``slack`` frames). NaN if there are no events."""
    if not events:
        return float("nan")
    rec = np.asarray(recovered, np.float64)
    base = float(np.median(rec))
    threshold = base + 0.5 * (float(rec.max()) - base)
    hits = sum(rec[max(a - slack, 0): b + slack].max() > threshold for a, b in events)
    return hits / len(events)


def lip_gap(face: Face, stream: FapStream) -> np.ndarray:
    """``(n,) float64`` vertical gap between the inner lip midpoints 2.2 and 2.3 of ``face``
    deformed by ``stream`` with the head kept still (FAPs 48-50 left out, so a head turn
    does not change it), in units of the face's MNS0 (0 = lips touching)."""
    top, bottom = face.feature_points["2.2"], face.feature_points["2.3"]
    values = np.array(stream.values)
    values[:, [f - 1 for f in HEAD_FAP_IDS]] = 0.0
    moved = face.deform(FapStream(stream.fps, values, stream.mask))
    return (moved[:, top, 1] - moved[:, bottom, 1]).astype(np.float64) / (
        face.fapu["MNS"] * FAPU_SCALE)


def lip_closures(gap: np.ndarray, fps: float, *, closed: float = LIPS_TOUCH,
                 longest: float = 0.4) -> list[tuple[int, int]]:
    """Runs ``[start, stop)`` where the lips close (``gap`` below ``closed`` MNS0) for at
    most ``longest`` seconds between open frames: the brief lip contacts of speech, those
    of p, b and m and the near-touches of other consonants (rests between phrases are
    longer and are left out). :func:`bilabial_closures` keeps those of p, b and m."""
    runs = closure_events(-np.asarray(gap), -closed)
    return [(a, b) for a, b in runs if a > 0 and b < len(gap) and (b - a) / fps <= longest]


def bilabial_closures(gap: np.ndarray, spans_ms: Sequence[tuple[float, float]], fps: float, *,
                      closed: float = LIPS_TOUCH) -> list[tuple[int, int]]:
    """Runs ``[start, stop)`` where the true lips are shut for a p, b or m: the runs of
    ``gap`` ``(n,)`` (MNS0, :func:`lip_gap` of the true stream) under ``closed`` that overlap
    one of ``spans_ms``, the ``(start, end)`` times in ms from the stream's first frame of
    the storyboard's bilabial visemes (``facelib.visemes.timeline.bilabial_spans``): a
    closure overlaps a span when one of its frames (frame ``i`` at ``1000 i / fps`` ms)
    falls in it. A closure that runs on into a pause counts once, whole; one cut by the
    clip's start or end counts too (whether the lips part is then checked on its other
    side only)."""
    runs = closure_events(-np.asarray(gap), -closed)
    frames = [(math.ceil(start * fps / 1000), math.ceil(end * fps / 1000))
              for start, end in spans_ms]
    return [(a, b) for a, b in runs if any(a < last and first < b for first, last in frames)]


def closure_recall(events: list[tuple[int, int]], gap: np.ndarray, *,
                   truth_gap: np.ndarray | None = None, closed: float = LIPS_TOUCH,
                   slack: int = 2) -> float:
    """Share of lip-closure ``events`` (runs ``[start, stop)``) during which the recovered
    ``gap`` ``(n,)`` (MNS0, :func:`lip_gap` of the recovered stream on the same face) also
    falls below ``closed`` within ``slack`` frames: the avatar's lips touch. With
    ``truth_gap`` ``(n,)`` (the true gap) a closure counts only if the avatar's lips also
    part (``gap >= closed`` in some frame) in the stretches on either side where the
    source's lips are apart, so one long closure does not count for several. NaN if there
    are no events."""
    if not events:
        return float("nan")
    shut = np.asarray(gap) < closed
    hits = [bool(shut[max(a - slack, 0): b + slack].any()) for a, b in events]
    if truth_gap is not None:
        apart = closure_events((np.asarray(truth_gap) >= closed).astype(np.float64), 0.5)
        hits = [hit and _parts(shut, apart, a, b) for hit, (a, b) in zip(hits, events,
                                                                          strict=True)]
    return sum(hits) / len(events)


def _parts(shut: np.ndarray, apart: Sequence[tuple[int, int]], start: int, stop: int) -> bool:
    """Whether ``shut`` ``(n,) bool`` is False somewhere in each run ``apart`` (the
    ``[a, b)`` frame runs where the true lips are apart) next to ``[start, stop)`` (runs at
    the ends of the clip included)."""
    near = [(a, b) for a, b in apart if b == start or a == stop]
    return all((~shut[a:b]).any() for a, b in near)


def false_closures(truth_gap: np.ndarray, gap: np.ndarray, *, closed: float = LIPS_TOUCH,
                   slack: int = 2) -> int:
    """Runs of frames where the recovered ``gap`` ``(n,)`` is below ``closed`` but the
    true ``truth_gap`` ``(n,)`` is not, in any frame of the run or within ``slack``: lips
    that touch on the avatar and not in the source."""
    shut = np.asarray(truth_gap) < closed
    runs = closure_events(-np.asarray(gap), -closed)
    return sum(not shut[max(a - slack, 0): b + slack].any() for a, b in runs)
