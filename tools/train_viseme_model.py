# ruff: noqa: RUF001 (IPA symbols and letters of many alphabets)
"""Train the acoustic viseme model (``facelib/data/visemes/acoustic_model.npz``).

Training data is made here, seeded, with exact phone times: libespeak-ng (the ``speech``
extra) speaks texts in the training languages below, with voice variants, speaking rates and
pitches drawn per utterance; its PHONEME events give each phone's first sample, so every
10 ms frame has its viseme (the phones through ``facelib.visemes.visemes_for``, the chain
the benchmarks score against). Texts: English from random words of the CMU dictionary that
pocketsphinx ships; other languages from num2words (numbers, ordinals, years spelt out) and
pseudo-words (a letter-bigram model of those words, and random syllables of the letters they
use), read by espeak-ng's own rules for the language. A share of the English utterances
(``--flite-share``) is spoken by CMU Flite instead (Debian's ``flite``: its diphone voices
``kal``, ``kal16`` and its statistical voices ``awb``, ``rms``, built from recordings of
real speakers, so closer to natural speech than espeak-ng's formant synthesis), whose
``-psdur`` output gives each phone's end time; flite's ``slt`` is never used (the benchmarks'
Festival voice is that speaker). Festival's voices and the held-out languages and voice
variants (``HELD_OUT_*``, the benchmarks' language test) are never used.

Each utterance is then degraded at random (seeded): level (-35 to +3 dB, clipped), noise
(white, pink, brown, babble of other utterances; 0-30 dB SNR), reverberation (decaying noise
impulse responses, RT60 0.15-0.8 s), band limits (telephone 300-3400 Hz at 8 kHz, random
low- and high-pass) and 8-bit mu-law coding. Features are those of
:func:`facelib.speech.acoustic.log_mel`; the model is scikit-learn's ``MLPClassifier``
(a training-only dependency; librosa, in the ``speech`` extra, already pulls it in) over the
spectra of frames ``t + OFFSETS``; its weights are stored for numpy inference.

    OMP_NUM_THREADS=1 nice -n 10 PYTHONPATH=. .venv/bin/python tools/train_viseme_model.py \\
        [--utterances N] [--epochs E] [--flite-share F] [--work DIR] [--out PATH] [--seed S]
        [--cmn 0|1]

Time: with 6000 utterances (about 10 hours of audio) the data take 5-9 minutes and each
epoch 2-12 minutes on one thread of this shared 2-core machine (the more so the higher its
load). The shipped model is the last checkpoint of ``--utterances 9000 --epochs 6
--flite-share 0.35`` (14.7 hours of audio): data 8 minutes, 25 minutes in all.

Stages are cached in ``--work`` (synthesized data per batch); rerunning with the same
arguments gives the same model bit for bit on the same machine and library versions. After
every epoch the model is written to ``--out`` and kept as ``WORK/epochN.npz``; the shipped
model is the checkpoint chosen on Festival's tuning sentences (see its NOTICE).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from facelib.errors import FacelibError  # noqa: E402
from facelib.speech.acoustic import (  # noqa: E402
    HOP,
    AcousticModel,
    LevelState,
    causal_normalize,
    log_mel,
    model_from_arrays,
)
from facelib.speech.audio import ALIGN_RATE, load_speech  # noqa: E402
from facelib.speech.espeak import synth_fresh  # noqa: E402
from facelib.speech.synth import events_to_timeline  # noqa: E402
from facelib.speech.timeline import Span  # noqa: E402
from facelib.visemes.mapping import visemes_for  # noqa: E402

# espeak-ng voice -> num2words language (None: English, from the CMU dictionary)
TRAIN_VOICES = {
    "en-us": None, "en": None, "en-029": None, "en-us-nyc": None,
    "es": "es", "es-419": "es", "fr": "fr", "fr-be": "fr", "de": "de", "cs": "cs", "sk": "sk",
    "sl": "sl", "hu": "hu", "fi": "fi", "ro": "ro", "sv": "sv", "nb": "no",
    "id": "id", "lt": "lt", "lv": "lv", "ca": "ca", "ru": "ru", "uk": "uk",
    "eo": "eo", "az": "az", "cy": "cy", "be": "be",
}
TRAIN_VARIANTS = ("", "+m1", "+m3", "+m4", "+m5", "+m6", "+f1", "+f3", "+f4", "+f5",
                  "+klatt", "+klatt2", "+klatt4", "+croak", "+Andy", "+belinda")
FLITE_VOICES = ("kal", "kal16", "awb", "rms")
"""CMU Flite's voices used (never ``slt``: the benchmarks' Festival voice is its speaker)."""
FLITE_TO_ARPABET = {
    "ax": "AH", "axr": "ER", "dx": "T", "el": "L", "em": "M", "en": "N", "hv": "HH",
    "nx": "N", "pau": "SIL", "h#": "SIL", "brth": "SIL",
}
"""Flite's US phone set (Festival's "radio" set) -> ARPAbet (pocketsphinx en-us)."""
HELD_OUT_VOICES = {"it": "it", "pt": "pt", "nl": "nl", "pl": "pl", "tr": "tr"}
HELD_OUT_VARIANTS = ("", "+m2", "+f2", "+klatt3", "+m7")
OFFSETS = (-20, -16, -12, -9, -7, -5, -4, -3, -2, -1, 0, 1, 2, 3, 4, 5, 6)
N_MELS, N_FFT = 40, 400
LAG = 2
REPRESENTATIVE = ("SIL", "m", "f", "θ", "t", "k", "ʃ", "s", "n", "r", "ɑ", "e", "ɪ", "ɒ", "ʊ")
"""The IPA phone each class (viseme id) is shown as (each maps back to its own viseme)."""
BATCH = 100


def vocabulary(lang: str | None, rng: np.random.Generator) -> list[str]:
    """Real words of ``lang``: CMU dictionary words (English) or number words (num2words)."""
    if lang is None:
        import pocketsphinx

        path = Path(pocketsphinx.__file__).parent / "model" / "en-us" / "cmudict-en-us.dict"
        words = sorted({line.split()[0].split("(")[0] for line in
                        path.read_text(encoding="utf-8").splitlines() if line.strip()})
        return [w for w in words if w.isalpha() and len(w) > 1]
    from num2words import num2words

    words: set[str] = set()
    numbers = [*range(120), *rng.integers(100, 10**6, 300).tolist()]
    for n in numbers:
        for kind in ("cardinal", "ordinal", "year"):
            try:
                said = num2words(int(n), lang=lang, to=kind)
            except (NotImplementedError, ValueError, TypeError, AttributeError, KeyError,
                    OverflowError, IndexError):
                continue
            words.update(w for w in said.replace("-", " ").replace(",", " ").split()
                         if w.isalpha())
    return sorted(words)


def pseudo_word(words: list[str], rng: np.random.Generator) -> str:
    """A letter-bigram walk over ``words`` (3-9 letters), or random syllables of their
    letters."""
    letters = sorted({c for w in words for c in w.lower()})
    vowels = [c for c in letters
              if c in "aeiouyàáâãäåæèéêëìíîïòóôõöøùúûüýąęėįųůőűăâîəıаеёиоуыэюяєії"]
    consonants = [c for c in letters if c not in vowels] or letters
    vowels = vowels or letters
    if rng.random() < 0.5:
        out = [consonants[rng.integers(len(consonants))] if rng.random() < 0.8 else ""]
        for _ in range(rng.integers(1, 4)):
            out.append(vowels[rng.integers(len(vowels))])
            if rng.random() < 0.7:
                out.append(consonants[rng.integers(len(consonants))])
        return "".join(out)
    word = words[rng.integers(len(words))].lower()
    out = [word[0]]
    length = int(rng.integers(3, 10))
    pairs: dict[str, list[str]] = {}
    for w in rng.choice(words, size=min(len(words), 200), replace=False):
        for a, b in zip(w.lower(), w.lower()[1:], strict=False):
            pairs.setdefault(a, []).append(b)
    while len(out) < length and out[-1] in pairs:
        nxt = pairs[out[-1]]
        out.append(nxt[rng.integers(len(nxt))])
    return "".join(out)


def make_text(words: list[str], english: bool, rng: np.random.Generator) -> str:
    """An utterance of 5-14 words with commas and full stops (pauses) between some."""
    n = int(rng.integers(5, 15))
    out = []
    for k in range(n):
        if english or rng.random() < 0.45:
            w = words[rng.integers(len(words))]
        else:
            w = pseudo_word(words, rng)
        out.append(w)
        if k < n - 1 and rng.random() < 0.12:
            out[-1] += "," if rng.random() < 0.6 else "."
    return " ".join(out) + "."


def requests(voices: dict[str, str | None], variants: tuple[str, ...], n: int, seed: int,
             *, flite_share: float = 0.0) -> list[tuple[str, str, int, int]]:
    """``n`` seeded ``(text, voice, words_per_minute, pitch)`` synthesis requests; a share
    ``flite_share`` of them English text for a Flite voice (``"flite:NAME"``)."""
    rng = np.random.default_rng([seed, 1])
    vocab = {v: vocabulary(lang, np.random.default_rng([seed, 2, i]))
             for i, (v, lang) in enumerate(sorted(voices.items()))}
    names = sorted(voices)
    out = []
    for _ in range(n):
        voice = names[rng.integers(len(names))]
        variant = variants[rng.integers(len(variants))]
        text = make_text(vocab[voice], voices[voice] is None, rng)
        spoken_by = voice + variant
        if flite_share and rng.random() < flite_share:
            text = make_text(vocab["en-us"], english=True, rng=rng)
            spoken_by = "flite:" + FLITE_VOICES[rng.integers(len(FLITE_VOICES))]
        out.append((text, spoken_by, int(rng.integers(120, 271)), int(rng.integers(20, 81))))
    return out


def flite_speak(text: str, voice: str, words_per_minute: int, pitch: int
                ) -> tuple[np.ndarray, list[Span]]:
    """``text`` spoken by Flite's ``voice``: ``(16 kHz samples, ARPAbet phones)``, the
    rate (``duration_stretch``) and mean pitch (``int_f0_target_mean``, 20-80 -> 85-205 Hz)
    as asked. FacelibError when flite is missing or fails."""
    import shutil
    import subprocess
    import tempfile

    import soundfile

    if shutil.which("flite") is None:
        raise FacelibError("flite is missing (apt-get install flite), or use --flite-share 0")
    with tempfile.TemporaryDirectory() as tmp:
        wav = Path(tmp, "out.wav")
        done = subprocess.run(
            ["flite", "-voice", voice, "--setf", f"duration_stretch={175 / words_per_minute:.3f}",
             "--setf", f"int_f0_target_mean={85 + 2 * pitch}", "-psdur", "-t", text,
             "-o", str(wav)], capture_output=True, text=True, check=False)
        if done.returncode != 0 or not wav.exists():
            raise FacelibError(f"flite failed on {text!r}: {done.stderr.strip()[-200:]}")
        samples, rate = soundfile.read(str(wav), dtype="float32")
    phones: list[Span] = []
    start = 0
    for item in done.stdout.split():
        label, _, end_s = item.rpartition(":")
        end = round(float(end_s) * 1000)
        label = FLITE_TO_ARPABET.get(label, label.upper())
        if phones and label == "SIL" and phones[-1].label == "SIL":
            phones[-1] = Span("SIL", phones[-1].start_ms, end)
        elif end > start:
            phones.append(Span(label, start, end))
        start = max(start, end)
    return load_speech(samples, sample_rate=rate), phones


def synthesize(batch: list[tuple[str, str, int, int]], rng: np.random.Generator
               ) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """Each request's ``(samples at 16 kHz, frame viseme ids)`` with 50-600 ms of silence
    added before and after (espeak-ng leaves almost none); None where it failed."""
    espoken = [r for r in batch if not r[1].startswith("flite:")]
    try:
        raws = iter(synth_fresh(espoken) if espoken else [])
    except FacelibError:
        if len(batch) == 1:
            return [None]
        return [r for b in batch for r in synthesize([b], rng)]
    out: list[tuple[np.ndarray, np.ndarray] | None] = []
    for text, voice, wpm, pitch in batch:
        try:
            if voice.startswith("flite:"):
                samples, phones = flite_speak(text, voice.removeprefix("flite:"), wpm, pitch)
                visemes = visemes_for(phones, alphabet="arpabet")
            else:
                raw = next(raws)
                timeline = events_to_timeline(raw.events, text, n_samples=raw.samples.size,
                                              sample_rate=raw.sample_rate)
                visemes = visemes_for(timeline.phones, alphabet="ipa")
                samples = load_speech(raw.samples.astype(np.float32) / 32768,
                                      sample_rate=raw.sample_rate)
        except FacelibError:
            out.append(None)
            continue
        before, after = (int(rng.integers(5, 61)) for _ in range(2))  # in 10 ms frames
        samples = np.concatenate([np.zeros(before * HOP, np.float32), samples,
                                  np.zeros(after * HOP, np.float32)])
        n = max(-(-(samples.size - HOP // 2) // HOP), 0)
        t = np.arange(n) * 10 + 5 - 10 * before
        ids = np.zeros(n, np.int8)
        for v in visemes:
            ids[(t >= v.start_ms) & (t < v.end_ms)] = v.viseme
        out.append((samples, ids))
    return out


def _biquad_filter(x: np.ndarray, kind: str, cutoff: float | tuple[float, float],
                   order: int = 4) -> np.ndarray:
    from scipy.signal import butter, sosfilt

    sos = butter(order, cutoff, btype=kind, fs=ALIGN_RATE, output="sos")
    return sosfilt(sos, x)


def degrade(x: np.ndarray, rng: np.random.Generator, others: list[np.ndarray]) -> np.ndarray:
    """``x`` (16 kHz) with a random chain of degradations (see the module docstring)."""
    from scipy.signal import fftconvolve, resample_poly

    y = x.astype(np.float64)
    if rng.random() < 0.3:  # reverberation
        rt60 = rng.uniform(0.15, 0.8)
        n = int(rt60 * ALIGN_RATE)
        ir = rng.normal(0, 1, n) * np.exp(-6.9 * np.arange(n) / n)
        ir[0] = 0
        ir /= np.sqrt(np.sum(ir**2))
        wet = fftconvolve(y, ir)[:y.size]
        mix = rng.uniform(0.2, 0.8)
        y = (1 - mix) * y + mix * wet * np.sqrt(np.mean(y**2) / max(np.mean(wet**2), 1e-12))
    if rng.random() < 0.5:  # noise
        kind = rng.integers(4)
        if kind == 3 and others:
            noise = np.zeros_like(y)
            for _ in range(3):
                o = others[rng.integers(len(others))]
                reps = -(-y.size // o.size)
                noise += np.roll(np.tile(o, reps)[:y.size], rng.integers(y.size))
        else:
            white = rng.normal(0, 1, y.size)
            if kind == 0:
                noise = white
            else:
                spec = np.fft.rfft(white)
                f = np.maximum(np.fft.rfftfreq(y.size, 1 / ALIGN_RATE), 20.0)
                spec /= f ** (0.5 if kind == 1 else 1.0)
                noise = np.fft.irfft(spec, y.size)
        snr = rng.uniform(0, 30)
        speech_power = np.mean(y[np.abs(y) > 0.01 * np.abs(y).max()] ** 2)
        y = y + noise * np.sqrt(speech_power / max(np.mean(noise**2), 1e-12) / 10 ** (snr / 10))
    band = rng.random()
    if band < 0.2:  # telephone
        y = _biquad_filter(y, "bandpass", (300, 3400))
        y = resample_poly(resample_poly(y, 1, 2), 2, 1)[:x.size]
    elif band < 0.35:
        y = _biquad_filter(y, "lowpass", rng.uniform(2500, 7000))
    elif band < 0.45:
        y = _biquad_filter(y, "highpass", rng.uniform(100, 400), order=2)
    peak = max(np.abs(y).max(), 1e-9)
    y = y / peak * 10 ** (rng.uniform(-35, 3) / 20)
    y = np.clip(y, -1, 1)
    if rng.random() < 0.1:  # 8-bit mu-law
        mu = 255.0
        c = np.sign(y) * np.log1p(mu * np.abs(y)) / np.log1p(mu)
        c = np.round(c * 127) / 127
        y = np.sign(c) * np.expm1(np.abs(c) * np.log1p(mu)) / mu
    return y.astype(np.float32)


def front_end() -> dict[str, np.ndarray]:
    import librosa

    mel = librosa.filters.mel(sr=ALIGN_RATE, n_fft=N_FFT, n_mels=N_MELS, fmin=50, fmax=8000)
    return {"mel": mel.astype(np.float32), "n_fft": np.array(N_FFT),
            "mean": np.zeros(N_MELS, np.float32), "scale": np.ones(N_MELS, np.float32)}


def dataset(reqs: list[tuple[str, str, int, int]], work: Path, tag: str, seed: int,
            *, augment: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Features ``(n, n_mels)`` (unnormalised), labels ``(n,)`` and utterance starts of
    ``reqs``, cached per batch under ``work``."""
    model = _model({**front_end(), **_dummy_net()})
    feats, labels, starts = [], [], []
    total = 0
    for b in range(0, len(reqs), BATCH):
        cache = work / f"{tag}-{b // BATCH:04d}.npz"
        if not cache.exists():
            rng = np.random.default_rng([seed, 3, b])
            made = [m for m in synthesize(reqs[b:b + BATCH], rng) if m is not None]
            others = [s for s, _ in made]
            f_list, l_list = [], []
            for clean, ids in made:
                samples = clean
                if augment and rng.random() > 0.25:
                    samples = degrade(samples, rng, others)
                if augment and rng.random() < 0.6:  # a recording's noise floor
                    floor = rng.normal(0, 10 ** (rng.uniform(-80, -45) / 20), samples.size)
                    samples = np.clip(samples + floor.astype(np.float32), -1, 1)
                f = log_mel(samples, model)
                n = min(f.shape[0], ids.size)
                f_list.append(f[:n])
                l_list.append(ids[:n])
            lengths = np.array([x.shape[0] for x in f_list])
            np.savez(cache, f=np.concatenate(f_list), y=np.concatenate(l_list), n=lengths)
            print(f"  {tag} batch {b // BATCH}: {len(made)} utterances, "
                  f"{lengths.sum() / 100:.0f} s", flush=True)
        with np.load(cache) as stored:
            feats.append(stored["f"])
            labels.append(stored["y"])
            for n in stored["n"]:
                starts.append(total)
                total += int(n)
    return np.concatenate(feats), np.concatenate(labels).astype(np.int64), np.array(starts)


