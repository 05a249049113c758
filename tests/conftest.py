"""Fixtures shared by the whole test tree: a seeded random generator and the builders that
tests used to re-declare per file (FAP frames and streams, the default head), and a memory
cap for hostile-input tests."""

from __future__ import annotations

import resource
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import N_FAPS, fap

HOSTILE_HEADROOM = 1536 * 1024 * 1024
"""Address space a hostile-input test may add to the process (1.5 GiB)."""


def _virtual_size() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmSize:"):
            return int(line.split()[1]) * 1024
    return 0


@pytest.fixture
def memory_cap() -> Iterator[None]:
    """Cap the process's address space at its current size plus 1.5 GiB for one test, so a
    regression in a hostile-input test fails with MemoryError instead of swamping the
    machine; the previous limit is restored afterwards."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    size = _virtual_size()
    if not size:
        pytest.skip("no /proc/self/status to measure the address space")
    cap = size + HOSTILE_HEADROOM
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


FapFrame = Callable[..., np.ndarray]
FapStreamBuilder = Callable[..., FapStream]


@pytest.fixture
def rng(request: pytest.FixtureRequest) -> np.random.Generator:
    """A generator seeded from the test's id: the same draws on every run of that test,
    different draws in different tests."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode("utf-8")))


def _column(key: str) -> int:
    """``"open_jaw"`` or ``"f3"`` (FAP 3) -> 0-based column."""
    if key[:1] == "f" and key[1:].isdigit():
        return fap(int(key[1:])).index
    return fap(key).index


def build_frame(**values: float) -> np.ndarray:
    """``(84,) float32`` FAP values, zero but for the FAPs named (``open_jaw=300``) or
    numbered (``f3=300``)."""
    out = np.zeros(N_FAPS, np.float32)
    for key, value in values.items():
        out[_column(key)] = value
    return out


def build_stream(n_frames: int, *, fps: float = 25.0, **columns: object) -> FapStream:
    """A FapStream of ``n_frames`` with the named FAPs set to a value or an ``(n_frames,)``
    array each (FAPs 3-68 masked in, as FapStream's default)."""
    values = np.zeros((n_frames, N_FAPS), np.float32)
    for key, column in columns.items():
        values[:, _column(key)] = np.asarray(column, dtype=np.float32)
    return FapStream(fps, values)


@pytest.fixture
def fap_frame() -> FapFrame:
    """The :func:`build_frame` builder."""
    return build_frame


@pytest.fixture
def fap_stream() -> FapStreamBuilder:
    """The :func:`build_stream` builder."""
    return build_stream


@pytest.fixture(scope="session")
def default_face():  # -> facelib.engine.Face
    """The default head, loaded once per session."""
    from facelib.engine import load_face

    return load_face()


@pytest.fixture
def storyboard_source(tmp_path: Path) -> Callable[[str], object]:
    """``make(body)``: an animation-like source (``faps``: one frame of zeros,
    ``storyboard``: the file ``tmp_path/story.fdl`` holding ``body``, loaded)."""
    from facelib.fdl import load

    def make(body: str) -> object:
        path = tmp_path / "story.fdl"
        path.write_text(body)

        class Source:
            faps = FapStream(25, np.zeros((1, N_FAPS), np.float32))
            storyboard = load(path)

        return Source()

    return make
