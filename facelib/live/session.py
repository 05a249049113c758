"""``Session``: a live face on the wall clock (or a manual one), fed text, audio and cues,
giving frames with their audio.

Frame ``i`` (time ``i / fps``) goes out when the session clock reaches it. Text is spoken
sentence by sentence as sentences complete (synthesis runs in a worker thread, by an
espeak-ng process started ahead of the sentence); each
sentence starts at the first frame not yet out plus the speech envelope's ramp, after the
speech before it. Streamed audio (16 kHz PCM) starts ``lookahead_ms`` after the first frame
not yet out, so the recognizer has that much audio past each frame it animates; the audio
goes out again with its frames (``Output.audio``). Cues start at the first frame not yet
out. With ``clock="manual"`` frames go out only when :meth:`Session.advance` is called
(tests, rendering through the server): the same input then gives the same frames.
"""

from __future__ import annotations

import asyncio
import functools
import math
import threading
from collections.abc import AsyncIterator, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from math import gcd
from typing import Any, Literal

import numpy as np

from facelib.checks import check_number
from facelib.cues import SpeechSpec
from facelib.errors import MissingExtraError, ParameterError
from facelib.live.engine import Engine, Frame
from facelib.live.inputs import Cues, cues_from_fdl, cues_from_json, split_sentences
from facelib.live.listen import Listener, ListenMethod, pcm16_samples
from facelib.live.plan import Plan, Window, window
from facelib.live.udp import UdpTarget, parse_target
from facelib.speech.espeak import Worker
from facelib.visemes.animate import SpeechAudio, spoken
from facelib.visemes.timeline import SpeechTimeline

__all__ = ["OUTPUT_RATE", "Output", "Session", "SyncSession"]

OUTPUT_RATE = 16000
"""Sample rate of the audio that goes out with the frames (Hz, mono)."""
_PREFETCH_S = 1.5
"""A window is computed ahead when the one held has less than this many seconds left."""
_MAX_TEXT_CHARS = 4000
_MAX_BUFFER_CHARS = 8000


@dataclass(frozen=True, eq=False)
class Output:
    """A frame with what goes out with it: ``audio`` ``(k,) float32`` at
    :data:`OUTPUT_RATE` from the frame's time to the next frame's, ``arkit`` ``(52,)
    float32`` weights and ``angles`` ``(9,) float32`` radians (head and eyes,
    :data:`facelib.export.arkit.ANGLE_NAMES`) when asked for (None otherwise), and
    ``dropped``, the frames dropped before this one because the reader was slow."""

    frame: Frame
    audio: np.ndarray
    arkit: np.ndarray | None = None
    dropped: int = 0
    angles: np.ndarray | None = None


@dataclass
class _Queue:
    items: asyncio.Queue[Any]
    dropped: int = 0
    waiting: list[Any] = field(default_factory=list)


