# ruff: noqa: RUF001 (Turkish sentences)
"""The acoustic viseme model (``facelib.speech.acoustic``) against exact phone times.

Three sets, each clean, with white noise at 10 dB SNR (speech power: samples above 1 % of
the peak) and through a telephone channel (300-3400 Hz band-pass, 8 kHz):

- Festival (``festival`` + ``festvox-us-slt-hts``, a voice the model never heard):
  Harvard lists 3-4 and 5-6 of ``visemes_align_accuracy.py`` (``--tuning``: lists 1-2, the
  set the switch penalty was chosen on); ``--compare`` adds the two-pass path
  (``recognize(method="words")``) under each condition;
- held-out espeak-ng languages (Italian, Portuguese, Dutch, Polish, Turkish: never in
  training) spoken by voice variants never in training (``HELD_OUT_VARIANTS`` of
  ``tools/train_viseme_model.py``), six sentences each written for this benchmark;
- speed: x real time of one minute of speech on this machine (one thread: run with
  ``OMP_NUM_THREADS=1``).

Scores as ``visemes_audio_only.py``: viseme class right per 10 ms (the truth and the model's
runs both through ``visemes_for``), p/b/m closures found and false.

    OMP_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/visemes_acoustic.py \\
        [--tuning] [--compare] [--model PATH] [--penalty P] [N]
"""

from __future__ import annotations

import dataclasses
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from visemes_align_accuracy import HELD_OUT, HELD_OUT_2, SENTENCES
from visemes_audio_only import closures, frame_ids, truth_visemes
from visemes_festival import synthesize as festival

from facelib.speech.acoustic import AcousticModel, frame_classes, load_model, recognize_acoustic
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.recognize import recognize
from facelib.speech.synth import synthesize
from facelib.visemes import visemes_for, with_visemes
from facelib.visemes.timeline import VisemeSpan

HELD_OUT_SENTENCES = {
    "it": ["Il mio babbo porta il pane a casa ogni mattina.",
           "Mamma mia, quanto piove oggi a Milano!",
           "Abbiamo comprato una bella bicicletta blu.",
           "Il bambino gioca nel parco con il suo cane.",
           "Domani partiamo presto per le montagne.",
           "Per favore, passami il sale e il pepe."],
    "pt": ["O meu pai bebe café com leite pela manhã.",
           "A menina brinca com a bola no jardim.",
           "Amanhã vamos passear de barco no rio.",
           "Ele comprou um livro bonito para a mãe.",
           "Por favor, abre a porta da sala.",
           "O tempo está bom para ir à praia."],
    "nl": ["Mijn moeder bakt elke morgen vers brood.",
           "De baby speelt met een blauwe bal.",
           "Morgen gaan we met de boot naar Amsterdam.",
           "Het meisje pakt haar boek uit de tas.",
           "Wil je mij even de melk geven?",
           "In de winter is het buiten koud en nat."],
    "pl": ["Moja mama piecze pyszny chleb w piątek.",
           "Mały brat bawi się piłką w parku.",
           "Jutro pojedziemy pociągiem do Krakowa.",
           "Proszę, podaj mi mleko i masło.",
           "Pies biegnie szybko po mokrej trawie.",
           "W zimie często pada śnieg w górach."],
    "tr": ["Babam her sabah ekmek ve peynir yer.",
           "Bu bahar parkta mavi bir balon gördüm.",
           "Yarın annemle birlikte pazara gideceğiz.",
           "Lütfen bana biraz su verir misin?",
           "Kedi bahçede güneşin altında uyuyor.",
           "Kış aylarında dağlarda bol kar yağar."],
}
VARIANTS = ("", "+m2", "+f2", "+klatt3", "+m7")
RATES = (0.9, 1.0, 1.15)


def noisy(x: np.ndarray, snr_db: float = 10.0, seed: int = 0) -> np.ndarray:
    """``x`` (16 kHz) plus seeded white noise at ``snr_db`` below the speech's power."""
    speech = x[np.abs(x) > 0.01 * np.abs(x).max()]
    noise = np.random.default_rng(seed).normal(0, 1, x.size)
    noise *= np.sqrt(np.mean(speech.astype(np.float64) ** 2) / 10 ** (snr_db / 10))
    return np.clip(x + noise, -1, 1).astype(np.float32)


def telephone(x: np.ndarray) -> np.ndarray:
    """``x`` (16 kHz) through 300-3400 Hz and an 8 kHz channel."""
    from scipy.signal import butter, resample_poly, sosfilt

    y = sosfilt(butter(4, (300, 3400), btype="bandpass", fs=ALIGN_RATE, output="sos"), x)
    return resample_poly(resample_poly(y, 1, 2), 2, 1)[:x.size].astype(np.float32)


CONDITIONS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "clean": lambda x: x, "noise 10 dB": noisy, "telephone": telephone}


