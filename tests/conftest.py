"""Fixtures shared by the whole suite."""

from __future__ import annotations

import resource
from collections.abc import Iterator
from pathlib import Path

import pytest

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