class Session:
    """A live session (see the module's docstring); use as ``async with Session(...) as s``.

    fps: frame rate; lookahead_ms: the audio look-ahead (0-500, default 80); seed: the
    random processes' seed; lang / voice / rate: synthesis of text; arkit: add ARKit-52
    weights to each output (default head only); clock: ``"wall"`` or ``"manual"``;
    queue_s: seconds of output kept for a slow reader (older frames are dropped);
    audio_in: the session will be sent audio: the recognizer loads as it starts (about
    0.6 s in a thread, 90 MB) instead of holding up the first chunk; livelink / vmc:
    ``"HOST:PORT"`` to send each frame to as a Live Link Face packet
    (:mod:`facelib.live.livelink`, port 11111 if left out) or a VMC bundle
    (:mod:`facelib.live.vmc`, port 39539); subject: the Live Link subject name; listen:
    how audio sent in is recognised: ``"acoustic"`` (the acoustic viseme model, any
    language; the default for every ``lang`` but English) or ``"phones"`` (pocketsphinx's
    phone loop, English; the default for English, where it measured better).
    """

    def __init__(self, *, face: object | None = None, fps: float = 30.0,
                 lookahead_ms: float = 80.0, seed: int = 0, lang: str = "en",
                 voice: str | None = None, rate: float = 1.0, arkit: bool = False,
                 clock: Literal["wall", "manual"] = "wall", epoch_s: float = 60.0,
                 queue_s: float = 5.0, audio_in: bool = False, livelink: str | None = None,
                 vmc: str | None = None, subject: str = "facelib",
                 listen: ListenMethod | None = None) -> None:
        if clock not in ("wall", "manual"):
            raise ParameterError(f"clock must be 'wall' or 'manual', got {clock!r}")
        if face is not None:
            raise ParameterError("live sessions play on the default head (face=None) for now")
        self.engine = Engine(fps=fps, seed=seed, epoch_s=epoch_s)
        self.lookahead_ms = round(check_number("lookahead_ms", lookahead_ms, low=0, high=500))
        self.lang, self.voice = lang, voice
        self.rate = check_number("rate", rate, low=0.5, high=2.5)
        self.arkit, self.clock = bool(arkit), clock
        self.udp = _targets(livelink, vmc)
        self.subject = subject
        self._text = ""
        english = lang.lower().startswith("en")
        self._listener = Listener(method=listen or ("phones" if english else "acoustic"))
        self._audio_next_ms: int | None = None  # session ms where the next audio sample goes
        self._queue = _Queue(asyncio.Queue(maxsize=max(1, round(queue_s * fps))))
        self._sentences: asyncio.Queue[tuple[str, int | None]] = asyncio.Queue()
        self._tasks: list[asyncio.Task[None]] = []
        self._closed = False
        self._t0 = 0.0
        self._audio_in = bool(audio_in)
        self._prepared: asyncio.Task[None] | None = None
        self._ahead: tuple[Plan, asyncio.Future[Window]] | None = None  # window computing
        # a thread of its own for windows: not queued behind synthesis in the loop's pool
        self._windows = ThreadPoolExecutor(max_workers=1, thread_name_prefix="facelib-live")

    # -- lifetime ----------------------------------------------------------------------
    async def __aenter__(self) -> Session:
        loop = asyncio.get_running_loop()
        self._t0 = loop.time()
        self._tasks.append(asyncio.create_task(self._speak()))
        if self._audio_in:
            self._prepared = asyncio.create_task(asyncio.to_thread(self._listener.prepare))
            self._tasks.append(self._prepared)
        if self.clock == "wall":
            self._tasks.append(asyncio.create_task(self._tick()))
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.close()

    async def close(self) -> None:
        """End now: the frame iterators end, the workers stop."""
        if self._closed:
            return
        self._closed = True
        if self._ahead is not None:
            self._ahead[1].cancel()
        for task in self._tasks:
            task.cancel()
        await asyncio.gather(*self._tasks, return_exceptions=True)
        self._windows.shutdown(wait=False, cancel_futures=True)
        for target in self.udp.values():
            target.close()
        self._put(None)

    async def stop(self) -> None:
        """Say what is left of the text, play the speech out, then end."""
        await self.say("", flush=True)
        await self._sentences.join()
        end = self.engine.content_end_ms
        if self.clock == "manual":
            await self.advance(end)
        else:
            while self.engine.now_ms < end and not self._closed:
                await asyncio.sleep(0.02)
        await self.close()

    # -- input -------------------------------------------------------------------------
    async def say(self, text: str, *, flush: bool = True, at_ms: int | None = None) -> None:
        """Speak ``text`` (a chunk of a longer text: complete sentences are spoken now, the
        rest waits for more unless ``flush``); the first sentence no earlier than session
        ``at_ms``."""
        if not isinstance(text, str) or len(text) > _MAX_TEXT_CHARS:
            raise ParameterError(f"text must be a string of at most {_MAX_TEXT_CHARS} "
                                 "characters")
        if len(self._text) + len(text) > _MAX_BUFFER_CHARS:
            raise ParameterError(f"more than {_MAX_BUFFER_CHARS} characters of text wait for "
                                 "a sentence end; send flush")
        sentences, self._text = split_sentences(self._text + text, flush=flush)
        for k, sentence in enumerate(sentences):
            await self._sentences.put((sentence, at_ms if k == 0 else None))

    async def _speak(self) -> None:
        """The synthesis worker: sentences in order, each placed when it is ready. An
        espeak-ng process waits for the next sentence, started while the session is quiet."""
        while True:
            spare = await asyncio.to_thread(_spare_worker)
            try:
                sentence, at_ms = await self._sentences.get()
            except asyncio.CancelledError:
                if spare is not None:
                    await asyncio.to_thread(spare.close)
                raise
            try:
                own, audio, playback = await asyncio.to_thread(
                    _spoken_by, spare, SpeechSpec(text=sentence, lang=self.lang,
                                                  voice=self.voice, rate=self.rate))
                start = self.engine.add_speech(own, audio, playback=playback,
                                               text=sentence, at_ms=at_ms)
                self._event({"type": "speech", "start_ms": start, "text": sentence,
                             "phones": [[p.label, p.start_ms, p.end_ms] for p in own.phones],
                             "words": [[w.label, w.start_ms, w.end_ms] for w in own.words]})
            except Exception as exc:  # noqa: BLE001 - reported on the stream, the session goes on
                self._event({"type": "error", "message": f"speech: {exc}"})
            finally:
                self._sentences.task_done()

    async def audio(self, pcm: bytes | np.ndarray) -> None:
        """Add speech audio: 16-bit little-endian PCM bytes or ``(n,) float`` samples, mono
        16 kHz. Its visemes come from the session's ``listen`` method (the acoustic viseme
        model, any language, or the phone loop), its loudness opens the jaw."""
        samples = pcm16_samples(pcm) if isinstance(pcm, bytes) else np.asarray(
            pcm, np.float32).reshape(-1)
        if samples.size == 0:
            return
        if not np.isfinite(samples).all():
            raise ParameterError("audio samples must be finite")
        if self._prepared is not None:
            await self._prepared
        engine = self.engine
        gap = self._audio_next_ms is None or self._audio_next_ms < engine.now_ms
        if gap or self._listener.should_end():
            self._listener.end()
        if self._listener.n_samples == 0:
            # the look-ahead counts from the chunk's arrival (the session clock), not from the
            # next frame or from when the chunk is decoded
            now = max(math.ceil(self.now_ms()), engine.now_ms)
            at = now + self.lookahead_ms if gap else self._audio_next_ms
            timeline, sound = await asyncio.to_thread(self._listener.feed, samples)
            start = engine.add_speech(timeline, sound, at_ms=at, lead_ms=0)
        else:
            timeline, sound = await asyncio.to_thread(self._listener.feed, samples)
            start = engine.add_speech(timeline, sound, replace_last=True)
        self._audio_next_ms = start + self._listener.duration_ms

    async def cue(self, cue: str | dict[str, Any], *, at_ms: int | None = None) -> int:
        """Place a cue now (or at session ``at_ms``, never before now): an FDL snippet
        (``'show { "joy", dur = 2 }'``) or a JSON-like dict (``{"show": "joy",
        "dur_ms": 2000}``). Returns the session ms its times count from."""
        cues: Cues = cues_from_fdl(cue) if isinstance(cue, str) else cues_from_json(cue)
        start = self.engine.add_cues(cues.expressions, cues.gaze, cues.camera, at_ms=at_ms)
        for move in cues.camera:
            self._event({"type": "camera", "framing": move.framing,
                         "start_ms": start + move.start_ms, "dur_ms": move.duration_ms})
        return start

    # -- output ------------------------------------------------------------------------
    def now_ms(self) -> float:
        """The session clock (ms)."""
        if self.clock == "manual":
            return float(self.engine.now_ms)
        return (asyncio.get_running_loop().time() - self._t0) * 1000.0

    async def advance(self, until_ms: float) -> None:
        """(Manual clock) give out every frame before ``until_ms``, once the text given so
        far has been synthesized and placed."""
        await self._sentences.join()
        self._emit(self.engine.advance(until_ms))

    async def _tick(self) -> None:
        """Each frame out when the clock reaches its time (not a frame later)."""
        loop = asyncio.get_running_loop()
        while True:
            frame_ms = self.engine.frame_ms(self.engine.committed)
            await asyncio.sleep(max(self._t0 + frame_ms / 1000.0 - loop.time(), 0.0))
            until = max(self.now_ms(), frame_ms) + 1e-3
            await self._window_for(until)
            self._emit(self.engine.advance(until))

    async def _window_for(self, until_ms: float) -> None:
        """Compute the engine's next window in a worker thread, ahead of need (the event
        loop, and every other session on it, goes on meanwhile); wait for it only when
        the frames before ``until_ms`` need it."""
        engine = self.engine
        wanted = engine.wanted(margin_s=_PREFETCH_S)
        ahead = self._ahead
        if wanted is not None and (ahead is None or ahead[0] is not wanted[0]):
            plan, n = wanted
            task = asyncio.ensure_future(asyncio.get_running_loop().run_in_executor(
                self._windows, functools.partial(window, plan, n_frames=n, rules=engine.rules)))
            ahead = self._ahead = (plan, task)
        if ahead is None:
            return
        if not ahead[1].done() and not engine.covers(until_ms):
            await asyncio.wait([ahead[1]])
        if ahead[1].done():
            self._ahead = None
            task = ahead[1]
            if not task.cancelled() and task.exception() is None:  # else the engine
                # computes it itself (and raises)
                engine.offer(ahead[0], task.result())

    def _emit(self, frames: list[Frame]) -> None:
        weights = angles = None
        if (self.arkit or self.udp) and frames:
            weights, angles = _arkit(frames, self.engine.fps)
            self._send_udp(frames, weights, angles)
        if not self.arkit:
            weights = angles = None
        for k, frame in enumerate(frames):
            audio = self.engine.audio(frame.time_ms, self.engine.frame_ms(frame.index + 1),
                                      sample_rate=OUTPUT_RATE)
            self._put(Output(frame, audio, None if weights is None else weights[k],
                             self._queue.dropped, None if angles is None else angles[k]))

    def _send_udp(self, frames: list[Frame], weights: np.ndarray, angles: np.ndarray) -> None:
        """Each frame to the Live Link and VMC targets, as it goes out."""
        from facelib.live import livelink, vmc

        for k, frame in enumerate(frames):
            if "livelink" in self.udp:
                self.udp["livelink"].send(livelink.packet(
                    weights[k], angles[k], frame=frame.index, fps=self.engine.fps,
                    subject=self.subject))
            if "vmc" in self.udp:
                self.udp["vmc"].send(vmc.bundle(weights[k], angles[k], viseme=frame.viseme,
                                                time_s=frame.time_ms / 1000))

    def _event(self, message: dict[str, Any]) -> None:
        self._put(message)

    def _put(self, item: Any) -> None:
        q = self._queue
        while q.items.full():
            dropped = q.items.get_nowait()
            q.dropped += isinstance(dropped, Output)
        q.items.put_nowait(item)

    async def messages(self) -> AsyncIterator[Output | dict[str, Any]]:
        """Frames (:class:`Output`) and events (``speech``, ``camera``, ``error`` dicts) in
        the order they were made, until the session ends."""
        while True:
            item = await self._queue.items.get()
            if item is None:
                return
            yield item

    async def frames(self) -> AsyncIterator[Output]:
        """The frames only (see :meth:`messages`)."""
        async for item in self.messages():
            if isinstance(item, Output):
                yield item


