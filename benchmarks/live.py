"""Live session latency and load (issue 35), on this machine's cores.

- text in -> first frame whose mouth the sentence drives (p50/p95 over N sentences), and
  -> first frame with the sentence's voiced audio;
- audio in (100 ms chunks, real time) -> the frame that carries that audio (p50/p95);
- K concurrent wall-clock sessions at 30 frames/s, all starting at once and each saying
  two sentences: frames out per second, the lag of frames behind their due time (p50/p95,
  the worst, and the worst once the start is over);
- memory of one session over a long input on the manual clock (as fast as it computes):
  an hour of text (a sentence every 4 s) and ten minutes of streamed audio, the memory
  the session holds (``tracemalloc``) and the process's peak resident size every few
  minutes of session time (bounded: flat after the first epoch).

Run: ``PYTHONPATH=. python benchmarks/live.py [--sentences 20] [--sessions 10]``.
"""

from __future__ import annotations

import argparse
import asyncio
import resource
import time
import tracemalloc

import numpy as np

from facelib.live.session import Session

_SPEECH_FAPS = np.array([3, 4, 5, 8, 9, 10, 11]) - 1
"""Jaw and mid-lip FAPs: the visemes drive them, idle motion does not (the lip corners,
FAPs 6, 7, 12, 13, move with the idle face and are left out)."""
SENTENCES = ["Hello there.", "How are you today?", "The weather is fine.",
             "Let us begin the lesson.", "Thank you very much."]


async def text_latency(n: int) -> tuple[list[float], list[float], float]:
    """Seconds from ``say`` to the first frame whose mouth moves, and to voiced audio, for
    ``n`` sentences after a first one (the process's first: imports and tables load),
    whose time to its mouth is returned apart. Frames made before the ``say`` are skipped."""
    mouth, voiced = [], []
    async with Session(fps=30) as s:
        frames = s.frames().__aiter__()
        for k in range(n + 1):
            await asyncio.sleep(0.6)  # let the previous sentence go by
            while s.engine.now_ms < s.engine.speech_end_ms + 300:
                await frames.__anext__()
            t0 = time.perf_counter()
            first = s.engine.committed
            await s.say(SENTENCES[k % len(SENTENCES)])
            got_mouth = None
            while True:
                out = await frames.__anext__()
                if out.frame.index < first:
                    continue
                if got_mouth is None and np.abs(out.frame.faps[_SPEECH_FAPS]).max() > 1:
                    got_mouth = time.perf_counter() - t0
                if np.abs(out.audio).max() > 0.02:
                    voiced.append(time.perf_counter() - t0)
                    break
            mouth.append(got_mouth if got_mouth is not None else voiced[-1])
    return mouth[1:], voiced[1:], mouth[0]


async def audio_latency(seconds: float) -> list[float]:
    """Seconds from sending a 100 ms audio chunk to the frame that carries its first sample
    (the frame whose span, ``i / fps`` to ``(i + 1) / fps``, holds it)."""
    from facelib.speech import synthesize
    from facelib.speech.audio import load_speech

    made = synthesize(" ".join(SENTENCES))
    pcm = load_speech(made.samples, sample_rate=made.sample_rate)
    sent: list[tuple[float, int]] = []  # (perf time, session ms of the first sample)
    got: list[tuple[float, float]] = []  # (perf time, frame ms) of each frame out
    try:
        session = Session(fps=30, lookahead_ms=80, audio_in=True)
    except TypeError:  # a facelib before audio_in (to compare with)
        session = Session(fps=30, lookahead_ms=80)
    async with session as s:
        await asyncio.sleep(1.5)  # the recognizer loads as the session starts

        async def read() -> None:
            async for o in s.frames():  # kept as they come (the reader is cancelled)
                got.append((time.perf_counter(), o.frame.time_ms))  # noqa: PERF401

        reader = asyncio.create_task(read())
        loop = asyncio.get_running_loop()
        t_start = loop.time()
        for k, first in enumerate(range(0, min(pcm.size, int(seconds * 16000)), 1600)):
            await asyncio.sleep(max(t_start + k * 0.1 - loop.time(), 0))
            t = time.perf_counter()
            await s.audio(pcm[first:first + 1600])
            sent.append((t, s._audio_next_ms - 100))  # where this chunk's first sample went
        await asyncio.sleep(0.5)
        reader.cancel()
    span = 1000 / 30
    return [next(t for t, ms in got if ms + span > at) - t0 for t0, at in sent
            if got[-1][1] + span > at]