class Score:
    def __init__(self) -> None:
        self.right = self.frames = self.found = self.total = self.false = 0

    def add(self, truth: tuple[VisemeSpan, ...], got: tuple[VisemeSpan, ...]) -> None:
        n = truth[-1].end_ms // 10
        self.frames += n
        self.right += int(np.sum(frame_ids(got, n) == frame_ids(truth, n)))
        hit, total, bad = closures(truth, got)
        self.found, self.total, self.false = (self.found + hit, self.total + total,
                                              self.false + bad)

    def row(self) -> str:
        return (f"{100 * self.right / max(self.frames, 1):.1f} % | {self.found}/{self.total} "
                f"| {self.false}")


def acoustic_visemes(x: np.ndarray, model: AcousticModel) -> tuple[VisemeSpan, ...]:
    return with_visemes(recognize_acoustic(x, sample_rate=ALIGN_RATE, model=model)).visemes


def festival_set(name: str, sentences: list[str], model: AcousticModel, compare: bool,
                 tmp: Path) -> None:
    print(f"Festival, {name}: {len(sentences)} sentences")
    paths = ["acoustic", *(["two-pass"] if compare else [])]
    scores = {(p, c): Score() for p in paths for c in CONDITIONS}
    for k, text in enumerate(sentences):
        wav = tmp / f"f{k}.wav"
        truth = truth_visemes(festival(text, wav))
        x = load_speech(wav)
        for cond, degrade in CONDITIONS.items():
            y = degrade(x)
            scores["acoustic", cond].add(truth, acoustic_visemes(y, model))
            if compare:
                got = with_visemes(recognize(y, sample_rate=ALIGN_RATE, method="words"))
                scores["two-pass", cond].add(truth, got.visemes)
    print("  | path | condition | viseme class right per 10 ms | p/b/m closures found "
          "| false closures |")
    for (path, cond), s in scores.items():
        print(f"  | {path} | {cond} | {s.row()} |")


def languages_set(model: AcousticModel) -> None:
    print("held-out espeak-ng languages and voice variants")
    print("  | language | clean | noise 10 dB | telephone | closures found (clean) "
          "| false |")
    total = {c: Score() for c in CONDITIONS}
    for lang, sentences in HELD_OUT_SENTENCES.items():
        scores = {c: Score() for c in CONDITIONS}
        for k, text in enumerate(sentences):
            made = synthesize(text, lang=lang, voice=lang + VARIANTS[k % len(VARIANTS)],
                              rate=RATES[k % len(RATES)])
            truth = visemes_for(made.timeline.phones, alphabet="ipa")
            x = load_speech(np.asarray(made.samples), sample_rate=made.sample_rate)
            for cond, degrade in CONDITIONS.items():
                got = acoustic_visemes(degrade(x), model)
                scores[cond].add(truth, got)
                total[cond].add(truth, got)
        c = scores["clean"]
        print(f"  | {lang} | " + " | ".join(f"{100 * s.right / s.frames:.1f} %"
                                              for s in scores.values())
              + f" | {c.found}/{c.total} | {c.false} |")
    print("  | all | " + " | ".join(f"{100 * s.right / s.frames:.1f} %" for s in total.values())
          + f" | {total['clean'].found}/{total['clean'].total} | {total['clean'].false} |")


def speed(model: AcousticModel) -> None:
    made = synthesize(" ".join(HELD_OUT_SENTENCES["it"] * 2), lang="it")
    x = load_speech(np.asarray(made.samples), sample_rate=made.sample_rate)
    x = np.tile(x, -(-60 * ALIGN_RATE // x.size))[:60 * ALIGN_RATE]
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        frame_classes(x, model)
        best = min(best, time.perf_counter() - t0)
    print(f"speed: {60 / best:.0f}x real time (60 s of audio in {best:.2f} s, best of 3); "
          f"look-ahead {model.look_ahead_ms:.1f} ms")


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    opts = dict(a[2:].split("=", 1) if "=" in a else (a[2:], "1")
                for a in sys.argv[1:] if a.startswith("--"))
    n = int(args[0]) if args else 20
    model = load_model(opts.get("model"))
    if "penalty" in opts:
        model = dataclasses.replace(model, switch_penalty=float(opts["penalty"]))
    print(f"model: {model.info}")
    sets = {"held-out (lists 3-4)": HELD_OUT, "held-out (lists 5-6)": HELD_OUT_2}
    if "tuning" in opts:
        sets = {"tuning (lists 1-2)": SENTENCES}
    with tempfile.TemporaryDirectory() as tmp:
        for name, sentences in sets.items():
            festival_set(name, sentences[:n], model, "compare" in opts, Path(tmp))
    if "tuning" not in opts:
        languages_set(model)
        speed(model)


if __name__ == "__main__":
    main()