def _spare_worker() -> Worker | None:
    """An espeak-ng process started ahead, or None without the ``speech`` extra. The
    resampler is imported here too (scipy.signal takes most of a second the first time)."""
    import scipy.signal  # noqa: F401

    try:
        return Worker()
    except MissingExtraError:
        return None


def _spoken_by(worker: Worker | None, spec: SpeechSpec,
               ) -> tuple[SpeechTimeline, SpeechAudio | None, SpeechAudio | None]:
    """:func:`facelib.visemes.animate.spoken` of ``spec`` by ``worker`` (closed after),
    and its audio at :data:`OUTPUT_RATE`."""
    try:
        own, audio = spoken(spec, worker=worker)
    finally:
        if worker is not None:
            worker.close()
    return own, audio, _resampled(audio)


def _resampled(audio: SpeechAudio | None) -> SpeechAudio | None:
    """``audio`` at :data:`OUTPUT_RATE` (the synthesizer speaks at 22050 Hz)."""
    if audio is None or audio.sample_rate == OUTPUT_RATE:
        return audio
    from scipy.signal import resample_poly

    g = gcd(OUTPUT_RATE, audio.sample_rate)
    samples = resample_poly(audio.samples, OUTPUT_RATE // g, audio.sample_rate // g)
    return SpeechAudio(np.clip(samples, -1, 1).astype(np.float32), OUTPUT_RATE)


def _targets(livelink: str | None, vmc: str | None) -> dict[str, UdpTarget]:
    """The UDP senders a session was asked for, by kind."""
    from facelib.live import livelink as ll
    from facelib.live import vmc as vm

    out = {}
    if livelink is not None:
        out["livelink"] = UdpTarget(*parse_target(livelink, default_port=ll.DEFAULT_PORT))
    if vmc is not None:
        vm._osc()  # MissingExtraError now, not at the first frame
        out["vmc"] = UdpTarget(*parse_target(vmc, default_port=vm.DEFAULT_PORT))
    return out


def _arkit(frames: list[Frame], fps: float) -> tuple[np.ndarray, np.ndarray]:
    """``(len(frames), 52) float32`` ARKit weights of the frames on the default head and
    ``(len(frames), 9) float32`` head and eye angles (radians)."""
    from facelib.export.arkit import to_arkit
    from facelib.mpeg4.stream import FapStream

    stream = FapStream(fps, np.stack([f.faps for f in frames]), np.stack([f.mask for f in frames]))
    curves = to_arkit(stream)
    return curves.weights, curves.angles


class SyncSession:
    """:class:`Session` for scripts without asyncio: the session runs on an event loop in
    a thread of its own; ``say``, ``audio``, ``cue`` and ``advance`` wait for it, and
    :meth:`frames` iterates the outputs. Use as ``with SyncSession(...) as s``."""

    def __init__(self, **options: Any) -> None:
        self._options = options
        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, daemon=True)
        self._session: Session | None = None

    def _call(self, coroutine: Any) -> Any:
        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result()

    def __enter__(self) -> SyncSession:
        self._thread.start()

        async def start() -> Session:
            return await Session(**self._options).__aenter__()

        self._session = self._call(start())
        return self

    def __exit__(self, *exc: object) -> None:
        self._call(self.session.close())
        self._loop.call_soon_threadsafe(self._loop.stop)
        self._thread.join(timeout=5)
        self._loop.close()

    @property
    def session(self) -> Session:
        if self._session is None:
            raise ParameterError("use SyncSession in a with block")
        return self._session

    def say(self, text: str, *, flush: bool = True, at_ms: int | None = None) -> None:
        self._call(self.session.say(text, flush=flush, at_ms=at_ms))

    def audio(self, pcm: bytes | np.ndarray) -> None:
        self._call(self.session.audio(pcm))

    def cue(self, cue: str | dict[str, Any], *, at_ms: int | None = None) -> int:
        return int(self._call(self.session.cue(cue, at_ms=at_ms)))

    def advance(self, until_ms: float) -> None:
        self._call(self.session.advance(until_ms))

    def stop(self) -> None:
        self._call(self.session.stop())

    def frames(self) -> Iterator[Output]:
        """The outputs until the session ends (after :meth:`stop`)."""
        iterator = self.session.frames().__aiter__()
        while True:
            try:
                yield self._call(iterator.__anext__())
            except StopAsyncIteration:
                return
