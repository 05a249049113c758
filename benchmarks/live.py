"""Live session latency and load (issue 35), on this machine's cores.

- text in -> first frame whose mouth the sentence drives (p50/p95 over N sentences), and
  -> first frame with the sentence's voiced audio;
- audio in (100 ms chunks, real time) -> the frame at that audio's time (p50/p95);
- K concurrent wall-clock sessions at 30 frames/s: frames out per second and the largest
  lag of a frame behind its due time.

Run: ``PYTHONPATH=. python benchmarks/live.py [--sentences 20] [--sessions 10]``.
"""

from __future__ import annotations

import argparse
import asyncio
import time

import numpy as np

from facelib.live.session import Session

SENTENCES = ["Hello there.", "How are you today?", "The weather is fine.",
             "Let us begin the lesson.", "Thank you very much."]


async def text_latency(n: int) -> tuple[list[float], list[float]]:
    """Seconds from ``say`` to the first frame whose mouth moves, and to voiced audio."""
    mouth, voiced = [], []
    async with Session(fps=30) as s:
        frames = s.frames().__aiter__()
        for k in range(n):
            await asyncio.sleep(0.6)  # let the previous sentence go by
            while s.engine.now_ms < s.engine.speech_end_ms + 300:
                await frames.__anext__()
            t0 = time.perf_counter()
            await s.say(SENTENCES[k % len(SENTENCES)])
            got_mouth = None
            while True:
                out = await frames.__anext__()
                if got_mouth is None and np.abs(out.frame.faps[2:18]).max() > 1:
                    got_mouth = time.perf_counter() - t0
                if np.abs(out.audio).max() > 0.02:
                    voiced.append(time.perf_counter() - t0)
                    break
            mouth.append(got_mouth if got_mouth is not None else voiced[-1])
    return mouth, voiced


async def audio_latency(seconds: float) -> list[float]:
    """Seconds from sending a 100 ms audio chunk to the frame at its first sample."""
    from facelib.speech import synthesize
    from facelib.speech.audio import load_speech

    made = synthesize(" ".join(SENTENCES))
    pcm = load_speech(made.samples, sample_rate=made.sample_rate)
    out = []
    async with Session(fps=30, lookahead_ms=80) as s:
        frames = s.frames().__aiter__()
        loop = asyncio.get_running_loop()
        t_start = loop.time()
        for k, first in enumerate(range(0, min(pcm.size, int(seconds * 16000)), 1600)):
            await asyncio.sleep(max(t_start + k * 0.1 - loop.time(), 0))
            sent = time.perf_counter()
            await s.audio(pcm[first:first + 1600])
            at = s._audio_next_ms - 100  # where this chunk's first sample went
            while True:
                o = await frames.__anext__()
                if o.frame.time_ms >= at:
                    out.append(time.perf_counter() - sent)
                    break
    return out


async def concurrent(k: int, seconds: float) -> tuple[float, float]:
    """Frames per second per session and the worst lag (s) of a frame behind its time."""
    lags: list[float] = []
    counts = [0] * k

    async def one(i: int) -> None:
        async with Session(fps=30, seed=i) as s:
            loop = asyncio.get_running_loop()
            await s.say(SENTENCES[i % len(SENTENCES)] + " " + SENTENCES[(i + 1) % 5])
            async for o in s.frames():
                lags.append(loop.time() - s._t0 - o.frame.time_ms / 1000)
                counts[i] += 1
                if o.frame.time_ms >= seconds * 1000:
                    break

    await asyncio.gather(*(one(i) for i in range(k)))
    return float(np.mean(counts)) / seconds, max(lags)


def _pct(values: list[float]) -> str:
    ms = np.array(values) * 1000
    return f"p50 {np.percentile(ms, 50):.0f} ms, p95 {np.percentile(ms, 95):.0f} ms (n={ms.size})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--sentences", type=int, default=20)
    parser.add_argument("--audio-s", type=float, default=8.0)
    parser.add_argument("--sessions", type=int, default=10)
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    mouth, voiced = asyncio.run(text_latency(args.sentences))
    print(f"text in -> first mouth frame:   {_pct(mouth)}")
    print(f"text in -> first voiced frame:  {_pct(voiced)}")
    heard = asyncio.run(audio_latency(args.audio_s))
    print(f"audio in -> its frame (80 ms look-ahead): {_pct(heard)}")
    fps, lag = asyncio.run(concurrent(args.sessions, args.seconds))
    print(f"{args.sessions} sessions at 30 fps: {fps:.1f} frames/s each, "
          f"worst lag {lag * 1000:.0f} ms")


if __name__ == "__main__":
    main()
