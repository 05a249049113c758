"""The acoustic viseme model: the shipped file, numpy inference, causality and streaming,
and its place on every audio-only path (any language)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import soundfile

import facelib
from facelib import data
from facelib.cli import main
from facelib.speech.acoustic import (
    MODEL_FILE,
    AcousticStream,
    frame_classes,
    frame_log_probs,
    load_model,
    log_mel,
    network_input,
    recognize_acoustic,
    start_level,
)
from facelib.speech.audio import ALIGN_RATE
from facelib.speech.recognize import recognize
from facelib.visemes import visemes_for, with_visemes


def _babble(seconds: float, seed: int = 0) -> np.ndarray:
    """A speech-like test signal: noise bursts through moving resonances, with pauses."""
    rng = np.random.default_rng(seed)
    n = round(seconds * ALIGN_RATE)
    t = np.arange(n) / ALIGN_RATE
    carrier = np.sin(2 * np.pi * (120 + 30 * np.sin(2 * np.pi * 0.7 * t)) * t)
    x = carrier * (0.5 + 0.5 * np.sin(2 * np.pi * 3.1 * t)) + 0.05 * rng.normal(0, 1, n)
    x[(t % 1.3) > 1.0] *= 0.01
    return (0.3 * x).astype(np.float32)


def test_shipped_model_loads_and_is_small():
    path = data.path(MODEL_FILE)
    assert path.is_file() and len(path.read_bytes()) < 5_000_000
    model = load_model()
    info = json.loads(model.info)
    assert info["made_by"] == "tools/train_viseme_model.py"
    assert not set(info["train_voices"]) & set(info["held_out_voices"])
    assert model.n_classes == 15 and model.labels[0] == "SIL"
    assert model.look_ahead_ms <= 100
    # each class's phone is shown as that class's viseme
    spans = visemes_for([facelib.speech.Span(label, 100 * k, 100 * k + 100)
                         for k, label in enumerate(model.labels)], alphabet="ipa")
    assert [v.viseme for v in spans] == list(range(15))


def test_frame_probabilities_shape():
    model = load_model()
    x = _babble(1.0)
    raw = log_mel(x, model)
    assert raw.shape == (100, model.mean.size) and raw.dtype == np.float32
    feats, _ = network_input(raw, model, start_level(model))
    logp = frame_log_probs(feats, model)
    assert logp.shape == (100, 15)
    np.testing.assert_allclose(np.exp(logp).sum(axis=1), 1, rtol=1e-5)
    assert frame_classes(x, model).shape == (100,)


def test_changing_later_audio_leaves_earlier_frames_alone():
    """Frame t's class depends on no sample later than ``look_ahead_ms`` past its centre."""
    model = load_model()
    x = _babble(3.0, seed=1)
    y = x.copy()
    cut_ms = 1500
    y[cut_ms * ALIGN_RATE // 1000:] = _babble(1.5, seed=2)
    a, b = frame_classes(x, model), frame_classes(y, model)
    last_safe = int((cut_ms - model.look_ahead_ms - 5) // 10)  # centre + look-ahead < cut
    assert (a[:last_safe + 1] == b[:last_safe + 1]).all()
    assert (a != b).any()  # the later audio does matter


@pytest.mark.parametrize("chunk", [1, 77, 160, 1600, 12345])
def test_streaming_gives_the_whole_file_result(chunk):
    model = load_model()
    x = _babble(2.0, seed=3)
    stream = AcousticStream(model)
    decided = []
    for k in range(0, x.size, chunk):
        decided += stream.feed(x[k:k + chunk])
        # every frame decided so far is within the look-ahead of the samples fed
        heard_ms = 1000 * stream.n_samples / ALIGN_RATE
        assert 10 * len(decided) + 5 + model.look_ahead_ms >= heard_ms - 10
    decided += stream.finish()
    np.testing.assert_array_equal(decided, frame_classes(x, model))


@pytest.mark.speech
@pytest.mark.parametrize(("lang", "text"), [("en", "mama, papa"), ("it", "mamma e papà")])
def test_closures_of_mama_papa(lang, text):
    """Each p/b/m of a synthesized sentence is shown closed where the phone is."""
    made = facelib.speech.synthesize(text, lang=lang)
    truth = [v for v in visemes_for(made.timeline.phones, alphabet="ipa") if v.is_bilabial]
    heard = with_visemes(recognize_acoustic(np.asarray(made.samples),
                                            sample_rate=made.sample_rate))
    got = [v for v in heard.visemes if v.is_bilabial]
    assert heard.source == "acoustic"
    assert len(truth) == 4

    def overlaps(a, b):
        return a.start_ms - 20 < b.end_ms and b.start_ms < a.end_ms + 20

    assert sum(any(overlaps(t, g) for g in got) for t in truth) >= 3
    assert all(any(overlaps(g, t) for t in truth) for g in got)


@pytest.mark.speech
def test_align_without_text_in_another_language(tmp_path):
    made = facelib.speech.synthesize("Il bambino mangia la mela con la mamma.", lang="it",
                                     voice="it+m2")
    wav = tmp_path / "it.wav"
    soundfile.write(str(wav), np.asarray(made.samples), made.sample_rate)
    out = tmp_path / "it.json"
    assert main(["align", str(wav), "--lang", "it", "-o", str(out)]) == 0
    got = json.loads(out.read_text())
    assert got["source"] == "acoustic"
    visemes = {v["viseme"] for v in got["visemes"]}
    assert 1 in visemes and len(visemes) >= 6
    # --method chooses the path: acoustic for English too
    en = tmp_path / "en.json"
    assert main(["align", str(wav), "--method", "acoustic", "-o", str(en)]) == 0
    assert json.loads(en.read_text())["visemes"] == got["visemes"]
    assert recognize(wav, language="it").source == "acoustic"
    made_fdl = tmp_path / "it.fdl"
    made_fdl.write_text('fps = 25\nsay { audio = "it.wav", lang = "it" }\n')
    animation = facelib.run_fdl(made_fdl)
    assert any(v.is_bilabial for v in animation.visemes)
    track = facelib.visemes_from_audio(wav, language="it", fps=25)
    assert track.speech.source == "acoustic" and any(v.is_bilabial for v in track.timeline)
