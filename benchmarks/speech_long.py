"""Long storyboards: peak memory and time of ``facelib run`` for 1, 5 and 20 minutes of
speech, text only (synthesized by espeak-ng) and with a recording (English: sentences found
by DTW, then pocketsphinx sentence by sentence).

Each run is a separate process measured by ``/usr/bin/time -v`` (maximum resident set
size, elapsed wall time). The "recording" is espeak-ng's en-us+m3 voice reading the
transcript. Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/speech_long.py            # 1 and 5 minutes
    PYTHONPATH=. .venv/bin/python benchmarks/speech_long.py 1 5 20     # any lengths
    PYTHONPATH=. .venv/bin/python benchmarks/speech_long.py --text-only 1 5 20

Prints one line per run: minutes, mode, peak MB, seconds, seconds per minute of speech.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import soundfile

from facelib.speech import synthesize

SENTENCES = (
    "Bob bought a big map of the moon.",
    "The quick brown fox jumps over the lazy dog.",
    "She sells sea shells by the sea shore, and the shells she sells are surely seashells.",
    "Peter Piper picked a peck of pickled peppers.",
    "My mother baked a pumpkin pie for the family picnic in the park.",
    "Please remember to bring both maps when you come back on Monday.",
)
WORDS_PER_MINUTE = 160


def transcript(minutes: float) -> str:
    """About ``minutes`` of speech: the sentences in turn until the word count is reached."""
    out: list[str] = []
    words = 0
    k = 0
    while words < minutes * WORDS_PER_MINUTE:
        sentence = SENTENCES[k % len(SENTENCES)]
        out.append(sentence)
        words += len(sentence.split())
        k += 1
    return " ".join(out)


def measure(story: Path, out: Path) -> tuple[float, float]:
    """(peak resident MB, elapsed s) of ``facelib run story -o out``."""
    facelib = Path(sys.executable).with_name("facelib")
    done = subprocess.run(["/usr/bin/time", "-v", str(facelib), "run", str(story), "-o",
                           str(out)], capture_output=True, text=True, check=True)
    peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)[1])
    clock = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)",
                      done.stderr)[1]
    seconds = sum(float(p) * 60 ** i for i, p in enumerate(reversed(clock.split(":"))))
    return peak_kb / 1024, seconds


def main(lengths: list[float], *, text_only: bool = False) -> None:
    print("minutes  mode        speech_s  peak_MB  seconds  s_per_speech_min")
    with tempfile.TemporaryDirectory() as folder:
        base = Path(folder)
        for minutes in lengths:
            text = transcript(minutes)
            (base / "text.txt").write_text(text, encoding="utf-8")
            recording = synthesize(text, lang="en", voice="en-us+m3")
            seconds_of_speech = recording.samples.size / recording.sample_rate
            soundfile.write(base / "speech.wav", np.asarray(recording.samples),
                            recording.sample_rate)
            del recording
            stories = {
                "text-only": 'say { transcript = "text.txt" }\n',
                "recording": 'say { audio = "speech.wav", transcript = "text.txt" }\n',
            }
            if text_only:
                del stories["recording"]
            for mode, body in stories.items():
                story = base / f"{mode}.fdl"
                story.write_text(body, encoding="utf-8")
                peak, seconds = measure(story, base / "out.fap")
                print(f"{minutes:7g}  {mode:10s}  {seconds_of_speech:8.0f}  {peak:7.0f}  "
                      f"{seconds:7.1f}  {seconds / (seconds_of_speech / 60):16.1f}",
                      flush=True)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--text-only"]
    main([float(a) for a in args] or [1.0, 5.0], text_only="--text-only" in sys.argv)
