"""``facelib serve``: live sessions over WebSocket (the ``live`` extra: ``websockets``).

One connection is one :class:`~facelib.live.session.Session`. The protocol (JSON text
messages; ``docs/live.md``):

in:  ``start`` (first; options, and ``token`` when the server has one), ``text``, ``audio``
     (``pcm``: base64 16-bit mono 16 kHz), ``cue`` (``fdl`` snippet, or ``show`` / ``look``
     / ``camera``), ``advance`` (manual clock), ``stop``;
out: ``started``, ``frame`` (``faps`` and/or ``arkit`` and/or ``viseme``, with ``audio``
     of the same time span), ``speech``, ``camera``, ``error``, ``end``.

A message the server cannot use gets an ``error`` message and the session goes on; one
over :data:`MAX_MESSAGE_BYTES` too (the library closes the connection above
:data:`HARD_MESSAGE_BYTES`). A slow reader loses the oldest frames (``dropped`` counts them),
never the server's memory. The server listens on 127.0.0.1 unless told otherwise and then
only with a token.
"""

from __future__ import annotations

import asyncio
import base64
import binascii
import hmac
import json
import logging
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

from facelib.errors import FacelibError, ParameterError
from facelib.live.session import OUTPUT_RATE, Output, Session
from facelib.live.udp import is_loopback, parse_target
from facelib.optional import require

__all__ = ["HARD_MESSAGE_BYTES", "MAX_MESSAGE_BYTES", "ServerOptions", "frame_message",
           "serve", "start_server"]

log = logging.getLogger("facelib.live")

MAX_MESSAGE_BYTES = 256 * 1024
"""Largest message a session reads; a larger one gets an error and is dropped."""
HARD_MESSAGE_BYTES = 1024 * 1024
"""Largest message the WebSocket layer accepts at all (it closes the connection, code 1009)."""
_OUTPUTS = {"faps", "arkit", "visemes"}
_SESSION_KEYS = ("fps", "lookahead_ms", "seed", "lang", "voice", "rate", "clock", "face",
                 "audio_in", "subject", "listen")
_START_KEYS = {"type", "token", "fps", "lookahead_ms", "seed", "lang", "voice", "rate",
               "outputs", "clock", "face", "audio_in", "livelink", "vmc", "subject", "listen"}


@dataclass(frozen=True)
class ServerOptions:
    """Where and how the server listens: ``host``, ``port``, ``token`` (required unless the
    host is a loopback address), ``max_sessions`` at once; ``livelink`` / ``vmc``:
    ``HOST:PORT`` every session's frames also go to (any host: the operator names it; a
    ``start`` message may name a loopback one for its own session)."""

    host: str = "127.0.0.1"
    port: int = 8765
    token: str | None = None
    max_sessions: int = 16
    livelink: str | None = None
    vmc: str | None = None

    def __post_init__(self) -> None:
        if not is_loopback(self.host) and not self.token:
            raise ParameterError(f"serving on {self.host!r} (not loopback) needs a token")
        if not 0 <= self.port <= 65535:
            raise ParameterError(f"port must be 0-65535, got {self.port!r}")


def _websockets() -> Any:
    return require("websockets")


def frame_message(out: Output, outputs: set[str]) -> dict[str, Any]:
    """The ``frame`` message of one output: index ``i``, time ``t_ms``, the asked-for
    ``faps`` (84 numbers, FAP k at k-1), ``arkit`` (52 weights) and ``viseme`` (id 0-14 or
    -1), ``speaking``, ``audio`` (base64 16-bit PCM at ``rate`` Hz, the frame's span) and
    ``dropped``."""
    f = out.frame
    message: dict[str, Any] = {"type": "frame", "i": f.index, "t_ms": round(f.time_ms, 3),
                               "speaking": f.speaking, "dropped": out.dropped}
    if "faps" in outputs:
        message["faps"] = [round(float(v), 3) for v in f.faps]
    if "arkit" in outputs and out.arkit is not None:
        message["arkit"] = [round(float(v), 4) for v in out.arkit]
    if "visemes" in outputs:
        message["viseme"] = f.viseme
    pcm = (out.audio.clip(-1, 1) * 32767).round().astype("<i2").tobytes()
    message["audio"] = {"rate": OUTPUT_RATE, "pcm": base64.b64encode(pcm).decode("ascii")}
    return message


def _session_from(start: dict[str, Any], options: ServerOptions) -> tuple[Session, set[str]]:
    """The session a ``start`` message asks for; ParameterError naming what is wrong."""
    if start.get("type") != "start":
        raise ParameterError("the first message must be {\"type\": \"start\", ...}")
    unknown = set(start) - _START_KEYS
    if unknown:
        raise ParameterError(f"start: unknown options {sorted(unknown)}")
    if options.token is not None and not (
            isinstance(start.get("token"), str)
            and hmac.compare_digest(start["token"].encode(), options.token.encode())):
        raise PermissionError("start: wrong or missing token")
    outputs = start.get("outputs", ["faps", "visemes"])
    if not isinstance(outputs, list) or not outputs or not set(outputs) <= _OUTPUTS:
        raise ParameterError(f"start: outputs must be a list from {sorted(_OUTPUTS)}")
    if not isinstance(start.get("audio_in", False), bool):
        raise ParameterError("start: audio_in must be true or false")
    kwargs: dict[str, Any] = {k: start[k] for k in _SESSION_KEYS if k in start}
    for kind, port in (("livelink", 11111), ("vmc", 39539)):
        if start.get(kind) is not None:  # a client may only name loopback targets
            parse_target(start[kind], default_port=port, loopback_only=True)
            kwargs[kind] = start[kind]
        elif getattr(options, kind) is not None:
            kwargs[kind] = getattr(options, kind)
    return Session(arkit="arkit" in outputs, **kwargs), set(outputs)


