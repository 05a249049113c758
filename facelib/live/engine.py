"""The incremental engine of a live session: input placed on a frame clock, frames
committed once and never changed.

The engine keeps a :class:`~facelib.live.plan.Plan` per epoch and runs the offline
pipeline over a window from the epoch's first frame (:func:`facelib.live.plan.window`),
ahead of the frames it has handed out. New input goes no earlier than the first frame not
yet handed out (``lead_ms`` later for speech, whose envelope ramps in before it starts), and
every generator is causal, so the frames already handed out are those a recomputation with
the new input would give: the session's frames are the offline pipeline's.

An epoch ends when it has lasted ``epoch_s`` and nothing placed in it goes on past the
next frame (quiet, or between two utterances: streamed audio never stops, but its
stretches do): the next one starts at that frame with a seed of its own and takes over the
input placed from there on, and the face cross-fades from the old epoch's eyes and head to
the new one's over ``crossfade_ms``, so the window (time and memory per frame) stays
bounded however long the session runs. Time
here is the engine's own (frames at ``fps`` from 0); :class:`facelib.live.session.Session`
ties it to the wall clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from facelib.checks import check_fps, check_number, check_seed
from facelib.cues import CameraCue, ExpressionCue, GazeCue, SpeechSpec
from facelib.errors import ParameterError
from facelib.live.plan import Plan, Utterance, Window, window
from facelib.sync import SyncRules
from facelib.visemes.animate import SpeechAudio, animate_spoken
from facelib.visemes.tables import timing_rules
from facelib.visemes.timeline import SpeechTimeline

__all__ = ["Engine", "Frame"]

_AHEAD_S = 3.0
"""How far past the requested frame a window is computed (s): one recomputation serves
this many frames when no input comes."""


@dataclass(frozen=True, eq=False)
class Frame:
    """One output frame.

    index: frame number from the session's start; ``time_ms`` = ``index * 1000 / fps``.
    faps: ``(84,) float32`` FAP values (FAP k in column k-1; 0 where nothing drives it).
    mask: ``(84,) bool``, the FAPs set in this frame.
    viseme: the MPEG-4 viseme id (0-14) shown, or -1 when nothing is said.
    speaking: whether the character speaks at this frame.
    """

    index: int
    time_ms: float
    faps: np.ndarray
    mask: np.ndarray
    viseme: int
    speaking: bool


@dataclass
class _Epoch:
    start: int  # first frame (session frames)
    plan: Plan
    window: Window | None = None
    heard_until_ms: float = math.inf  # its utterances from here on play in the next epoch


class Engine:
    """Frames of a live session on its own clock (see the module's docstring).

    fps: output frame rate; seed: seed of the first epoch (each later one derives its own);
    epoch_s: least length of an epoch; crossfade_ms: the blend between epochs.
    """

    def __init__(self, *, fps: float = 30.0, seed: int = 0, epoch_s: float = 60.0,
                 crossfade_ms: int = 400, rules: SyncRules | None = None) -> None:
        self.fps = check_fps(fps)
        self.seed = check_seed(seed)
        self.epoch_frames = math.ceil(check_number("epoch_s", epoch_s, low=1.0) * self.fps)
        self.crossfade_frames = max(1, round(crossfade_ms * self.fps / 1000))
        self.rules = rules or SyncRules.load()
        self.lead_ms = int(timing_rules()["envelope_ramp_ms"])
        self.committed = 0  # frames handed out
        self._epoch = _Epoch(0, Plan(self.fps, self.seed))
        self._previous: _Epoch | None = None
        self._epochs = 1

    # -- time --------------------------------------------------------------------------
    def frame_ms(self, index: int) -> float:
        """Time of session frame ``index`` (ms)."""
        return index * 1000.0 / self.fps

    @property
    def now_ms(self) -> int:
        """The earliest time new input may start: the first frame not yet handed out (ms,
        rounded up)."""
        return math.ceil(self.frame_ms(self.committed))

    @property
    def speech_end_ms(self) -> int:
        """End of the last utterance placed (ms, session clock), or 0."""
        e = self._epoch
        ends = [u.end_ms for u in e.plan.utterances]
        return round(self.frame_ms(e.start)) + max(ends) if ends else 0

    @property
    def content_end_ms(self) -> float:
        """Time of the frame after the last one the cues and speech placed so far drive
        (session ms): where a session that is told to stop may end."""
        e = self._epoch
        return self.frame_ms(e.start + e.plan.content_frames)

    def _local(self, at_ms: int) -> int:
        return at_ms - round(self.frame_ms(self._epoch.start))

    def place(self, at_ms: int | None, *, lead_ms: int = 0) -> int:
        """Session ms where input asked for at ``at_ms`` (None: now) goes: no earlier than
        ``now_ms + lead_ms``."""
        earliest = self.now_ms + lead_ms
        return earliest if at_ms is None else max(int(at_ms), earliest)

    # -- input -------------------------------------------------------------------------
    def add_speech(self, timeline: SpeechTimeline, audio: SpeechAudio | None, *,
                   playback: SpeechAudio | None = None,
                   text: str | None = None, at_ms: int | None = None,
                   style: str | float = "normal", replace_last: bool = False,
                   lead_ms: int | None = None) -> int:
        """Place speech with a known ``timeline`` (its own ms) and ``audio`` no earlier than
        now plus the envelope's ramp and after the speech already placed (``replace_last``:
        instead of the last utterance, at its start: streamed audio that grew). ``audio``
        drives the jaw; ``playback`` (default ``audio``) is what :meth:`audio` plays.
        ``lead_ms`` (default: the ramp) shortens the lead for streamed audio, whose mouth
        then starts from where the frames out left it. Returns its start (session ms)."""
        plan = self._epoch.plan
        utterances = list(plan.utterances)
        if replace_last and utterances:
            start = round(self.frame_ms(self._epoch.start)) + utterances.pop().start_ms
        else:
            lead = self.lead_ms if lead_ms is None else lead_ms
            start = max(self.place(at_ms, lead_ms=lead), self.speech_end_ms)
        spec = SpeechSpec(text=text, start_ms=self._local(start), style=style)
        animation = animate_spoken(spec, timeline, audio, fps=self.fps)
        utterances.append(Utterance(self._local(start), timeline, animation, audio, text,
                                    playback or audio, style))
        self._set(replace(plan, utterances=tuple(utterances)))
        return start

    def add_cues(self, expressions: tuple[ExpressionCue, ...] = (),
                 gaze: tuple[GazeCue, ...] = (), camera: tuple[CameraCue, ...] = (), *,
                 at_ms: int | None = None) -> int:
        """Place cues whose times count from ``at_ms`` (None: now; never before now).
        Returns the session ms they count from."""
        start = self.place(at_ms)
        shift = self._local(start)
        plan = self._epoch.plan
        self._set(replace(
            plan,
            expressions=plan.expressions + tuple(
                replace(c, start_ms=c.start_ms + shift) for c in expressions),
            gaze=plan.gaze + tuple(replace(c, start_ms=c.start_ms + shift) for c in gaze),
            camera=plan.camera + tuple(replace(c, start_ms=c.start_ms + shift) for c in camera),
        ))
        return start

    def _set(self, plan: Plan) -> None:
        self._epoch.plan = plan
        self._epoch.window = None  # the frames handed out stay as they were (causality)

    # -- output ------------------------------------------------------------------------
    def advance(self, until_ms: float) -> list[Frame]:
        """Hand out every frame before ``until_ms`` (session ms) not yet handed out."""
        last = math.ceil(until_ms * self.fps / 1000 - 1e-9)
        out = []
        while self.committed < last:
            self._maybe_new_epoch()
            out.append(self._frame(self.committed))
            self.committed += 1
        return out

    def wanted(self, *, margin_s: float) -> tuple[Plan, int] | None:
        """``(plan, n_frames)`` of the window the current epoch needs before ``margin_s``
        more seconds of frames go out (None: the one it has lasts): a session computes it
        ahead, off its clock (:func:`facelib.live.plan.window`), and :meth:`offer` s it."""
        e = self._epoch
        local = self.committed - e.start
        if e.window is not None and e.window.n_frames - local > margin_s * self.fps:
            return None
        return e.plan, local + 1 + round(_AHEAD_S * self.fps)

    def offer(self, plan: Plan, computed: Window) -> None:
        """Use ``computed`` (``window(plan, ...)``) if ``plan`` is still the epoch's and it
        reaches further than the window held; else drop it. The frames are the same as
        those :meth:`advance` would compute itself (the window is a pure function)."""
        e = self._epoch
        if e.plan is plan and (e.window is None or computed.n_frames > e.window.n_frames):
            e.window = computed

    def covers(self, until_ms: float) -> bool:
        """Whether the window held has every frame before ``until_ms`` (no epoch starts)."""
        e = self._epoch
        last = math.ceil(until_ms * self.fps / 1000 - 1e-9) - 1 - e.start
        return e.window is not None and last < e.window.n_frames

    def _rows(self, epoch: _Epoch, index: int) -> tuple[np.ndarray, np.ndarray, int, bool]:
        local = index - epoch.start
        if epoch.window is None or local >= epoch.window.n_frames:
            ahead = local + 1 + round(_AHEAD_S * self.fps)
            epoch.window = window(epoch.plan, n_frames=ahead, rules=self.rules)
        w = epoch.window
        return (w.stream.values[local], w.stream.mask[local], int(w.visemes[local]),
                bool(w.speaking[local]))

    def _frame(self, index: int) -> Frame:
        values, mask, viseme, speaking = self._rows(self._epoch, index)
        previous = self._previous
        if previous is not None:
            a = (index - self._epoch.start + 1) / (self.crossfade_frames + 1)
            old, old_mask, _, _ = self._rows(previous, index)
            values = ((1 - a) * old + a * values).astype(np.float32)
            mask = mask | old_mask
            if index - self._epoch.start + 1 >= self.crossfade_frames:
                self._previous = None
        return Frame(index, self.frame_ms(index), np.array(values, np.float32),
                     np.array(mask, bool), viseme, speaking)

    def _maybe_new_epoch(self) -> None:
        """Start the next epoch at the next frame when this one is long and nothing in it
        goes on past that frame."""
        e = self._epoch
        local = self.committed - e.start
        if local < self.epoch_frames or self._previous is not None:
            return
        seed = (self.seed * 1_000_003 + self._epochs) % 2**63
        shift = round(self.frame_ms(self.committed)) - round(self.frame_ms(e.start))
        plan = (Plan(self.fps, seed) if local >= e.plan.content_frames
                else self._carried(e.plan, shift, seed))
        if plan is None:
            return
        e.heard_until_ms = shift
        self._previous = e
        self._epochs += 1
        self._epoch = _Epoch(self.committed, plan)

    def _carried(self, plan: Plan, shift: int, seed: int) -> Plan | None:
        """The next epoch's plan, starting ``shift`` ms into ``plan``'s epoch: the cues and
        utterances that start there or later, their times from there; None when something
        placed earlier goes on for more than a frame past it (what ends within the frame,
        and an utterance's release ramp, the old epoch plays through the cross-fade)."""
        ends = shift + 1000.0 / self.fps
        spans = [(c.start_ms, c.end_ms) for c in plan.expressions]
        spans += [(c.start_ms, c.end_ms) for c in plan.gaze]
        spans += [(c.start_ms, c.end_ms) for c in plan.camera]
        spans += [(u.start_ms, u.end_ms) for u in plan.utterances]
        if any(start < shift and end > ends for start, end in spans):
            return None

        def later(items: tuple) -> tuple:
            return tuple(replace(c, start_ms=c.start_ms - shift) for c in items
                         if c.start_ms >= shift)

        utterances = tuple(
            replace(u, start_ms=u.start_ms - shift, animation=animate_spoken(
                SpeechSpec(text=u.text, start_ms=u.start_ms - shift, style=u.style),
                u.timeline, u.audio, fps=self.fps))
            for u in plan.utterances if u.start_ms >= shift)
        return Plan(self.fps, seed, later(plan.expressions), later(plan.gaze),
                    later(plan.camera), utterances)

    def audio(self, first_ms: float, last_ms: float, *, sample_rate: int) -> np.ndarray:
        """``(n,) float32`` speech placed in ``[first_ms, last_ms)`` (session ms) at
        ``sample_rate`` (the utterances' ``playback``; others are not heard), silence
        elsewhere."""
        if last_ms < first_ms:
            raise ParameterError(f"audio: {last_ms} ms is before {first_ms} ms")
        first = round(first_ms * sample_rate / 1000)
        n = round(last_ms * sample_rate / 1000) - first
        out = np.zeros(n, np.float32)
        for epoch in (self._previous, self._epoch):
            if epoch is None:
                continue
            base = round(self.frame_ms(epoch.start) * sample_rate / 1000)
            for u in epoch.plan.utterances:
                sound = u.playback
                if (sound is None or sound.sample_rate != sample_rate
                        or u.start_ms >= epoch.heard_until_ms):
                    continue
                at = base + round(u.start_ms * sample_rate / 1000) - first
                lo, hi = max(at, 0), min(at + sound.samples.size, n)
                if hi > lo:
                    out[lo:hi] += sound.samples[lo - at:hi - at]
        return out
