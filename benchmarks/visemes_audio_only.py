"""Visemes from audio with and without the transcript, against Festival's exact phones.

Synthesises Harvard sentences with Festival (``festival`` + ``festvox-us-slt-hts``; lists
3-4 and 5-6 of ``visemes_align_accuracy.py``, held out from every setting; ``--tuning``
adds lists 1-2, the set the recognition settings were chosen on) and turns each into
visemes by every path:

- ``forced``: audio + transcript (``facelib.visemes.align(wav, text)``);
- ``phone loop``: audio alone, pocketsphinx's phone loop (``recognize(method="phones")``);
- ``two-pass pocketsphinx``: audio alone, pocketsphinx's word decoder with the language
  model its wheel ships, then forced alignment of that transcript
  (``recognize(method="auto", decoder="pocketsphinx")``: the phone loop where the words
  cannot be aligned);
- ``two-pass whisper:NAME``: the same with Whisper (faster-whisper and a model package, the
  ``asr`` extra) as pass 1, for each installed model of ``recognition.json``
  (``decoder="whisper:NAME"``);
- ``acoustic``: audio alone, the acoustic viseme model (``recognize(method="acoustic")``,
  any language; ``benchmarks/visemes_acoustic.py`` measures it further);
- ``default``: ``facelib.visemes_from_audio(wav)``, two-pass with the first installed
  decoder and the phone-loop fallback.

Both the truth and each path go through the same phone -> viseme chain
(``visemes_for``: the map, short silences merged, minimum durations). Printed per path:

- viseme class right per 10 ms: the share of 10 ms frames (centres at 5, 15, ... ms over
  the whole recording, silence included) whose viseme id equals the truth's;
- p/b/m closures found: truth bilabial viseme spans that a bilabial span of the path
  overlaps (within ``TOLERANCE_MS``), of all truth bilabial spans;
- false closures: bilabial spans of the path that overlap no truth bilabial span (within
  the same tolerance);
- for each two-pass path: the word error rate of pass 1 and the mean confidence of the
  words it got right and wrong; the real-time factor of each path on this machine (Whisper
  loads once per process; pocketsphinx makes its decoders afresh on every call).

``--conditions=clean,noise,telephone`` (default clean) also degrades the audio as
``visemes_acoustic.py`` does (white noise at 10 dB SNR; 300-3400 Hz at 8 kHz);
``--paths=forced,two-pass whisper:base,...`` measures only the named paths. A path that
raises SpeechError on a sentence (the aligner finds no path through noisy audio) scores it
as silence throughout and is counted under "sentences failed".

    OMP_NUM_THREADS=1 PYTHONPATH=. .venv/bin/python benchmarks/visemes_audio_only.py \\
        [--tuning] [--held-out] [--conditions=...] [--paths=...] [N]
"""

from __future__ import annotations

import difflib
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from visemes_align_accuracy import HELD_OUT, HELD_OUT_2, SENTENCES
from visemes_festival import synthesize

import facelib
from facelib.errors import SpeechError
from facelib.speech import Span
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.pronounce import tokenize
from facelib.speech.recognize import decode_words, recognize
from facelib.speech.timeline import cover
from facelib.speech.whisper import installed_models
from facelib.visemes import align, visemes_for, with_visemes
from facelib.visemes.timeline import SpeechTimeline, VisemeSpan

TOLERANCE_MS = 20
R = ALIGN_RATE
Path_ = Callable[[np.ndarray, str], SpeechTimeline]


def _two_pass(decoder: str) -> Path_:
    return lambda x, _: with_visemes(recognize(x, sample_rate=R, method="auto",
                                               decoder=decoder))


PATHS: dict[str, Path_] = {
    "forced": lambda x, text: align(x, text, sample_rate=R),
    "phone loop": lambda x, _: with_visemes(recognize(x, sample_rate=R, method="phones")),
    "two-pass pocketsphinx": _two_pass("pocketsphinx"),
    **{f"two-pass whisper:{m}": _two_pass(f"whisper:{m}") for m in installed_models()},
    "acoustic": lambda x, _: with_visemes(recognize(x, sample_rate=R, method="acoustic")),
    "default": lambda x, _: facelib.visemes_from_audio(x, sample_rate=R).speech,
}


def truth_visemes(phones: Sequence[tuple[str, float, float]]) -> tuple[VisemeSpan, ...]:
    spans = [Span(label, round(1000 * a), round(1000 * b)) for label, a, b in phones]
    return visemes_for(cover(spans, spans[-1].end_ms))


def frame_ids(visemes: Sequence[VisemeSpan], n: int) -> np.ndarray:
    """``(n,) int``: the viseme id at 5, 15, 25, ... ms (0 outside every span)."""
    t = np.arange(n) * 10 + 5
    out = np.zeros(n, int)
    for v in visemes:
        out[(t >= v.start_ms) & (t < v.end_ms)] = v.viseme
    return out