async def _handle(session: Session, message: dict[str, Any]) -> bool:
    """Act on one message of a started session; False for ``stop``."""
    kind = message.get("type")
    at_ms = message.get("at_ms")
    if at_ms is not None and (isinstance(at_ms, bool) or not isinstance(at_ms, int)):
        raise ParameterError(f"at_ms must be an integer of ms, got {at_ms!r}")
    if kind == "text":
        await session.say(message.get("text", ""), flush=bool(message.get("flush", False)),
                          at_ms=at_ms)
    elif kind == "audio":
        try:
            pcm = base64.b64decode(str(message.get("pcm", "")), validate=True)
        except (binascii.Error, ValueError) as exc:
            raise ParameterError(f"audio: pcm is not base64 ({exc})") from None
        await session.audio(pcm)
    elif kind == "cue":
        cue = message["fdl"] if "fdl" in message else {
            k: v for k, v in message.items() if k not in ("type", "at_ms")}
        await session.cue(cue, at_ms=at_ms)
    elif kind == "advance":
        until = message.get("until_ms")
        if session.clock != "manual" or isinstance(until, bool) or not isinstance(
                until, int | float) or not 0 <= until <= 86_400_000:
            raise ParameterError("advance takes until_ms (ms) and a session with clock manual")
        await session.advance(float(until))
    elif kind == "stop":
        return False
    else:
        raise ParameterError(f"unknown message type {kind!r} (text, audio, cue, advance, stop)")
    return True


def _decode(raw: str | bytes) -> dict[str, Any]:
    if len(raw) > MAX_MESSAGE_BYTES:
        raise ParameterError(f"message of {len(raw)} bytes, more than {MAX_MESSAGE_BYTES}")
    try:
        message = json.loads(raw)
    except (ValueError, RecursionError) as exc:
        raise ParameterError(f"not JSON: {str(exc)[:120]}") from None
    if not isinstance(message, dict):
        raise ParameterError("a message is a JSON object with a type")
    return message


def _error_text(exc: BaseException) -> str:
    text = exc.message if isinstance(exc, FacelibError) else str(exc)
    return f"{type(exc).__name__}: {text}"[:500]


async def _pump(session: Session, outputs: set[str],
                send: Callable[[str], Awaitable[None]]) -> None:
    """Send the session's frames and events until it ends."""
    async for item in session.messages():
        text = json.dumps(item if isinstance(item, dict) else frame_message(item, outputs))
        await send(text)
    await send(json.dumps({"type": "end"}))


async def _connection(ws: Any, options: ServerOptions, live: set[Any]) -> None:
    """One client: start, then messages until stop or close; errors go to the client."""
    async def error(exc: BaseException) -> None:
        await ws.send(json.dumps({"type": "error", "message": _error_text(exc)}))

    if len(live) >= options.max_sessions:
        await error(ParameterError(f"the server has {options.max_sessions} sessions already"))
        return
    live.add(ws)
    try:
        while True:
            try:
                session, outputs = _session_from(_decode(await ws.recv()), options)
                break
            except (FacelibError, PermissionError, TypeError, ValueError) as exc:
                await error(exc)
                if isinstance(exc, PermissionError):
                    return
        await _serve_session(ws, session, outputs, error)
    finally:
        live.discard(ws)


async def _serve_session(ws: Any, session: Session, outputs: set[str],
                         error: Callable[[BaseException], Awaitable[None]]) -> None:
    async with session:
        await ws.send(json.dumps({"type": "started", "fps": session.engine.fps,
                                  "lookahead_ms": session.lookahead_ms,
                                  "sample_rate": OUTPUT_RATE, "clock": session.clock}))
        pump = asyncio.create_task(_pump(session, outputs, ws.send))
        try:
            async for raw in ws:
                try:
                    if not await _handle(session, _decode(raw)):
                        await session.stop()
                        break
                except Exception as exc:  # noqa: BLE001 - every bad message is answered
                    await error(exc)
            else:  # the client went away: end the session now
                await session.close()
            await pump
        finally:
            pump.cancel()


async def start_server(options: ServerOptions) -> Any:
    """Start listening; returns the websockets server (``.sockets``, ``.close()``)."""
    server = _websockets()
    live: set[Any] = set()

    async def handler(ws: Any) -> None:
        try:
            await _connection(ws, options, live)
        except Exception as exc:  # noqa: BLE001 - one connection never takes the server down
            log.info("connection ended: %s", _error_text(exc))

    return await server.serve(handler, options.host, options.port,
                              max_size=HARD_MESSAGE_BYTES, max_queue=16)


async def serve(options: ServerOptions) -> None:
    """Serve until cancelled."""
    server = await start_server(options)
    async with server:
        await server.serve_forever()