async def concurrent(k: int, seconds: float) -> tuple[float, np.ndarray, np.ndarray]:
    """Frames per second per session, and the lag (s) of each frame behind its due time
    (when the reader has it) with the frame's time (s)."""
    lags: list[tuple[float, float]] = []
    counts = [0] * k

    async def one(i: int) -> None:
        async with Session(fps=30, seed=i) as s:
            loop = asyncio.get_running_loop()
            await s.say(SENTENCES[i % len(SENTENCES)] + " " + SENTENCES[(i + 1) % 5])
            async for o in s.frames():
                due = o.frame.time_ms / 1000
                lags.append((due, loop.time() - s._t0 - due))
                counts[i] += 1
                if o.frame.time_ms >= seconds * 1000:
                    break

    await asyncio.gather(*(one(i) for i in range(k)))
    at, lag = np.array(lags).T
    return float(np.mean(counts)) / seconds, lag, at


async def memory(minutes: int, *, audio: bool) -> list[tuple[int, float, float, float]]:
    """``(minute, MB held, peak resident MB, compute s since the last row)`` of one
    manual-clock session fed ``minutes`` of input: a sentence every 4 s, or (``audio``)
    synthesized speech in 100 ms chunks."""
    every_s, report = 4.0, max(1, minutes // 6)
    rows = []
    async with Session(fps=30, clock="manual", seed=1, audio_in=audio) as s:
        pcm = None
        if audio:
            from facelib.speech import synthesize
            from facelib.speech.audio import load_speech

            made = synthesize(" ".join(SENTENCES))
            pcm = load_speech(made.samples, sample_rate=made.sample_rate)
        await s.advance(1000)
        tracemalloc.start()
        base = tracemalloc.get_traced_memory()[0]
        k, tick = 0, time.perf_counter()
        for minute in range(1, minutes + 1):
            while (k + 1) * (0.1 if audio else every_s) <= minute * 60:
                if pcm is None:
                    await s.say(SENTENCES[k % len(SENTENCES)])
                    k += 1
                    await s.advance(k * every_s * 1000)
                else:
                    first = (k * 1600) % (pcm.size - 1600)
                    await s.audio(pcm[first:first + 1600])
                    k += 1
                    await s.advance(k * 100)
            await s.advance(minute * 60_000)
            if minute % report == 0:
                held = (tracemalloc.get_traced_memory()[0] - base) / 1e6
                rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
                rows.append((minute, held, rss, time.perf_counter() - tick))
                tick = time.perf_counter()
        tracemalloc.stop()
    return rows


def _pct(values: list[float]) -> str:
    ms = np.array(values) * 1000
    return f"p50 {np.percentile(ms, 50):.0f} ms, p95 {np.percentile(ms, 95):.0f} ms (n={ms.size})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sentences", type=int, default=20)
    parser.add_argument("--audio-s", type=float, default=8.0)
    parser.add_argument("--sessions", type=int, default=10)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--memory-minutes", type=int, default=60,
                        help="minutes of text for the memory part (audio: a sixth)")
    parser.add_argument("--only", choices=("text", "audio", "load", "memory"), action="append",
                        help="run only these parts (repeatable; default all)")
    args = parser.parse_args()
    parts = set(args.only or ("text", "audio", "load", "memory"))
    if "text" in parts:
        mouth, voiced, cold = asyncio.run(text_latency(args.sentences))
        print(f"text in -> first mouth frame, the process's first sentence: {cold * 1000:.0f} ms")
        print(f"text in -> first mouth frame:   {_pct(mouth)}")
        print(f"text in -> first voiced frame:  {_pct(voiced)}")
    if "audio" in parts:
        heard = asyncio.run(audio_latency(args.audio_s))
        print(f"audio in -> its frame (80 ms look-ahead): {_pct(heard)}")
    if "load" in parts:
        fps, lag, at = asyncio.run(concurrent(args.sessions, args.seconds))
        print(f"{args.sessions} sessions at 30 fps: {fps:.1f} frames/s each; frame lag "
              f"{_pct(list(lag))}, worst {lag.max() * 1000:.0f} ms; after the first 2 s "
              f"worst {lag[at >= 2].max() * 1000:.0f} ms")
    if "memory" in parts:
        for audio, minutes in ((False, args.memory_minutes),
                               (True, max(1, args.memory_minutes // 6))):
            rows = asyncio.run(memory(minutes, audio=audio))
            print(f"one session, {minutes} min of {'audio' if audio else 'text'}: " + "; ".join(
                f"{m} min {held:.0f} MB held, peak RSS {rss:.0f} MB ({s:.0f} s)"
                for m, held, rss, s in rows))


if __name__ == "__main__":
    main()
