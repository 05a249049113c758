"""Regenerate the committed speech fixtures in tests/data/speech/alignment (needs festival
and the festvox-us-slt-hts voice):
``PYTHONPATH=. .venv/bin/python tests/data/speech/make_fixtures.py``.

Each fixture is ``NAME.flac`` (16 kHz mono) plus ``NAME.tsv`` with the transcript on the
first line (``# text: ...``) and Festival's exact phones (ARPAbet, start s, end s).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))

import soundfile  # noqa: E402
from visemes_festival import synthesize  # noqa: E402

FIXTURES = {
    "quick_fox": "The quick brown fox jumps over the lazy dog.",
    "oov_names": "Zorblat met Quixotl near the glimmerfen bridge.",
    "bilabials": "Bob made a map of the big pump by the moor.",
}


def main() -> None:
    out = Path(__file__).parent / "alignment"
    out.mkdir(exist_ok=True)
    for name, text in FIXTURES.items():
        wav = out / f"{name}.wav"
        phones = synthesize(text, wav)
        data, rate = soundfile.read(str(wav))
        soundfile.write(str(out / f"{name}.flac"), data, rate, subtype="PCM_16")
        wav.unlink()
        rows = [f"# text: {text}"] + [f"{p}\t{s:.3f}\t{e:.3f}" for p, s, e in phones]
        (out / f"{name}.tsv").write_text("\n".join(rows) + "\n")
        print(name, f"{len(phones)} phones", f"{phones[-1][2]:.2f} s")


if __name__ == "__main__":
    main()
