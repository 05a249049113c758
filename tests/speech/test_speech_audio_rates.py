"""Sample rates are checked where speech audio enters (load_speech), before any sample is
read or resampled: a header saying 1 Hz once sized an 11.9 GiB resampling filter in `run`
and `align`, and 2^31-1 Hz 320 GiB (issue 38, class 7)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from facelib.checks import check_sample_rate
from facelib.cli import main
from facelib.errors import ParameterError, SpeechError
from facelib.speech.audio import load_speech


def _wav(path: Path, rate: int, n: int = 4000) -> Path:
    """A 16-bit mono WAV of ``n`` samples of noise whose header says ``rate`` Hz."""
    body = (np.random.default_rng(0).normal(0, 3000, n)).astype("<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, 1, rate, (rate * 2) & 0xFFFFFFFF, 2, 16)
    riff = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack(
        "<I", len(body)) + body
    path.write_bytes(b"RIFF" + struct.pack("<I", len(riff)) + riff)
    return path


@pytest.mark.parametrize("rate", [1, 2**31 - 1, 3999, 384_001])
def test_a_header_rate_outside_the_range_is_refused_before_reading(tmp_path, rate):
    wav = _wav(tmp_path / "voice.wav", rate)
    with pytest.raises(SpeechError, match=rf"voice.wav has a sample rate of {rate} Hz"):
        load_speech(wav)


@pytest.mark.parametrize("rate", [0, -16000, 1, 10**9, 16000.5, True])
def test_an_array_rate_outside_the_range_is_refused(rate):
    with pytest.raises(SpeechError, match="sample_rate has a sample rate"):
        load_speech(np.ones(16000, np.float32) * 0.1, sample_rate=rate)


def test_rates_inside_the_range_pass():
    assert check_sample_rate(8000, source="x") == 8000
    assert check_sample_rate(np.int32(44100), source="x") == 44100
    with pytest.raises(ParameterError, match=r"x has a sample rate of 2\.5 Hz"):
        check_sample_rate(2.5, source="x")


@pytest.mark.parametrize("command", ["align", "run"])
def test_commands_refuse_a_1_hz_wav_without_a_traceback(tmp_path, capsys, command):
    wav = _wav(tmp_path / "voice.wav", 1)
    if command == "align":
        args = ["align", str(wav), "--text", "hello there", "-o", str(tmp_path / "out.json")]
    else:
        story = tmp_path / "story.fdl"
        story.write_text('say { "hello there", audio = "voice.wav" }\n')
        args = ["run", str(story), "-o", str(tmp_path / "out.fap")]
    assert main(args) != 0
    err = capsys.readouterr().err
    assert "sample rate of 1 Hz" in err and "Traceback" not in err
    assert not (tmp_path / "out.fap").exists() and not (tmp_path / "out.json").exists()