def _dummy_net() -> dict[str, np.ndarray]:
    return {"offsets": np.array(OFFSETS), "n_layers": np.array(1),
            "w0": np.zeros((N_MELS * len(OFFSETS), len(REPRESENTATIVE)), np.float32),
            "b0": np.zeros(len(REPRESENTATIVE), np.float32),
            "labels": np.array(REPRESENTATIVE), "lag": np.array(LAG),
            "switch_penalty": np.array(0.0), "info": np.array("{}")}


def _model(arrays: dict[str, np.ndarray]) -> AcousticModel:
    return model_from_arrays(arrays)


def stack(features: np.ndarray, starts: np.ndarray, rows: np.ndarray,
          pad: np.ndarray) -> np.ndarray:
    """``(len(rows), n_context * n_mels)`` inputs of frames ``rows`` (context within the
    frame's utterance, ``pad`` outside it)."""
    utt = np.searchsorted(starts, rows, side="right") - 1
    lo = starts[utt]
    hi = np.append(starts[1:], features.shape[0])[utt]
    out = []
    for o in OFFSETS:
        r = rows + o
        inside = (r >= lo) & (r < hi)
        block = np.tile(pad, (rows.size, 1))
        block[inside] = features[r[inside]]
        out.append(block)
    return np.concatenate(out, axis=1)


