"""Dask clusters as facelib uses them: a client that reads only plain data from the cluster.

Dask's own client unpickles what a cluster sends: a task's result type, its exception and
traceback, ``warn`` events, and any frame marked as a pickle, whatever ``deserializers``
says. A worker can make the scheduler relay such a frame, so one hostile worker could run
code in the process that asked for the work. :func:`open_client` gives a client whose
every message from the cluster is decoded by :func:`decode_message` (msgpack, and results
serialized by msgpack; no pickle, no Dask types, no bytes) and whose handlers never
unpickle a type or an error; :func:`check_address` refuses a scheduler on another machine
over plain TCP unless the caller says the cluster is trusted. See ``docs/security.md``.

facelib keeps no state of its own here: the plain-data transport is registered once with
Dask's table of transports under its own schemes (``facelib-tcp``, ``facelib-tls``), which
nothing else uses.
"""

from __future__ import annotations

import contextlib
import ipaddress
import struct
from collections.abc import Iterator, Sequence
from typing import Any

from facelib.errors import FacelibError, FileError, ParameterError
from facelib.optional import missing_extra

__all__ = ["MAX_MESSAGE_BYTES", "TASK_FAILED", "check_address", "decode_message",
           "open_client", "refused", "tls_security"]

MAX_MESSAGE_BYTES = 64 * 1024 * 1024
"""The most bytes one message from the cluster may hold (facelib's are a few kB)."""
_MAX_DEPTH = 32
"""The deepest nesting of lists and maps read from a message."""
REFUSED = "<refused by facelib: {}>"
"""What stands in a message for a value that is not plain data (a pickle, bytes, ...)."""
TASK_FAILED = ("the task failed on the cluster (its error is not read: Dask sends it "
               "pickled); see the worker's log")
"""The error of every task that failed on the cluster."""
_PLAIN_SCHEMES = {"tcp": "facelib-tcp", "tls": "facelib-tls"}


def refused(value: object) -> bool:
    """Whether ``value`` is the stand-in :func:`decode_message` put for refused data."""
    return isinstance(value, str) and value.startswith(REFUSED[:REFUSED.index("{")])


def _plain(value: Any, depth: int = 0) -> Any:
    """``value`` (decoded msgpack) with every part that is not plain data (text, numbers,
    booleans, None, and lists, tuples, sets and maps of them) replaced by a stand-in."""
    if value is None or isinstance(value, str | int | float | bool):
        return value
    if depth >= _MAX_DEPTH:
        return REFUSED.format("nested too deeply")
    if isinstance(value, tuple | list):
        return tuple(_plain(v, depth + 1) for v in value)
    if isinstance(value, set | frozenset):
        return {_plain(v, depth + 1) for v in value if isinstance(v, str | int | float)}
    if isinstance(value, dict):
        keys = [_plain(k, depth + 1) for k in value]
        if any(refused(k) for k in keys):
            return REFUSED.format("a map with keys that are not plain data")
        return {k: _plain(v, depth + 1) for k, v in zip(keys, value.values(), strict=True)}
    if isinstance(value, bytes | bytearray | memoryview):
        return REFUSED.format("bytes")
    return REFUSED.format(type(value).__name__)


def _serialized(header_frame: Any, frames: Sequence[Any], offset: int) -> Any:
    """The value of a ``__Serialized__`` entry whose header is ``frames[offset]``: decoded
    when msgpack serialized it (uncompressed, in one frame), else a stand-in."""
    import msgpack

    try:
        header = msgpack.loads(header_frame, raw=False, strict_map_key=False)
    except (ValueError, TypeError, msgpack.UnpackException):
        return REFUSED.format("a malformed header")
    if not isinstance(header, dict) or header.get("serializer") != "msgpack":
        kind = header.get("serializer") if isinstance(header, dict) else None
        return REFUSED.format(f"data serialized by {kind!r:.40}")
    if (header.get("num-sub-frames") != 1
            or list(header.get("split-num-sub-frames", [1])) != [1]
            or list(header.get("compression", [None])) != [None]):
        return REFUSED.format("data in split or compressed frames")
    if offset + 2 > len(frames):
        return REFUSED.format("a missing frame")
    return _msgpack(frames[offset + 1], frames, nested=True)


