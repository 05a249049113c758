"""Visemes from audio with and without the transcript, against Festival's exact phones.

Synthesises Harvard sentences with Festival (``festival`` + ``festvox-us-slt-hts``; lists
3-4 and 5-6 of ``visemes_align_accuracy.py``, held out from every setting; ``--tuning``
adds lists 1-2, the set the recognition settings were chosen on) and turns each into
visemes by every path:

- ``forced``: audio + transcript (``facelib.visemes.align(wav, text)``);
- ``phone loop``: audio alone, pocketsphinx's phone loop (``recognize(method="phones")``);
- ``two-pass``: audio alone, pocketsphinx's word decoder with the language model its wheel
  ships, then forced alignment of that transcript (``recognize(method="words")``);
- ``acoustic``: audio alone, the acoustic viseme model (``recognize(method="acoustic")``,
  any language; ``benchmarks/visemes_acoustic.py`` measures it further);
- ``default``: ``facelib.visemes_from_audio(wav)``, two-pass with the phone-loop fallback.

Both the truth and each path go through the same phone -> viseme chain
(``visemes_for``: the map, short silences merged, minimum durations). Printed per path:

- viseme class right per 10 ms: the share of 10 ms frames (centres at 5, 15, ... ms over
  the whole recording, silence included) whose viseme id equals the truth's;
- p/b/m closures found: truth bilabial viseme spans that a bilabial span of the path
  overlaps (within ``TOLERANCE_MS``), of all truth bilabial spans;
- false closures: bilabial spans of the path that overlap no truth bilabial span (within
  the same tolerance);
- for two-pass: the word error rate of pass 1 and the mean confidence of the words it got
  right and wrong; the real-time factor of each path on this machine.

    PYTHONPATH=. .venv/bin/python benchmarks/visemes_audio_only.py [--tuning] [N]
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
from facelib.speech import Span
from facelib.speech.pronounce import tokenize
from facelib.speech.recognize import decode_words, recognize
from facelib.speech.timeline import cover
from facelib.visemes import align, visemes_for, with_visemes
from facelib.visemes.timeline import SpeechTimeline, VisemeSpan

TOLERANCE_MS = 20
PATHS: dict[str, Callable[[Path, str], SpeechTimeline]] = {
    "forced": align,
    "phone loop": lambda wav, _: with_visemes(recognize(wav, method="phones")),
    "two-pass": lambda wav, _: with_visemes(recognize(wav, method="words")),
    "acoustic": lambda wav, _: with_visemes(recognize(wav, method="acoustic")),
    "default": lambda wav, _: facelib.visemes_from_audio(wav).speech,
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


def word_errors(text: str, wav: Path) -> tuple[int, int, list[float], list[float]]:
    """(errors, reference words, confidences of right words, of wrong ones) of pass 1."""
    from facelib.speech.audio import load_speech

    ref = [t for t in tokenize(text) if t[0].isalpha()]
    hyp = decode_words(load_speech(wav))
    matcher = difflib.SequenceMatcher(a=ref, b=[w for w, _ in hyp], autojunk=False)
    right = {b.b + i for b in matcher.get_matching_blocks() for i in range(b.size)}
    errors = max(len(ref), len(hyp)) - len(right)
    return (errors, len(ref), [c for i, (_, c) in enumerate(hyp) if i in right],
            [c for i, (_, c) in enumerate(hyp) if i not in right])


def measure(sentences: Sequence[str], tmp: Path) -> None:
    right = dict.fromkeys(PATHS, 0)
    found = dict.fromkeys(PATHS, 0)
    false = dict.fromkeys(PATHS, 0)
    seconds = dict.fromkeys(PATHS, 0.0)
    frames = n_closures = errors = n_words = 0
    sure: list[float] = []
    unsure: list[float] = []
    audio_s = 0.0
    for k, text in enumerate(sentences):
        wav = tmp / f"s{k}.wav"
        truth = truth_visemes(synthesize(text, wav))
        n = truth[-1].end_ms // 10
        frames += n
        audio_s += truth[-1].end_ms / 1000
        ids = frame_ids(truth, n)
        for name, path in PATHS.items():
            t0 = time.perf_counter()
            got = path(wav, text)
            seconds[name] += time.perf_counter() - t0
            right[name] += int(np.sum(frame_ids(got.visemes, n) == ids))
            hit, total, bad = closures(truth, got.visemes)
            found[name] += hit
            false[name] += bad
        n_closures += total
        e, r, ok, wrong = word_errors(text, wav)
        errors, n_words, sure, unsure = errors + e, n_words + r, sure + ok, unsure + wrong
    print(f"  sentences {len(sentences)}, audio {audio_s:.1f} s, frames {frames}, "
          f"p/b/m closures {n_closures}")
    print("  | path | viseme class right per 10 ms | p/b/m closures found | false closures "
          "| real-time factor |")
    for name in PATHS:
        print(f"  | {name} | {100 * right[name] / frames:.1f} % | {found[name]}/{n_closures} "
              f"| {false[name]} | {seconds[name] / audio_s:.2f} |")
    print(f"  pass 1 word error rate {100 * errors / n_words:.1f} % ({errors} of {n_words}); "
          f"mean confidence of right words {np.mean(sure):.2f} (n={len(sure)}), "
          f"of wrong ones {np.mean(unsure) if unsure else float('nan'):.2f} (n={len(unsure)})")


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    n = int(args[0]) if args else 20
    sets = {"held-out (lists 3-4)": HELD_OUT, "held-out (lists 5-6)": HELD_OUT_2}
    if "--tuning" in sys.argv:
        sets = {"tuning (lists 1-2)": SENTENCES, **sets}
    with tempfile.TemporaryDirectory() as tmp:
        for name, sentences in sets.items():
            print(name)
            measure(sentences[:n], Path(tmp))


if __name__ == "__main__":
    main()