def warp_features(x: np.ndarray, starts: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Speaker and channel variety in feature space, per utterance (unnormalised log-mel
    ``x``): the mel axis stretched by a factor 0.85-1.15 (vocal tract length), a spectral
    tilt of up to +-1.5 (natural log) from the lowest to the highest band and a smooth random
    equaliser (three cosines, up to 0.4 each) on frames above the floor."""
    out = np.empty_like(x)
    bands = np.arange(x.shape[1], dtype=np.float64)
    top = x.shape[1] - 1
    floor = float(np.log(1e-8))
    ends = np.append(starts[1:], x.shape[0])
    for a, b in zip(starts, ends, strict=True):
        u = x[a:b]
        alpha = rng.uniform(0.85, 1.15)
        src = np.clip(bands * alpha, 0, top)
        lo = np.floor(src).astype(int)
        hi = np.minimum(lo + 1, top)
        w = (src - lo).astype(np.float32)
        u = u[:, lo] * (1 - w) + u[:, hi] * w
        eq = rng.uniform(-1.5, 1.5) * (bands / top - 0.5)
        for _ in range(3):
            eq += rng.uniform(-0.4, 0.4) * np.cos(np.pi * rng.uniform(0.5, 4) * bands / top
                                                  + rng.uniform(0, 2 * np.pi))
        voiced = u > floor + 3
        out[a:b] = np.where(voiced, np.maximum(u + eq.astype(np.float32), floor + 3), u)
    return out


def save(net: object, args: argparse.Namespace, *, mean: np.ndarray, scale: np.ndarray,
         init: np.ndarray | None, hidden: tuple[int, ...], hours: float, accuracy: float,
         epochs: int, seconds: float) -> None:
    """Write the model's ``.npz`` (front end, weights, how it was made)."""
    arrays = {**front_end(), "mean": mean, "scale": scale, **_dummy_net(),
              "n_layers": np.array(len(net.coefs_)),  # type: ignore[attr-defined]
              "switch_penalty": np.array(args.penalty)}
    if init is not None:
        arrays["level_init"] = init
    for k, (w, b) in enumerate(zip(net.coefs_, net.intercepts_,  # type: ignore[attr-defined]
                                   strict=True)):
        arrays[f"w{k}"] = w.astype(np.float32)
        arrays[f"b{k}"] = b.astype(np.float32)
    info = {
        "made_by": "tools/train_viseme_model.py", "seed": args.seed,
        "utterances": args.utterances, "epochs": epochs, "hidden": list(hidden),
        "train_hours": round(hours, 3), "train_voices": sorted(TRAIN_VOICES),
        "train_variants": list(TRAIN_VARIANTS), "held_out_voices": sorted(HELD_OUT_VOICES),
        "held_out_variants": list(HELD_OUT_VARIANTS), "offsets": list(OFFSETS),
        "n_mels": N_MELS, "n_fft": N_FFT, "lag": LAG, "feature_warp": bool(args.feature_warp),
        "level_normalisation": init is not None,
        "validation_frame_accuracy": round(accuracy, 4), "seconds": round(seconds),
        "synthesis": "libespeak-ng (espeakng-loader wheel) and, for a share "
                     f"{args.flite_share:g} of the utterances, CMU Flite's voices "
                     f"{', '.join(FLITE_VOICES)}; no Festival voice, no slt",
        "flite_share": args.flite_share,
    }
    arrays["info"] = np.array(json.dumps(info))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(args.out, **arrays)
    np.savez_compressed(args.work / f"epoch{epochs}.npz", **arrays)  # every checkpoint kept
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e6:.2f} MB)", flush=True)


