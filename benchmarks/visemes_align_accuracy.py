"""Forced-alignment accuracy and speed against Festival's exact phone boundaries.

Synthesises sentences with Festival (``festival`` + ``festvox-us-slt-hts``), aligns each
with ``facelib.visemes.align`` and prints the share of phone onsets within 20 ms and 50 ms
of the truth, the mean absolute onset error and the real-time factor (alignment time /
audio duration; the one-off model load is reported apart).

    PYTHONPATH=. .venv/bin/python benchmarks/visemes_align_accuracy.py [N_SENTENCES]

Phones are matched by label sequence (difflib), so dictionary differences between Festival
and the CMU dictionary only drop the unmatched phones from the statistics.
"""

from __future__ import annotations

import difflib
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from visemes_festival import synthesize

from facelib.visemes.align import _decoder, align

SENTENCES = (  # Harvard sentences (IEEE 1969), lists 1-2
    "The birch canoe slid on the smooth planks.",
    "Glue the sheet to the dark blue background.",
    "It's easy to tell the depth of a well.",
    "These days a chicken leg is a rare dish.",
    "Rice is often served in round bowls.",
    "The juice of lemons makes fine punch.",
    "The box was thrown beside the parked truck.",
    "The hogs were fed chopped corn and garbage.",
    "Four hours of steady work faced us.",
    "A large size in stockings is hard to sell.",
    "The boy was there when the sun rose.",
    "A rod is used to catch pink salmon.",
    "The source of the huge river is the clear spring.",
    "Kick the ball straight and follow through.",
    "Help the woman get back to her feet.",
    "A pot of tea helps to pass the evening.",
    "Smoky fires lack flame and heat.",
    "The soft cushion broke the man's fall.",
    "The salt breeze came across from the sea.",
    "The girl at the booth sold fifty bonds.",
)


def main() -> None:
    args = [a for a in sys.argv[1:] if a != "-v"]
    n = int(args[0]) if args else len(SENTENCES)
    t0 = time.perf_counter()
    _decoder()
    load_s = time.perf_counter() - t0
    errors: list[float] = []
    labels: list[str] = []
    audio_s = align_s = 0.0
    matched = total = 0
    with tempfile.TemporaryDirectory() as tmp:
        for k, text in enumerate(SENTENCES[:n]):
            wav = Path(tmp, f"s{k}.wav")
            truth = [p for p in synthesize(text, wav) if p[0] != "SIL"]
            t0 = time.perf_counter()
            timeline = align(wav, text)
            align_s += time.perf_counter() - t0
            audio_s += timeline.duration_ms / 1000
            got = [p for p in timeline.phones if p.label != "SIL"]
            matcher = difflib.SequenceMatcher(
                a=[p[0] for p in truth], b=[p.label for p in got], autojunk=False)
            total += len(truth)
            for block in matcher.get_matching_blocks():
                for i in range(block.size):
                    t = truth[block.a + i][1]
                    g = got[block.b + i].start_ms / 1000
                    errors.append(g - t)
                    labels.append(truth[block.a + i][0])
                    matched += 1
    signed = np.array(errors)
    err = np.abs(signed)
    if "-v" in sys.argv:
        for lab in sorted(set(labels)):
            sel = np.array(labels) == lab
            print(f"  {lab:3s} n={sel.sum():3d} mean signed {1000 * signed[sel].mean():+6.1f} ms")
    print(f"mean signed onset error: {1000 * signed.mean():+.1f} ms")
    print(f"sentences: {n}, audio: {audio_s:.1f} s, phones: {total}, matched: {matched}")
    print(f"onsets within 20 ms: {100 * np.mean(err <= 0.020):.1f} %")
    print(f"onsets within 50 ms: {100 * np.mean(err <= 0.050):.1f} %")
    print(f"mean |onset error|: {1000 * err.mean():.1f} ms, median {1000 * np.median(err):.1f} ms")
    print(f"real-time factor: {align_s / audio_s:.3f} (model load {load_s:.2f} s, once)")


if __name__ == "__main__":
    main()
