"""Festival speech synthesis with exact phone boundaries (a test-data source for the
aligner): the ``festival`` Debian package with the ``festvox-us-slt-hts`` voice.

Not part of the library: used by ``benchmarks/visemes_align_accuracy.py`` and
``tests/data/speech/make_fixtures.py``.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import soundfile
from scipy.signal import resample_poly

VOICE = "voice_cmu_us_slt_arctic_hts"
# Festival's US "radio" phone set -> ARPAbet (pocketsphinx en-us); pau/h# are silence.
FESTIVAL_TO_ARPABET = {
    "ax": "AH", "axr": "ER", "dx": "T", "el": "L", "em": "M", "en": "N", "hv": "HH",
    "nx": "N", "pau": "SIL", "h#": "SIL", "brth": "SIL",
}


def synthesize(text: str, wav: Path) -> list[tuple[str, float, float]]:
    """Speak ``text`` into ``wav`` (16 kHz mono, 16-bit) and return the exact phones as
    ``(ARPAbet, start_s, end_s)``, silences joined."""
    if shutil.which("festival") is None:
        raise RuntimeError("festival is missing: apt-get install festival festvox-us-slt-hts")
    with tempfile.TemporaryDirectory() as tmp:
        raw, segs, scm = Path(tmp, "raw.wav"), Path(tmp, "out.segs"), Path(tmp, "say.scm")
        quoted = text.replace("\\", " ").replace('"', " ")
        scm.write_text(
            f'({VOICE})\n(set! utt (Utterance Text "{quoted}"))\n(utt.synth utt)\n'
            f'(utt.save.wave utt "{raw}" \'riff)\n(utt.save.segs utt "{segs}")\n'
        )
        subprocess.run(["festival", "-b", str(scm)], check=True, capture_output=True)
        data, rate = soundfile.read(str(raw), dtype="float64")
        lines = segs.read_text().split("#", 1)[1].split("\n")
    if data.ndim == 2:
        data = data.mean(axis=1)
    data = resample_poly(data, 16000, rate) if rate != 16000 else data
    soundfile.write(str(wav), np.clip(data, -1, 1), 16000, subtype="PCM_16")
    phones: list[tuple[str, float, float]] = []
    start = 0.0
    for line in lines:
        parts = line.split()
        if len(parts) != 3:
            continue
        end, label = float(parts[0]), parts[2]
        label = FESTIVAL_TO_ARPABET.get(label, label.upper())
        if phones and label == "SIL" and phones[-1][0] == "SIL":
            phones[-1] = ("SIL", phones[-1][1], end)
        else:
            phones.append((label, start, end))
        start = end
    return phones
