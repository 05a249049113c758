"""Forced-alignment accuracy and speed against Festival's exact phone boundaries.

Synthesises sentences with Festival (``festival`` + ``festvox-us-slt-hts``), aligns each
with ``facelib.visemes.align`` and prints the share of phone onsets within 20 ms and 50 ms
of the truth, the mean absolute onset error and the real-time factor (alignment time /
audio duration; the one-off model load is reported apart), for each sentence set apart:
lists 1-2 (the set the aligner's settings were tuned on) and two held-out sets, lists 3-4
and 5-6, that no setting was chosen on. A change must help the held-out sets too.

    PYTHONPATH=. .venv/bin/python benchmarks/visemes_align_accuracy.py [-v] [--dtw] [N]

``--dtw`` measures the DTW aligner (``facelib.speech.align_dtw``: espeak-ng's synthesized
transcript warped onto the recording) instead. Its phones are IPA, so its phones are
matched to Festival's by their viseme sequence (IPA and ARPAbet -> viseme id) rather than
by label.

``-v`` adds the mean signed onset error per phone (positive: the aligner is late). Errors
are whole milliseconds (aligner ms minus Festival's times rounded to ms, which are
multiples of 5 ms), so an error of exactly 20 ms counts as within 20 ms.

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

from facelib.speech import align_dtw
from facelib.speech.decoding import new_decoder
from facelib.visemes import align
from facelib.visemes.ipa import ipa_viseme
from facelib.visemes.tables import phone_viseme

SENTENCES = (  # Harvard sentences (IEEE 1969), lists 1-2: the tuning set
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


HELD_OUT = (  # Harvard lists 3-4
    "The small pup gnawed a hole in the sock.",
    "The fish twisted and turned on the bent hook.",
    "Press the pants and sew a button on the vest.",
    "The swan dive was far short of perfect.",
    "The beauty of the view stunned the young boy.",
    "Two blue fish swam in the tank.",
    "Her purse was full of useless trash.",
    "The colt reared and threw the tall rider.",
    "It snowed, rained, and hailed the same morning.",
    "Read verse out loud for pleasure.",
    "Hoist the load to your left shoulder.",
    "Take the winding path to reach the lake.",
    "Note closely the size of the gas tank.",
    "Wipe the grease off his dirty face.",
    "Mend the coat before you go out.",
    "The wrist was badly strained and hung limp.",
    "The stray cat gave birth to kittens.",
    "The young girl gave no clear response.",
    "The meal was cooked before the bell rang.",
    "What joy there is in living.",
)
HELD_OUT_2 = (  # Harvard lists 5-6
    "A king ruled the state in the early days.",
    "The ship was torn apart on the sharp reef.",
    "Sickness kept him home the third week.",
    "The wide road shimmered in the hot sun.",
    "The lazy cow lay in the cool grass.",
    "Lift the square stone over the fence.",
    "The rope will bind the seven books at once.",
    "Hop over the fence and plunge in.",
    "The friendly gang left the drug store.",
    "Mesh wire keeps chicks inside.",
    "The frosty air passed through the coat.",
    "The crooked maze failed to fool the mouse.",
    "Adding fast leads to wrong sums.",
    "The show was a flop from the very start.",
    "A saw is a tool used for making boards.",
    "The wagon moved on well oiled wheels.",
    "March the soldiers past the next hill.",
    "A cup of sugar makes sweet fudge.",
    "Place a rosebush near the porch steps.",
    "Both lost their lives in the raging storm.",
)
SETS = {"tuning (lists 1-2)": SENTENCES, "held-out (lists 3-4)": HELD_OUT,
        "held-out (lists 5-6)": HELD_OUT_2}


def measure(sentences: tuple[str, ...], tmp: Path, *, verbose: bool, dtw: bool) -> None:
    """Align each sentence and print the onset statistics of the set."""
    errors: list[int] = []  # ms, aligner minus truth
    labels: list[str] = []
    audio_s = align_s = 0.0
    matched = total = 0
    for k, text in enumerate(sentences):
        wav = Path(tmp, f"s{k}.wav")
        truth = [p for p in synthesize(text, wav) if p[0] != "SIL"]
        t0 = time.perf_counter()
        timeline = align_dtw(wav, text, lang="en") if dtw else align(wav, text)
        align_s += time.perf_counter() - t0
        audio_s += timeline.duration_ms / 1000
        got = [p for p in timeline.phones if p.label != "SIL"]
        if dtw:
            a = [phone_viseme(p[0]).visemes[0] for p in truth]
            b = [ipa_viseme(p.label).visemes[0] for p in got]
        else:
            a, b = [p[0] for p in truth], [p.label for p in got]
        matcher = difflib.SequenceMatcher(a=a, b=b, autojunk=False)
        total += len(truth)
        for block in matcher.get_matching_blocks():
            for i in range(block.size):
                errors.append(got[block.b + i].start_ms - round(1000 * truth[block.a + i][1]))
                labels.append(truth[block.a + i][0])
                matched += 1
    signed = np.array(errors)
    err = np.abs(signed)
    if verbose:
        for lab in sorted(set(labels)):
            sel = np.array(labels) == lab
            print(f"  {lab:3s} n={sel.sum():3d} mean signed {signed[sel].mean():+6.1f} ms")
    print(f"  mean signed onset error: {signed.mean():+.1f} ms")
    print(f"  sentences: {len(sentences)}, audio: {audio_s:.1f} s, phones: {total}, "
          f"matched: {matched}")
    print(f"  onsets within 20 ms: {100 * np.mean(err <= 20):.1f} % "
          f"(under 20 ms: {100 * np.mean(err < 20):.1f} %)")
    print(f"  onsets within 50 ms: {100 * np.mean(err <= 50):.1f} %")
    print(f"  mean |onset error|: {err.mean():.1f} ms, median {np.median(err):.1f} ms")
    print(f"  real-time factor: {align_s / audio_s:.3f}")


def main() -> None:
    args = [a for a in sys.argv[1:] if a not in ("-v", "--dtw")]
    n = int(args[0]) if args else len(SENTENCES)
    t0 = time.perf_counter()
    new_decoder()
    print(f"model load {time.perf_counter() - t0:.2f} s (once per process)")
    with tempfile.TemporaryDirectory() as tmp:
        for name, sentences in SETS.items():
            print(name)
            measure(sentences[:n], Path(tmp), verbose="-v" in sys.argv, dtw="--dtw" in sys.argv)


if __name__ == "__main__":
    main()
