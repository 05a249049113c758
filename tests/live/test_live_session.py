"""Live sessions: the same input gives the offline pipeline's frames; text, cues and audio
go where the clock says; bad cues are refused with a FacelibError."""

from __future__ import annotations

import asyncio

import numpy as np
import pytest

from facelib.animation import animate
from facelib.errors import FdlError, ParameterError
from facelib.fdl import loads
from facelib.live.engine import Engine
from facelib.live.inputs import cues_from_fdl, cues_from_json, split_sentences
from facelib.live.session import OUTPUT_RATE, Session, SyncSession

pytestmark = pytest.mark.speech

STORYBOARD = '''fps = 30
seed = 7
say { "Hello there, how are you today?", at = 0.5 }
show { "joy", at = 1, dur = 2 }
look { "lookTo", "left", dur = 0.8, at = 2.5 }
'''


async def _live_run() -> list:
    async with Session(clock="manual", seed=7, fps=30) as s:
        await s.say("Hello there, how are you today?", at_ms=500)
        await s.advance(900)  # frames go out before the later cues are known
        await s.cue('show { "joy", dur = 2 }', at_ms=1000)
        await s.advance(2400)
        await s.cue({"look": "lookTo", "args": ["left"], "dur_ms": 800}, at_ms=2500)
        await s.stop()
        return [o async for o in s.messages()]