def _msgpack(data: Any, frames: Sequence[Any], *, nested: bool) -> Any:
    """``data`` decoded as msgpack; Dask's ``__Serialized__`` entries at the top level are
    followed into ``frames`` (msgpack only), every other extension is refused."""
    import msgpack

    def hook(entry: dict[Any, Any]) -> Any:
        if "__Pickled__" in entry:
            return REFUSED.format("a pickle")
        offset = entry.get("__Serialized__")
        if offset is not None:
            if nested or not isinstance(offset, int) or isinstance(offset, bool) \
                    or not 0 < offset < len(frames):
                return REFUSED.format("serialized data")
            return _serialized(frames[offset], frames, offset)
        if "__Enum__" in entry:
            return REFUSED.format("a Python enum")
        if "__Set__" in entry:
            return set(entry["as-list"]) if isinstance(entry.get("as-list"), tuple) else \
                REFUSED.format("a malformed set")
        return entry

    try:
        return _plain(msgpack.loads(data, object_hook=hook, use_list=False, raw=False,
                                    strict_map_key=False))
    except (ValueError, TypeError, RecursionError, msgpack.UnpackException):
        return REFUSED.format("malformed msgpack")


def decode_message(frames: Sequence[bytes | memoryview]) -> Any:
    """One message of Dask's protocol (``frames[0]`` msgpack, the rest the frames its
    ``__Serialized__`` entries point at) as plain data; what is not is a stand-in text
    (see :func:`refused`). Never unpickles and never imports."""
    if not frames:
        return REFUSED.format("an empty message")
    return _msgpack(frames[0], frames, nested=False)


async def _read_frames(comm: Any) -> list[Any]:
    """The frames of the next message on ``comm`` (a Dask TCP comm), at most
    :data:`MAX_MESSAGE_BYTES` in all; a longer one closes the comm."""
    from distributed.comm.core import CommClosedError
    from distributed.comm.tcp import convert_stream_closed_error, read_bytes_rw
    from distributed.protocol.utils import unpack_frames
    from tornado.iostream import StreamClosedError

    stream = comm.stream
    if stream is None:
        raise CommClosedError()
    try:
        (size,) = struct.unpack("Q", await stream.read_bytes(8))
        if size > MAX_MESSAGE_BYTES:
            raise CommClosedError(f"a message of {size} bytes from the cluster (facelib "
                                  f"reads at most {MAX_MESSAGE_BYTES})")
        frames, buffer_sizes = unpack_frames(await read_bytes_rw(stream, size), partial=True)
        if size + sum(buffer_sizes) > MAX_MESSAGE_BYTES:
            raise CommClosedError(f"a message of {size + sum(buffer_sizes)} bytes from the "
                                  f"cluster (facelib reads at most {MAX_MESSAGE_BYTES})")
        for n in buffer_sizes:
            frames.append(await read_bytes_rw(stream, n))
    except StreamClosedError as exc:
        comm.stream = None
        comm._closed = True
        convert_stream_closed_error(comm, exc)
    except BaseException:
        comm.abort()  # a partly read message leaves the stream unusable
        raise
    return frames


def _register_plain_transport() -> None:
    """Add facelib's plain-data TCP and TLS transports to Dask's table (once)."""
    from distributed.comm import registry
    from distributed.comm.tcp import TCP, TLS, TCPBackend, TCPConnector, TLSBackend, TLSConnector

    class PlainTCP(TCP):
        async def read(self, deserializers: Any = None) -> Any:
            return decode_message(await _read_frames(self))

    class PlainTLS(TLS):
        async def read(self, deserializers: Any = None) -> Any:
            return decode_message(await _read_frames(self))

    class PlainTCPConnector(TCPConnector):
        comm_class = PlainTCP

    class PlainTLSConnector(TLSConnector):
        comm_class = PlainTLS

    class PlainTCPBackend(TCPBackend):
        _connector_class = PlainTCPConnector

    class PlainTLSBackend(TLSBackend):
        _connector_class = PlainTLSConnector

    registry.backends.setdefault(_PLAIN_SCHEMES["tcp"], PlainTCPBackend())
    registry.backends.setdefault(_PLAIN_SCHEMES["tls"], PlainTLSBackend())