def closures(truth: Sequence[VisemeSpan], got: Sequence[VisemeSpan]) -> tuple[int, int, int]:
    """(truth closures found, truth closures, false closures)."""
    a = [(v.start_ms - TOLERANCE_MS, v.end_ms + TOLERANCE_MS) for v in truth if v.is_bilabial]
    b = [(v.start_ms, v.end_ms) for v in got if v.is_bilabial]

    def hit(x: tuple[int, int], ys: list[tuple[int, int]]) -> bool:
        return any(x[0] < y[1] and y[0] < x[1] for y in ys)

    return sum(hit(x, b) for x in a), len(a), sum(not hit(y, a) for y in b)


def word_errors(text: str, x: np.ndarray, decoder: str
                ) -> tuple[int, int, list[float], list[float]]:
    """(errors, reference words, confidences of right words, of wrong ones) of pass 1."""
    ref = [t for t in tokenize(text) if t[0].isalpha()]
    hyp = [(t, c) for w, c in decode_words(x, decoder=decoder)
           for t in tokenize(w) if t[0].isalpha()]
    matcher = difflib.SequenceMatcher(a=ref, b=[w for w, _ in hyp], autojunk=False)
    right = {b.b + i for b in matcher.get_matching_blocks() for i in range(b.size)}
    errors = max(len(ref), len(hyp)) - len(right)
    return (errors, len(ref), [c for i, (_, c) in enumerate(hyp) if i in right],
            [c for i, (_, c) in enumerate(hyp) if i not in right])


def measure(sentences: Sequence[str], tmp: Path, paths: Sequence[str],
            degrade: Callable[[np.ndarray], np.ndarray]) -> None:
    right = dict.fromkeys(paths, 0)
    found = dict.fromkeys(paths, 0)
    false = dict.fromkeys(paths, 0)
    seconds = dict.fromkeys(paths, 0.0)
    failed = dict.fromkeys(paths, 0)
    decoders = [p.removeprefix("two-pass ") for p in paths if p.startswith("two-pass ")]
    wer = {d: [0, 0, [], []] for d in decoders}
    frames = n_closures = 0
    audio_s = 0.0
    for k, text in enumerate(sentences):
        wav = tmp / f"s{k}.wav"
        truth = truth_visemes(synthesize(text, wav))
        x = degrade(load_speech(wav))
        n = truth[-1].end_ms // 10
        frames += n
        audio_s += truth[-1].end_ms / 1000
        ids = frame_ids(truth, n)
        for name in paths:
            t0 = time.perf_counter()
            try:
                visemes = PATHS[name](x, text).visemes
            except SpeechError:  # scored as silence throughout
                visemes, failed[name] = (), failed[name] + 1
            seconds[name] += time.perf_counter() - t0
            right[name] += int(np.sum(frame_ids(visemes, n) == ids))
            hit, total, bad = closures(truth, visemes)
            found[name] += hit
            false[name] += bad
        n_closures += total
        for d in decoders:
            for i, v in enumerate(word_errors(text, x, d)):
                wer[d][i] += v
    print(f"  sentences {len(sentences)}, audio {audio_s:.1f} s, frames {frames}, "
          f"p/b/m closures {n_closures}")
    print("  | path | viseme class right per 10 ms | p/b/m closures found | false closures "
          "| real-time factor | sentences failed |")
    for name in paths:
        print(f"  | {name} | {100 * right[name] / frames:.1f} % | {found[name]}/{n_closures} "
              f"| {false[name]} | {seconds[name] / audio_s:.2f} | {failed[name]} |")
    for d, (errors, n_words, sure, unsure) in wer.items():
        print(f"  {d}: pass 1 word error rate {100 * errors / n_words:.1f} % "
              f"({errors} of {n_words}); mean confidence of right words {np.mean(sure):.2f} "
              f"(n={len(sure)}), of wrong ones "
              f"{np.mean(unsure) if unsure else float('nan'):.2f} (n={len(unsure)})")


def main() -> None:
    from visemes_acoustic import noisy, telephone

    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    opts = dict(a[2:].split("=", 1) if "=" in a else (a[2:], "1")
                for a in sys.argv[1:] if a.startswith("--"))
    n = int(args[0]) if args else 20
    conditions = {"clean": lambda x: x, "noise": noisy, "telephone": telephone}
    chosen = opts.get("conditions", "clean").split(",")
    paths = opts["paths"].split(",") if "paths" in opts else list(PATHS)
    unknown = [p for p in paths if p not in PATHS] + [c for c in chosen if c not in conditions]
    if unknown:
        raise SystemExit(f"unknown paths or conditions: {unknown}; paths: {list(PATHS)}")
    sets = {"held-out (lists 3-4)": HELD_OUT, "held-out (lists 5-6)": HELD_OUT_2}
    if "tuning" in opts:
        sets = {"tuning (lists 1-2)": SENTENCES, **(sets if "held-out" in opts else {})}
    with tempfile.TemporaryDirectory() as tmp:
        for cond in chosen:
            for name, sentences in sets.items():
                print(f"{name}, {cond}", flush=True)
                measure(sentences[:n], Path(tmp), paths, conditions[cond])


if __name__ == "__main__":
    main()