def test_a_session_gives_the_offline_frames_bit_for_bit() -> None:
    offline = animate(loads(STORYBOARD)).faps
    out = asyncio.run(_live_run())
    frames = [o for o in out if not isinstance(o, dict)]
    events = [o for o in out if isinstance(o, dict)]
    assert [e["type"] for e in events] == ["speech"] and events[0]["start_ms"] == 500
    assert len(frames) == offline.n_frames == 100
    values = np.stack([o.frame.faps for o in frames])
    assert np.array_equal(values, offline.values)
    masks = np.stack([o.frame.mask for o in frames])
    assert not (masks & ~offline.mask).any()  # a frame sets only what the stream sets
    # the synthesized speech goes out with its frames: silent before 500 ms, voiced after
    audio = np.concatenate([o.audio for o in frames])
    assert audio.size == round(offline.n_frames / 30 * OUTPUT_RATE)
    assert not audio[: OUTPUT_RATE // 2].any() and np.abs(audio[OUTPUT_RATE:]).max() > 0.1


def test_later_input_never_changes_frames_already_out() -> None:
    engine = Engine(fps=25, seed=3)
    first = engine.advance(2000)
    alone = Engine(fps=25, seed=3).advance(4000)
    assert all(np.array_equal(a.faps, b.faps) for a, b in zip(first, alone, strict=False))
    start = engine.add_cues(cues_from_json({"show": "joy", "dur_ms": 500}).expressions)
    assert start == 2000  # placed at the first frame not yet out
    later = engine.advance(4000)
    changed = [f.index for f, g in zip(later, alone[50:], strict=True)
               if not np.array_equal(f.faps, g.faps)]
    assert changed and changed[0] >= 50


def test_idle_eyes_blink_and_move_on_their_own() -> None:
    frames = Engine(fps=25, seed=1).advance(20_000)
    lids = np.array([f.faps[18] for f in frames])  # FAP 19, upper left lid
    yaw = np.array([f.faps[22] for f in frames])  # FAP 23, left eye yaw
    assert lids.max() > 0.8 * 1024 and np.ptp(yaw) > 0  # blinks and saccades while silent


def test_epochs_bound_the_window_and_cross_fade() -> None:
    engine = Engine(fps=25, seed=2, epoch_s=2.0, crossfade_ms=400)
    frames = engine.advance(8000)
    values = np.stack([f.faps for f in frames])
    assert engine._epoch.start > 0  # a later epoch runs
    assert engine._epoch.window is not None and engine._epoch.window.n_frames < 200
    step = np.abs(np.diff(values[:, 47:50], axis=0)).max()  # head FAPs: no jump at a seam
    assert step < 2000


def test_text_is_split_into_sentences_as_it_streams() -> None:
    assert split_sentences("Hello there. How") == (["Hello there."], "How")
    assert split_sentences("are you? I am", flush=True) == (["are you?", "I am"], "")
    assert split_sentences("3.5 apples") == ([], "3.5 apples")
    assert split_sentences(" ... ", flush=True) == ([], "")


@pytest.mark.parametrize("snippet", [
    'say "hello"', 'define_expression { "x", open_jaw = 1 }', "while true do end",
    'show { "joy", dur = 1 }\nshow { "joy", dur = 1 }', "x" * 500, 'os.execute("ls")',
])
def test_hostile_or_foreign_snippets_are_refused(snippet: str) -> None:
    with pytest.raises(FdlError):
        cues_from_fdl(snippet)


def test_cue_messages_are_checked() -> None:
    assert cues_from_json({"camera": "face"}).camera[0].duration_ms == 0
    for bad in ({}, {"show": "joy", "look": "x"}, {"show": 3}, {"show": "joy", "dur_ms": -1},
                {"look": "lookTo", "args": [True]}, {"show": "joy", "intensity": 2}):
        with pytest.raises(ParameterError):
            cues_from_json(bad)


def test_streamed_audio_moves_the_jaw_in_its_frames() -> None:
    from facelib.speech import synthesize
    from facelib.speech.audio import load_speech

    made = synthesize("Open your mouth wide and say ah.")
    pcm = load_speech(made.samples, sample_rate=made.sample_rate)
    with SyncSession(clock="manual", lookahead_ms=80) as s:
        for k in range(0, pcm.size, 1600):  # 100 ms chunks
            s.audio((pcm[k:k + 1600] * 32767).astype("<i2").tobytes())
        s.stop()
        frames = list(s.frames())
    jaw = np.array([o.frame.faps[2] for o in frames])  # FAP 3, open_jaw
    heard = np.concatenate([o.audio for o in frames])
    first = np.flatnonzero(np.abs(heard) > 1e-3)[0]
    assert abs(first - 80 * OUTPUT_RATE // 1000) < OUTPUT_RATE // 100  # out after 80 ms
    assert jaw.max() > 0 and any(o.frame.viseme > 0 for o in frames)


def test_streamed_audio_that_never_stops_still_ends_epochs() -> None:
    """A microphone streams without a break: an epoch ends between two stretches of its
    audio, the next takes the stretch that starts there, and each sample is heard once."""
    from facelib.speech import synthesize
    from facelib.speech.audio import load_speech

    made = synthesize("Say it again, and again, please.")
    said = load_speech(made.samples, sample_rate=made.sample_rate)
    pcm = np.tile(np.concatenate([said, np.zeros(8000, np.float32)]), 6)  # about 16 s
    with SyncSession(clock="manual", lookahead_ms=80, epoch_s=2.0, queue_s=30) as s:
        for k in range(0, pcm.size - 1600, 1600):
            s.audio((pcm[k:k + 1600] * 32767).astype("<i2").tobytes())
            s.advance((k // 1600 + 1) * 100)
        s.stop()
        frames = list(s.frames())
        # the first stretch (about 10.5 s) ends an epoch, the stop another: with epochs
        # waiting for a quiet session, only the stop would
        assert s.session.engine._epochs == 3
    heard = np.concatenate([o.audio for o in frames])
    sent = np.abs(pcm).max()
    assert 0.8 * sent < np.abs(heard).max() < 1.2 * sent  # none of it twice over
    jaw = np.array([o.frame.faps[2] for o in frames])  # FAP 3, open_jaw
    assert jaw[330:450].max() > 0.5 * jaw.max()  # the carried stretch moves the mouth


def test_windows_computed_ahead_on_the_wall_clock_give_the_same_frames() -> None:
    async def run() -> list:
        async with Session(fps=30, seed=4) as s:  # wall clock: windows come from a thread
            out = []
            async for o in s.frames():
                out.append(o)
                if len(out) == 100:  # past the first window's prefetch point
                    return out
        return out

    live = asyncio.run(run())
    alone = Engine(fps=30, seed=4).advance(100 * 1000 / 30)
    assert [o.frame.index for o in live] == list(range(100))
    assert all(np.array_equal(o.frame.faps, f.faps) for o, f in zip(live, alone, strict=True))


def test_streamed_audio_in_any_language_takes_the_acoustic_model() -> None:
    """The listener's acoustic stream decides each frame as the offline model does, and a
    session hears Italian audio (no transcript, no English model) with its closures."""
    from facelib.live.listen import Listener
    from facelib.speech import synthesize
    from facelib.speech.acoustic import frame_classes
    from facelib.speech.audio import load_speech

    made = synthesize("Mamma, il babbo porta la mela.", lang="it")
    pcm = load_speech(made.samples, sample_rate=made.sample_rate)
    listener = Listener(method="acoustic")
    for k in range(0, pcm.size, 1600):
        timeline, _ = listener.feed(pcm[k:k + 1600])
    assert timeline.source == "acoustic" and timeline.duration_ms == pcm.size // 16
    decided = listener._stream.classes  # what the stream has decided
    assert decided == frame_classes(pcm)[:len(decided)].tolist()
    assert len(decided) >= pcm.size // 160 - 12  # at most the look-ahead undecided
    assert any(v.is_bilabial for v in timeline.visemes)
    with SyncSession(clock="manual", lookahead_ms=100, lang="it") as s:
        for k in range(0, pcm.size, 1600):
            s.audio((pcm[k:k + 1600] * 32767).astype("<i2").tobytes())
        s.stop()
        frames = list(s.frames())
    assert any(o.frame.viseme == 1 for o in frames)
    with pytest.raises(ParameterError, match="listen"):
        Listener(method="words")  # type: ignore[arg-type]