def _plain_client_class() -> type:
    """A ``distributed.Client`` that never unpickles a result's type or a task's error and
    ignores events (a worker's ``print`` and ``warn``)."""
    from distributed import Client

    class PlainDataClient(Client):
        def _handle_key_in_memory(self, key: Any = None, type: Any = None,
                                  workers: Any = None) -> None:
            super()._handle_key_in_memory(key=key, type=None, workers=workers)

        def _handle_task_erred(self, key: Any = None, exception: Any = None,
                               traceback: Any = None) -> None:
            super()._handle_task_erred(key=key, exception=TASK_FAILED, traceback=None)

        async def _handle_event(self, topic: Any, event: Any) -> None:
            return None

    return PlainDataClient


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def check_address(address: object, *, tls: bool, trust: bool) -> str:
    """``address`` (``tcp://HOST:PORT``, ``tls://HOST:PORT`` or ``HOST:PORT``) in full, if
    facelib may use it: a ``tls://`` address needs TLS settings (``tls``), and a ``tcp://``
    one a scheduler on this machine unless ``trust`` (the caller trusts the cluster and
    the network to it). Other schemes need ``trust``."""
    if not isinstance(address, str) or not 0 < len(address) <= 1000:
        raise ParameterError(f"a scheduler address must be a text like tcp://HOST:8786, got "
                             f"{address!r:.80}")
    full = address if "://" in address else f"tcp://{address}"
    scheme, _, location = full.partition("://")
    try:
        from distributed.comm.addressing import parse_host_port

        host = str(parse_host_port(location)[0])
    except (ValueError, TypeError):
        raise ParameterError(f"scheduler {address!r}: not an address like "
                             f"tcp://HOST:8786") from None
    if scheme == "tls" and not tls:
        raise ParameterError(f"scheduler {address!r}: a tls:// address needs the cluster's "
                             f"certificates (--tls-ca, --tls-cert, --tls-key)")
    if scheme == "tcp" and tls:
        raise ParameterError(f"scheduler {address!r}: TLS settings were given for a tcp:// "
                             f"address; use tls://")
    if scheme not in _PLAIN_SCHEMES and not trust:
        raise ParameterError(f"scheduler {address!r}: facelib talks to a cluster over tcp:// "
                             f"or tls:// (pass --trust-cluster to use another transport)")
    if scheme == "tcp" and not trust and not _is_loopback(host):
        raise ParameterError(
            f"scheduler {address!r} is not on this machine: anyone on the network between "
            f"could pose as it; connect with TLS (tls://, --tls-ca, --tls-cert, --tls-key) "
            f"or pass --trust-cluster if the cluster and the network are yours")
    return full


def tls_security(*, ca: str, cert: str, key: str) -> Any:
    """Dask ``Security`` for a client of a TLS cluster: the CA that signed the cluster's
    certificates (the scheduler must show one), this client's certificate and key; TLS
    is required on every connection. The files must be regular files."""
    from pathlib import Path

    try:
        from distributed.security import Security
    except ImportError:
        raise missing_extra("distributed") from None
    for what, path in (("--tls-ca", ca), ("--tls-cert", cert), ("--tls-key", key)):
        if not Path(path).is_file():
            raise FileError(f"{what}: not a readable file", path=path)
    return Security(tls_ca_file=ca, tls_client_cert=cert, tls_client_key=key,
                    require_encryption=True)


def _security(client: Any) -> Any:
    security = getattr(client, "security", None)
    return security if getattr(security, "require_encryption", False) or \
        getattr(security, "tls_ca_file", None) else None


@contextlib.contextmanager
def open_client(scheduler: Any, *, security: Any = None, trust: bool = False,
                timeout: float = 30) -> Iterator[Any]:
    """A connected plain-data client for ``scheduler`` (an address, checked by
    :func:`check_address`, or a ``distributed.Client``), closed on leaving. A Client the
    caller made is used as it is only with ``trust``; otherwise facelib opens its own
    plain-data client to the same scheduler with the same security."""
    try:
        from distributed import Client
    except ImportError:
        raise missing_extra("distributed") from None
    if isinstance(scheduler, Client):
        if trust:
            yield scheduler
            return
        security = security or _security(scheduler)
        scheduler = getattr(scheduler.scheduler, "address", None)
    address = check_address(scheduler, tls=security is not None, trust=trust)
    scheme, _, location = address.partition("://")
    if scheme in _PLAIN_SCHEMES:
        _register_plain_transport()
        address = f"{_PLAIN_SCHEMES[scheme]}://{location}"
        client_class = _plain_client_class()
    else:
        client_class = Client
    try:
        client = client_class(address, security=security, timeout=timeout,
                              serializers=["msgpack"], deserializers=["msgpack"],
                              direct_to_workers=False, set_as_default=False)
    except (OSError, TimeoutError) as exc:
        raise FacelibError(f"cannot reach the Dask scheduler {scheduler!r}: {exc}") from None
    try:
        yield client
    finally:
        client.close()
