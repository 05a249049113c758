"""``facelib serve`` driven by a real WebSocket client on a free loopback port: frames match
the offline pipeline, bad input gets an error and the server goes on."""

from __future__ import annotations

import asyncio
import base64
import json
from collections.abc import AsyncIterator, Awaitable, Callable
from contextlib import asynccontextmanager
from typing import Any

import numpy as np
import pytest

pytest.importorskip("websockets")
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed

from facelib.animation import animate
from facelib.errors import ParameterError
from facelib.fdl import loads
from facelib.live.server import HARD_MESSAGE_BYTES, MAX_MESSAGE_BYTES, ServerOptions, start_server

pytestmark = pytest.mark.speech
LIMIT_S = 60


@asynccontextmanager
async def _server(token: str | None = None) -> AsyncIterator[str]:
    server = await start_server(ServerOptions(port=0, token=token))
    port = server.sockets[0].getsockname()[1]
    try:
        yield f"ws://127.0.0.1:{port}"
    finally:
        server.close()
        await server.wait_closed()


def _run(body: Callable[[str], Awaitable[Any]], token: str | None = None) -> Any:
    async def main() -> Any:
        async with _server(token) as url:
            return await asyncio.wait_for(body(url), LIMIT_S)
    return asyncio.run(main())


async def _until(ws: Any, kind: str) -> tuple[dict, list[dict]]:
    seen = []
    while True:
        message = json.loads(await ws.recv())
        if message["type"] == kind:
            return message, seen
        seen.append(message)


def test_a_client_gets_the_offline_frames_with_their_audio() -> None:
    offline = animate(loads('fps = 25\nsay { "Good morning to you.", at = 0.4 }\n'
                            'show { "joy", at = 0.8, dur = 1.5 }\n')).faps

    async def body(url: str) -> list[dict]:
        async with connect(url) as ws:
            await ws.send(json.dumps({"type": "start", "fps": 25, "clock": "manual",
                                      "outputs": ["faps", "visemes"]}))
            started, _ = await _until(ws, "started")
            assert started["sample_rate"] == 16000
            await ws.send(json.dumps({"type": "text", "text": "Good morning ", "at_ms": 400}))
            await ws.send(json.dumps({"type": "text", "text": "to you.", "at_ms": 400}))
            await ws.send(json.dumps({"type": "advance", "until_ms": 600}))
            await ws.send(json.dumps({"type": "cue", "fdl": 'show { "joy", dur = 1.5 }',
                                      "at_ms": 800}))
            await ws.send(json.dumps({"type": "stop"}))
            _, seen = await _until(ws, "end")
            return seen

    seen = _run(body)
    frames = [m for m in seen if m["type"] == "frame"]
    assert [m["type"] for m in seen if m["type"] != "frame"] == ["speech"]
    assert [f["i"] for f in frames] == list(range(offline.n_frames))
    values = np.array([f["faps"] for f in frames])
    np.testing.assert_allclose(values, offline.values, atol=5e-4, rtol=0)
    assert any(f["viseme"] > 0 for f in frames)
    pcm = b"".join(base64.b64decode(f["audio"]["pcm"]) for f in frames)
    assert len(pcm) // 2 == round(offline.n_frames / 25 * 16000)


def test_bad_messages_get_errors_and_the_session_goes_on() -> None:
    async def body(url: str) -> list[str]:
        errors = []
        async with connect(url, max_size=None) as ws:
            await ws.send("{not json")
            errors.append((await _until(ws, "error"))[0]["message"])
            await ws.send(json.dumps({"type": "start", "clock": "manual", "fps": 10}))
            await _until(ws, "started")
            for bad in ("[1, 2]", json.dumps({"type": "dance"}),
                        json.dumps({"type": "text", "text": "x" * (MAX_MESSAGE_BYTES + 10)}),
                        json.dumps({"type": "cue", "fdl": "while true do end"}),
                        json.dumps({"type": "cue", "fdl": 'io.open("/etc/passwd")'}),
                        json.dumps({"type": "audio", "pcm": "%%%"}),
                        json.dumps({"type": "audio", "pcm": base64.b64encode(b"abc").decode()}),
                        "[" * 100_000 + "]" * 100_000,
                        json.dumps({"type": "advance", "until_ms": -5})):
                await ws.send(bad)
                errors.append((await _until(ws, "error"))[0]["message"])
            await ws.send(json.dumps({"type": "advance", "until_ms": 1000}))
            await ws.send(json.dumps({"type": "stop"}))
            _, seen = await _until(ws, "end")
            assert len([m for m in seen if m["type"] == "frame"]) == 10  # it went on
        async with connect(url, max_size=None) as ws:  # over the hard limit: it closes
            await ws.send("x" * (HARD_MESSAGE_BYTES + 1))
            with pytest.raises(ConnectionClosed):
                await ws.recv()
        async with connect(url) as ws:  # and the server is still up
            await ws.send(json.dumps({"type": "start", "clock": "manual"}))
            await _until(ws, "started")
        return errors

    errors = _run(body)
    assert len(errors) == 10 and all(errors)
    assert "not JSON" in errors[0] and "unknown message type" in errors[2]
    assert "FdlError" in errors[4] and "FdlError" in errors[5]


def test_a_token_is_needed_off_loopback_and_checked() -> None:
    with pytest.raises(ParameterError, match="token"):
        ServerOptions(host="0.0.0.0")

    async def body(url: str) -> str:
        async with connect(url) as ws:
            await ws.send(json.dumps({"type": "start", "token": "wrong"}))
            message, _ = await _until(ws, "error")
            with pytest.raises(ConnectionClosed):
                await ws.recv()
        async with connect(url) as ws:
            await ws.send(json.dumps({"type": "start", "token": "s3cret", "clock": "manual"}))
            await _until(ws, "started")
        return message["message"]

    assert "token" in _run(body, token="s3cret")


def test_a_wall_clock_session_streams_frames_in_real_time() -> None:
    async def body(url: str) -> list[dict]:
        async with connect(url) as ws:
            await ws.send(json.dumps({"type": "start", "fps": 20}))
            await _until(ws, "started")
            await ws.send(json.dumps({"type": "text", "text": "Hi.", "flush": True}))
            speech, _ = await _until(ws, "speech")
            frames = []
            while len(frames) < 30:
                message = json.loads(await ws.recv())
                if message["type"] == "frame":
                    frames.append(message)
            await ws.send(json.dumps({"type": "stop"}))
            await _until(ws, "end")
            return [speech, *frames]

    speech, *frames = _run(body)
    indices = [f["i"] for f in frames]
    assert indices == list(range(indices[0], indices[0] + 30))  # none dropped, in order
    assert speech["phones"] and speech["start_ms"] > 0
