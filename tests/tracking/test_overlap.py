"""The threads beside MediaPipe: the same items and results in the same order as inline,
errors raised in the caller, and no thread or decoder left running."""

import threading

import pytest

from facelib.tracking.overlap import InOrder, read_ahead


def _threads() -> set[str]:
    return {t.name for t in threading.enumerate() if t.name.startswith("facelib-")}


def test_read_ahead_gives_every_item_in_order():
    assert list(read_ahead(iter(range(1000)), depth=3)) == list(range(1000))
    assert not _threads()


def test_read_ahead_raises_the_source_error_at_its_place():
    def source():
        yield 1
        yield 2
        raise ValueError("frame 3 is broken")

    got = []

    def consume():
        for item in read_ahead(source()):
            got.append(item)  # noqa: PERF402 (the items before the error)

    with pytest.raises(ValueError, match="frame 3"):
        consume()
    assert got == [1, 2]
    assert not _threads()


def test_stopping_early_closes_the_source():
    closed = threading.Event()

    def source():
        try:
            yield from range(10_000)
        finally:
            closed.set()

    items = read_ahead(source(), depth=2)
    assert [next(items) for _ in range(5)] == [0, 1, 2, 3, 4]
    items.close()
    assert closed.is_set()
    assert not _threads()


def test_in_order_runs_calls_in_submission_order():
    seen = []
    with InOrder(depth=2) as worker:
        for k in range(500):
            worker.submit(lambda k=k: seen.append(k))
        worker.wait()
        assert seen == list(range(500))
        worker.submit(lambda: seen.append("last"))
    assert seen[-1] == "last"
    assert not _threads()


def test_in_order_raises_the_first_error_and_skips_the_rest():
    seen = []

    def fail():
        raise RuntimeError("brows of frame 2")

    def run():
        with InOrder() as worker:
            worker.submit(lambda: seen.append(1))
            worker.submit(fail)
            worker.submit(lambda: seen.append(3))

    with pytest.raises(RuntimeError, match="frame 2"):
        run()
    assert seen == [1]
    assert not _threads()


def test_an_error_in_the_caller_drops_the_waiting_calls():
    started = threading.Event()
    seen = []

    def slow():  # still running when the caller fails: ends once the worker drops the rest
        started.set()
        for _ in range(10_000):
            if worker._dropping:
                break
            threading.Event().wait(0.001)
        seen.append("slow")

    def run():
        with worker:
            worker.submit(slow)
            worker.submit(lambda: seen.append("dropped"))
            started.wait(5)
            raise KeyError("caller")

    worker = InOrder()
    with pytest.raises(KeyError):
        run()
    assert seen == ["slow"]
    assert not _threads()
