"""Work done beside MediaPipe's graph on a second core: frames read ahead from the decoder,
and the per-frame work that follows the landmarks (the brows' registration, the face's
light) done in order on a worker thread.

MediaPipe, OpenCV, numpy's large operations and pipe reads release the GIL, so these
threads run while the face mesh does; the results are the same as done inline, in the
same order. Every thread here is joined before its function returns, also on error.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Generator, Iterator
from contextlib import suppress
from typing import Any, TypeVar

__all__ = ["InOrder", "read_ahead"]

T = TypeVar("T")

_DONE = object()
"""The end of an iterator (or a worker's queue)."""


def read_ahead(items: Iterator[T], *, depth: int = 4) -> Generator[T, None, None]:
    """``items`` as they come, read up to ``depth`` ahead on a thread (a video's frames
    decoded and copied from ffmpeg's pipe while the caller works on the last one).

    An exception raised by ``items`` is raised here at its place in the sequence. When the
    caller stops early (closes this generator), the thread stops and ``items`` is closed
    (its ``close()`` called where it has one), so a decoder's process ends too.
    """
    ahead: queue.Queue[Any] = queue.Queue(maxsize=depth)
    stop = threading.Event()

    def fill() -> None:
        try:
            for item in items:
                while True:  # wait for room, or for the caller to stop
                    if stop.is_set():
                        return
                    with suppress(queue.Full):
                        ahead.put(item, timeout=0.05)
                        break
            ahead.put(_DONE)
        except BaseException as exc:  # noqa: BLE001 (raised in the caller's thread)
            ahead.put(exc)

    thread = threading.Thread(target=fill, name="facelib-read-ahead", daemon=True)
    thread.start()
    try:
        while (item := ahead.get()) is not _DONE:
            if isinstance(item, BaseException):
                raise item
            yield item
    finally:
        stop.set()
        while thread.is_alive():  # let a blocked put() see the stop
            with suppress(queue.Empty):
                ahead.get(timeout=0.05)
        thread.join()
        close = getattr(items, "close", None)
        if close is not None:
            close()


class InOrder:
    """Calls run one at a time, in the order given, on one worker thread, at most ``depth``
    waiting (the caller waits beyond that). The first exception a call raises is raised
    by :meth:`wait` or :meth:`join` (the calls after it are skipped). Use as a context
    manager: leaving it joins the worker (and on an error in the caller, drops the calls not
    yet run)."""

    def __init__(self, *, depth: int = 8) -> None:
        self._calls: queue.Queue[Any] = queue.Queue(maxsize=depth)
        self._error: BaseException | None = None
        self._dropping = False
        self._thread = threading.Thread(target=self._work, name="facelib-in-order",
                                        daemon=True)
        self._thread.start()

    def _work(self) -> None:
        while (call := self._calls.get()) is not _DONE:
            if self._error is None and not self._dropping:
                try:
                    call()
                except BaseException as exc:  # noqa: BLE001 (raised by wait() or join())
                    self._error = exc
            self._calls.task_done()

    def submit(self, call: Callable[[], object]) -> None:
        """Run ``call()`` after the calls submitted before it."""
        if self._error is not None:
            self.join()
        self._calls.put(call)

    def wait(self) -> None:
        """Wait for the calls submitted so far (the worker stays); raise the first
        exception one raised."""
        self._calls.join()
        self._raise()

    def join(self) -> None:
        """Wait for every call submitted; raise the first exception one raised."""
        self._stop()
        self._raise()

    def _stop(self) -> None:
        if self._thread.is_alive():
            self._calls.put(_DONE)
            self._thread.join()

    def _raise(self) -> None:
        error, self._error = self._error, None
        if error is not None:
            raise error

    def __enter__(self) -> InOrder:
        return self

    def __exit__(self, kind: type[BaseException] | None, *_: object) -> None:
        if kind is None:
            self.join()
        else:  # the caller failed: skip what is left, stop, and let its error go on
            self._dropping = True
            self._stop()
