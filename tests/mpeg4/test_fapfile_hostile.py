"""``.fap`` files from anywhere: the reader never lets a file size its allocation, never
leaks a built-in exception, and the writer never emits values the format cannot hold."""

from __future__ import annotations

import os
import random
import warnings

import numpy as np
import pytest

from facelib.errors import FacelibWarning, FapFormatError, ParameterError
from facelib.mpeg4 import FapStream, read_fap, write_fap

pytestmark = pytest.mark.usefixtures("memory_cap")

MASK = " ".join(["0", "0", "1"] + ["0"] * 65)


@pytest.mark.parametrize(("text", "message"), [
    ("2.1 n 25 2000000\n" + MASK + "\n0 5\n", "cannot describe more than 32"),
    ("2.1 n 25 1000000000000\n", "cannot describe more than 16"),
    ("2.1 n 25 \u00b2\n", "bad frame count"),
    ("2.1 n 25 1\n" + MASK + "\n\u00b2 5\n", "frame number"),
    ("2.1 n 25 1\n" + MASK + "\n0 \u0661\n", "is not a number"),
    ("2.1 n 25 1\n" + MASK.replace("0", "1", 1) + "\n0 40000 0 0 0 5\n", "field select1 is 40000"),
    ("2.1 n 25 1\n" + MASK + "\n0 1e30\n", "outside the format's range"),
    ("2.1 n 1e308 1\n" + MASK + "\n0 1\n", "bad frame rate"),
    ("2.1 n 25 1\n" + MASK + "\n0 1\n" + MASK + "\n1 1\n" + MASK + "\n2 1\n", "more frames"),
])
def test_hostile_fap_files(tmp_path, text, message):
    path = tmp_path / "bad.fap"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FapFormatError, match=message):
        read_fap(path)


def test_special_files_are_refused(tmp_path):
    fifo = tmp_path / "pipe.fap"
    os.mkfifo(fifo)
    with pytest.raises(FapFormatError, match="not a regular file"):
        read_fap(fifo)
    with pytest.raises(FapFormatError, match="not a regular file"):
        read_fap(tmp_path)


def test_writer_refuses_values_the_format_cannot_hold(tmp_path):
    values = np.zeros((3, 84), np.float32)
    values[2, 4] = 1e30
    with pytest.raises(ParameterError, match="frame 2 FAP 5 is 1e"):
        write_fap(FapStream(25, values), tmp_path / "x.fap")
    assert not list(tmp_path.iterdir())


def test_stream_refuses_high_level_fields_out_of_range():
    viseme = np.zeros((2, 4), np.int32)
    viseme[1, 0] = 40000
    with pytest.raises(ParameterError, match="viseme field 0 of frame 1 is 40000"):
        FapStream(25, np.zeros((2, 84)), viseme=viseme)


def _mutate(text: str, rng: random.Random) -> str:
    chars = list(text)
    for _ in range(rng.randint(1, 8)):
        kind = rng.random()
        i = rng.randrange(len(chars))
        if kind < 0.3:
            chars[i] = rng.choice("0123456789 \n\t-+.eE#\u00b2\u0661x\r\0")
        elif kind < 0.5:
            del chars[i]
        elif kind < 0.7:
            chars.insert(i, rng.choice(["9" * rng.randint(1, 30), "\n", " ", "1e999", "-"]))
        else:
            j = rng.randrange(len(chars))
            chars[i:i] = chars[j : j + rng.randint(1, 200)]
    return "".join(chars)


@pytest.mark.slow
def test_fuzzed_fap_files_raise_only_fap_format_errors(tmp_path):
    """10,000 mutations of valid files: each reads or raises FapFormatError, nothing else."""
    rng = random.Random(21)
    values = np.zeros((6, 84), np.float32)
    values[:, 2:20] = np.arange(18) * 7
    seeds = []
    for dialect in ("standard", "xface", "greta", "extended"):
        viseme = np.tile([1, 2, 30, 1], (6, 1))
        stream = FapStream(25, values, viseme=viseme)
        seeds.append(write_fap(stream, tmp_path / f"{dialect}.fap", dialect=dialect).read_text())
    path = tmp_path / "fuzz.fap"
    outcomes = {"read": 0, "error": 0}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FacelibWarning)
        for _ in range(10_000):
            path.write_bytes(_mutate(rng.choice(seeds), rng).encode("utf-8", "surrogatepass"))
            try:
                read_fap(path)
                outcomes["read"] += 1
            except FapFormatError:
                outcomes["error"] += 1
    assert outcomes["read"] > 100
    assert outcomes["error"] > 1000