def normalize_all(x: np.ndarray, starts: np.ndarray, init: np.ndarray | None) -> np.ndarray:
    """:func:`causal_normalize` of each utterance of ``x`` from the state ``init`` (or ``x``
    itself when ``init`` is None: no level normalisation)."""
    if init is None:
        return x
    out = np.empty_like(x)
    ends = np.append(starts[1:], x.shape[0])
    for a, b in zip(starts, ends, strict=True):
        out[a:b] = causal_normalize(x[a:b], LevelState(None, init))[0]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--utterances", type=int, default=6000)
    parser.add_argument("--epochs", type=int, default=12)
    parser.add_argument("--hidden", default="320,256")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--work", type=Path, default=Path("/tmp/facelib-viseme-train"))
    parser.add_argument("--out", type=Path,
                        default=ROOT / "facelib" / "data" / "visemes" / "acoustic_model.npz")
    parser.add_argument("--flite-share", type=float, default=0.35,
                        help="share of utterances spoken by CMU Flite's voices (English)")
    parser.add_argument("--penalty", type=float, default=4.0)
    parser.add_argument("--cmn", type=int, default=0,
                        help="1: causal level and channel normalisation of the features")
    parser.add_argument("--feature-warp", type=int, default=1,
                        help="1: warp the features of every epoch after the first")
    args = parser.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from sklearn.neural_network import MLPClassifier

    t0 = time.time()
    args.work.mkdir(parents=True, exist_ok=True)
    reqs = requests(TRAIN_VOICES, TRAIN_VARIANTS, args.utterances, args.seed,
                    flite_share=args.flite_share)
    x, y, starts = dataset(reqs, args.work,
                           f"train{args.seed}-{args.utterances}-f{args.flite_share:g}",
                           args.seed, augment=True)
    val_reqs = requests(TRAIN_VOICES, TRAIN_VARIANTS, max(args.utterances // 20, 40),
                        args.seed + 1, flite_share=args.flite_share)
    xv, yv, sv = dataset(val_reqs, args.work,
                         f"val{args.seed}-{args.utterances}-f{args.flite_share:g}",
                         args.seed + 1, augment=True)
    print(f"data: {x.shape[0] / 100 / 3600:.2f} h train, {xv.shape[0] / 100 / 60:.1f} min "
          f"validation, {time.time() - t0:.0f} s", flush=True)
    floor = np.log(np.full(N_MELS, 1e-8, np.float32))
    raw = x
    init = None
    if args.cmn:
        loud = x.mean(axis=1) > np.percentile(x.mean(axis=1), 50)
        init = x[loud].mean(axis=0).astype(np.float32)
        x = normalize_all(x, starts, init)
        xv = normalize_all(xv, sv, init)
        floor = floor - init
    mean = x.mean(axis=0).astype(np.float32)
    scale = x.std(axis=0).astype(np.float32) + 1e-3
    x = (x - mean) / scale
    xv = (xv - mean) / scale
    pad = ((floor - mean) / scale).astype(np.float32)
    hidden = tuple(int(h) for h in args.hidden.split(","))
    net = MLPClassifier(hidden_layer_sizes=hidden, activation="relu", solver="adam",
                        alpha=1e-4, batch_size=256, learning_rate_init=1e-3,
                        random_state=args.seed)
    rng = np.random.default_rng([args.seed, 4])
    classes = np.arange(len(REPRESENTATIVE))
    vrows = np.arange(xv.shape[0])
    xv_stacked = stack(xv, sv, vrows, pad)
    chunk = 50_000
    for epoch in range(args.epochs):
        if epoch == int(args.epochs * 0.75):
            net._optimizer.learning_rate_init = 3e-4  # adam's step, late epochs
        xe = ((normalize_all(warp_features(raw, starts, rng), starts, init) - mean)
              / scale).astype(np.float32) if args.feature_warp and epoch > 0 else x
        order = rng.permutation(x.shape[0])
        for k in range(0, order.size, chunk):
            rows = np.sort(order[k:k + chunk])
            net.partial_fit(stack(xe, starts, rows, pad), y[rows], classes=classes)
        acc = float(np.mean(net.predict(xv_stacked) == yv))
        print(f"epoch {epoch + 1}: validation frames right {100 * acc:.1f} % "
              f"({time.time() - t0:.0f} s)", flush=True)
        save(net, args, mean=mean, scale=scale, init=init, hidden=hidden,
             hours=x.shape[0] / 360000,
             accuracy=acc, epochs=epoch + 1, seconds=time.time() - t0)


if __name__ == "__main__":
    main()
