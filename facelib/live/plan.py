"""What a live session has been told so far, as plain data, and the offline functions run
over it: one window of frames from frame 0 of an epoch.

An epoch is a stretch of the session computed as one storyboard: its cues and utterances in
ms from the epoch's first frame. :func:`window` runs exactly what
:func:`facelib.animation.animate` runs (the viseme generator per utterance, then
:func:`facelib.animation.compose`), so a session whose input is one storyboard's gives that
storyboard's frames bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facelib.animation import compose, speech_track
from facelib.cues import CameraCue, ExpressionCue, GazeCue, Storyboard
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.track import FapTrack
from facelib.sync import SyncRules
from facelib.visemes.animate import SpeechAudio, VisemeAnimation
from facelib.visemes.timeline import SpeechTimeline, VisemeSpan

__all__ = ["Plan", "Utterance", "Window", "window"]


@dataclass(frozen=True, eq=False)
class Utterance:
    """One sentence (or one stretch of streamed audio) placed on the epoch's clock.

    start_ms: where it starts, ms from the epoch's first frame.
    timeline: phones, words and visemes in its own ms (0 = ``start_ms``).
    animation: the viseme generator's output for it (track from the epoch's frame 0).
    audio: its samples from ``start_ms`` (synthesized or received; they drive the jaw), or
        None.
    text: what is said, or None for received audio.
    playback: the samples the session plays (``audio`` at the output rate), or None.
    style: the speaking style it was animated with.
    """

    start_ms: int
    timeline: SpeechTimeline
    animation: VisemeAnimation
    audio: SpeechAudio | None
    text: str | None = None
    playback: SpeechAudio | None = None
    style: str | float = "normal"

    @property
    def end_ms(self) -> int:
        """End of the speech (ms from the epoch's first frame)."""
        return self.start_ms + self.timeline.duration_ms

    @property
    def n_frames(self) -> int:
        """Frames of its track (through the envelope's release ramp)."""
        return self.animation.track.n_frames


@dataclass(frozen=True)
class Plan:
    """An epoch's input: frame rate, seed, the cues (ms from the epoch's first frame) and
    the utterances, in the order they came."""

    fps: float
    seed: int
    expressions: tuple[ExpressionCue, ...] = ()
    gaze: tuple[GazeCue, ...] = ()
    camera: tuple[CameraCue, ...] = ()
    utterances: tuple[Utterance, ...] = field(default=())

    def storyboard(self) -> Storyboard:
        """The plan's cues as a storyboard without speech."""
        return Storyboard(fps=self.fps, seed=self.seed,
                          expressions=tuple(sorted(self.expressions, key=lambda c: c.start_ms)),
                          gaze=tuple(sorted(self.gaze, key=lambda c: c.start_ms)),
                          camera=self.camera)

    @property
    def content_frames(self) -> int:
        """Frames until the last cue and utterance track have ended (as ``animate`` counts
        them: one frame past the last cue's end)."""
        ends = self.storyboard().cues_end_ms
        n = int(np.floor(ends * self.fps / 1000 + 1e-9)) + 1
        return max([n, *(u.n_frames for u in self.utterances)])


@dataclass(frozen=True, eq=False)
class Window:
    """Frames ``0 .. n_frames - 1`` of an epoch: the synchronized ``stream``, the viseme
    id shown at each frame (``visemes``, ``(n,) int16``, -1 where none) and whether the
    character speaks there (``speaking``, ``(n,) bool``)."""

    stream: FapStream
    visemes: np.ndarray
    speaking: np.ndarray

    @property
    def n_frames(self) -> int:
        return self.stream.n_frames


def _merged(utterances: tuple[Utterance, ...], rules: SyncRules, n_frames: int,
            ) -> tuple[FapTrack | None, np.ndarray | None]:
    """The viseme tracks of the utterances (importance on their weights) summed over
    ``n_frames``, and their speaking masks or-ed; one utterance's as it is."""
    if not utterances:
        return None, None
    if len(utterances) == 1:
        u = utterances[0]
        return speech_track(u.animation, rules), u.animation.speaking
    fps = utterances[0].animation.track.fps
    values = np.zeros((n_frames, 84), np.float32)
    weight = np.zeros((n_frames, 84), np.float32)
    speaking = np.zeros(n_frames, bool)
    for u in utterances:
        track = speech_track(u.animation, rules).padded(n_frames)
        values += track.values
        weight += track.weight
        k = min(u.animation.speaking.size, n_frames)
        speaking[:k] |= u.animation.speaking[:k]
    return FapTrack(fps, values, np.minimum(weight, 1.0)), speaking


def _viseme_ids(spans: list[VisemeSpan], n_frames: int, fps: float) -> np.ndarray:
    """``(n_frames,) int16``: the id of the viseme span under each frame, -1 elsewhere."""
    out = np.full(n_frames, -1, np.int16)
    times = np.arange(n_frames) * 1000.0 / fps
    for span in spans:
        inside = (times >= span.start_ms) & (times < span.end_ms)
        out[inside] = span.viseme
    return out


def window(plan: Plan, *, n_frames: int, rules: SyncRules) -> Window:
    """Frames ``0 .. max(n_frames, plan.content_frames) - 1`` of ``plan``'s epoch, by the
    offline generators and synchronizer (:func:`facelib.animation.compose`)."""
    n = max(n_frames, plan.content_frames)
    track, speaking = _merged(plan.utterances, rules, n)
    stream, _, _ = compose(plan.storyboard(), visemes=track, speaking=speaking, n_frames=n,
                           rules=rules)
    spans = [s for u in plan.utterances for s in u.animation.timeline]
    talking = np.zeros(n, bool)
    if speaking is not None:
        talking[: speaking.size] = speaking[:n]
    return Window(stream, _viseme_ids(spans, n, plan.fps), talking)
