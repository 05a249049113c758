"""How legible the speech is: mouth opening, jaw drop, closures and the envelope, per head.

Speaks held-out-style Harvard sentences (lists 3-6 of ``visemes_align_accuracy.py``, none of
which any viseme value was tuned on, plus one open-vowel sentence) as text-only storyboards
(espeak-ng gives the audio and the phone times), deforms each head with the stream, head
rotation removed (FAPs 48-50: the mouth is measured in the head's own frame), and prints per
head and style:

- the inner-lip gap (feature point 2.2 above 2.3, mm; negative where the lips press): its
  median and 95th percentile over the speaking frames, and its peak on each open vowel (aa,
  oh spans other than a reduced schwa);
- the jaw: the drop of the chin point 2.1 (mm), 95th percentile and its largest on /a/;
- p/b/m: the widest gap inside any bilabial span (a seal is under 0.5 mm) and the false
  closures (speaking frames with the gap under 0.5 mm more than 80 ms from any p/b/m and
  outside f/v, whose lower lip rises to the upper teeth);
- the per-frame correlation of the mouth opening (the gap, 0 where the lips touch or press)
  with the speech envelope (the RMS of the audio over 40 ms centred on each frame), per
  sentence and its mean.

    PYTHONPATH=. .venv/bin/python benchmarks/visemes_legibility.py [--heads default,cartoon,soma]
        [--styles normal,mumble,emphatic]
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
from pathlib import Path

import numpy as np

import facelib
from facelib.engine import load_face
from facelib.visemes.articulation import is_reduced

ROOT = Path(__file__).resolve().parent.parent
SENTENCES = (
    "The boy was there when the sun rose.",
    "A rod is used to catch pink salmon.",
    "The source of the huge river is the clear spring.",
    "Kick the ball straight and follow through.",
    "Help the woman get back to her feet.",
    "A pot of tea helps to pass the evening.",
    "The birch canoe slid on the smooth planks.",
    "Father was calm, but the dog barked at the park.",
)
SEAL_MM = 0.5
NEAR_BILABIAL_MS = 80


def heads(names: list[str]):
    heads_dir = ROOT / "examples" / "heads"
    for name in names:
        if name == "default":
            yield name, load_face()
        elif name == "cartoon":
            yield name, facelib.setup_face(heads_dir / "cartoon_head.obj",
                                           landmarks=heads_dir / "cartoon_landmarks.json")
        elif name == "soma":
            yield name, facelib.setup_face(heads_dir / "soma_head.ply",
                                           landmarks=heads_dir / "soma_landmarks.json")


def speak(text: str, style: str, folder: Path) -> facelib.Animation:
    path = folder / "sentence.fdl"
    path.write_text(f'fps = 25\nsay {{ text = "{text}", style = "{style}" }}\n')
    return facelib.run_fdl(path)


def frames_in(spans, names: set[str], fps: float, n: int, *, pad_ms: float = 0) -> np.ndarray:
    """``(n,) bool``: frames whose time lies in a span named in ``names`` (widened by pad)."""
    t = np.arange(n) * 1000.0 / fps
    mask = np.zeros(n, bool)
    for s in spans:
        if s.name in names:
            mask |= (t >= s.start_ms - pad_ms) & (t < s.end_ms + pad_ms)
    return mask


def envelope(anim: facelib.Animation, n: int) -> np.ndarray:
    """``(n,)`` RMS of the speech audio over 40 ms centred on each frame."""
    audio = anim.speech_audio
    samples = np.asarray(audio.samples, np.float64)
    rate = audio.sample_rate
    centre = (np.arange(n) / anim.faps.fps - anim.audio_offset) * rate
    half = int(0.02 * rate)
    out = np.zeros(n)
    for i, c in enumerate(centre.astype(int)):
        part = samples[max(c - half, 0):max(c + half, 0)]
        out[i] = np.sqrt(np.mean(part ** 2)) if part.size else 0.0
    return out


def measure(face, anims) -> dict[str, object]:
    fp = face.feature_points
    rest = np.asarray(face.vertices, np.float64)
    gaps, jaws, peaks, a_jaw, seals, corr = [], [], [], [], [], []
    false = 0
    for anim in anims:
        values = np.array(anim.faps.values)
        values[:, 47:50] = 0.0  # head pitch, yaw, roll
        moved = face.deform(dataclasses.replace(anim.faps, values=values))
        n, fps, spans = len(moved), anim.faps.fps, anim.visemes
        gap = 1000 * (moved[:, fp["2.2"], 1] - moved[:, fp["2.3"], 1])
        jaw = 1000 * (rest[fp["2.1"], 1] - moved[:, fp["2.1"], 1])
        speaking = frames_in(spans, {s.name for s in spans} - {"sil"}, fps, n)
        gaps.append(gap[speaking])
        jaws.append(jaw[speaking])
        for s in spans:
            span = frames_in([s], {s.name}, fps, n)
            if not span.any():
                continue
            if s.name in ("aa", "oh") and not is_reduced(s):
                peaks.append(gap[span].max())
            if s.name == "aa":
                a_jaw.append(jaw[span].max())
            if s.name == "PP":
                seals.append(gap[span].min())
        near = frames_in(spans, {"PP"}, fps, n, pad_ms=NEAR_BILABIAL_MS) | frames_in(
            spans, {"FF"}, fps, n)
        false += int(((gap < SEAL_MM) & speaking & ~near).sum())
        opening = np.maximum(gap, 0.0)  # pressed lips are as shut as touching ones
        corr.append(float(np.corrcoef(opening, envelope(anim, n))[0, 1]))
    gap_all, jaw_all = np.concatenate(gaps), np.concatenate(jaws)
    return {"gap_p50": np.percentile(gap_all, 50), "gap_p95": np.percentile(gap_all, 95),
            "open_peak_min": min(peaks), "open_peak_median": float(np.median(peaks)),
            "jaw_p95": np.percentile(jaw_all, 95), "jaw_a_max": max(a_jaw),
            "widest_pbm": max(seals), "n_pbm": len(seals), "false_closures": false,
            "envelope_r": corr}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--heads", default="default,cartoon,soma")
    parser.add_argument("--styles", default="normal,mumble,emphatic")
    args = parser.parse_args()
    styles = args.styles.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        anims = {style: [speak(s, style, Path(tmp)) for s in SENTENCES] for style in styles}
    print("head     style     gap p50  p95  open-vowel peak min/median  jaw p95  /a/ max  "
          "widest p/b/m (n)  false  envelope r mean (min)")
    for name, face in heads(args.heads.split(",")):
        for style in styles:
            m = measure(face, anims[style])
            r = np.array(m["envelope_r"])
            print(f"{name:8s} {style:9s} {m['gap_p50']:5.1f} {m['gap_p95']:5.1f}   "
                  f"{m['open_peak_min']:5.1f} / {m['open_peak_median']:5.1f}           "
                  f"{m['jaw_p95']:5.1f}   {m['jaw_a_max']:5.1f}    "
                  f"{m['widest_pbm']:5.2f} ({m['n_pbm']})       {m['false_closures']:3d}    "
                  f"{r.mean():.2f} ({r.min():.2f})")


if __name__ == "__main__":
    main()
