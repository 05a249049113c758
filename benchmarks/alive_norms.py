"""A face alive between cues, measured against the norms of issue 32 (items 4 and 5).

Prints blinks a minute per state and the least blink interval (10 min of each state, five
seeds), the head's sd while listening (2 min storyboards), the head turn and the eyes'
angle in the head on an 18 deg ``lookTo`` (ten seeds), and the breathing rate found in
the FAP stream (nostril widening pulses and the spectrum of head pitch). Every number
comes from streams, never from a clock.

Run: PYTHONPATH=. .venv/bin/python benchmarks/alive_norms.py
"""

from __future__ import annotations

import numpy as np

from facelib import animate, fap
from facelib.fdl import loads
from facelib.gaze import simulate
from facelib.gaze.norms import blink_norms
from facelib.sync import Liveliness, SyncRules

DEG = np.pi / 180 / 1e-5  # angle units per degree
FPS = 25
STATES = {  # state -> (behaviour tuple, speaking)
    "rest": (("default", "thinking"), False),
    "listening": (("default", "listening"), False),
    "talking": (("default", "talking"), True),
    "reading": (("concentration",), False),
}


def blinks() -> None:
    norms = blink_norms()
    least = np.inf
    for state, (args, speaking) in STATES.items():
        counts, evoked = [], 0
        for seed in range(5):
            anim = simulate(*args, seconds=600, seed=seed, speaking=speaking)
            counts.append(len(anim.blinks) / 10)
            evoked += sum(b.evoked for b in anim.blinks)
            starts = np.array([b.start for b in anim.blinks])
            least = min(least, float(np.diff(starts).min(initial=np.inf)))
        print(f"blinks/min {state:9s}: {np.mean(counts):5.1f} (seeds {min(counts):.1f}-"
              f"{max(counts):.1f}; data {norms.rate(state):g}), {evoked} of "
              f"{sum(counts) * 10:.0f} gaze-evoked")
    print(f"least blink interval: {least:.3f} s (data {norms.min_interval_s:g} s)")


def listening_head() -> None:
    sds = []
    for seed in range(5):
        sb = loads(f'fps = {FPS}\nseed = {seed}\nlook {{ "default", "listening", dur = 120 }}')
        values = animate(sb).faps.values / DEG
        sds.append([values[:, fap(n).index].std()
                    for n in ("head_pitch", "head_yaw", "head_roll")])
    sd = np.array(sds)
    print("head sd listening (deg, 5 seeds): pitch {:.2f} ({:.2f}-{:.2f}), yaw {:.2f} "
          "({:.2f}-{:.2f}), roll {:.2f} ({:.2f}-{:.2f})".format(
              *[x for k in range(3) for x in (sd[:, k].mean(), sd[:, k].min(), sd[:, k].max())]))


def look18() -> None:
    planned, shown, eye = [], [], []
    for seed in range(10):
        sb = loads(f'fps = {FPS}\nseed = {seed}\nlook {{ "lookTo", "left", 18.0, at = 1.0, '
                   f'dur = 3 }}')
        anim = animate(sb)
        hold = slice(2 * FPS, 4 * FPS)  # 1 s after the look's onset to its end
        planned.append(anim.tracks["gaze"].values[hold, fap("head_yaw").index].mean() / DEG)
        values = anim.faps.values[hold] / DEG
        shown.append(values[:, fap("head_yaw").index].mean())
        eye.append(np.abs(values[:, [fap("yaw_l_eyeball").index,
                                     fap("yaw_r_eyeball").index]]).max())
    print(f"lookTo left 18 deg (10 seeds): head turn {min(planned):.2f} deg by the head-eye "
          f"rule, {np.mean(shown):.2f} deg mean in the stream with the idle motion "
          f"(seeds {min(shown):.2f}-{max(shown):.2f}); eyes in the head at most "
          f"{max(eye):.2f} deg")


def breathing() -> None:
    sb = loads(f'fps = {FPS}\nseed = 1\nlook {{ "default", "listening", dur = 120 }}')
    values = animate(sb).faps.values
    still = animate(sb, rules=SyncRules(head_noise=None),
                    liveliness=Liveliness(listening_amplitude=0.0)).faps.values
    nose = values[:, fap("stretch_l_nose").index]
    pulses = np.count_nonzero((nose[1:] > 0) & (nose[:-1] <= 0))
    pitch = still[:, fap("head_pitch").index].astype(np.float64)
    spectrum = np.abs(np.fft.rfft(pitch - pitch.mean(), n=8 * pitch.size))
    freq = np.fft.rfftfreq(8 * pitch.size, 1 / FPS)
    band = (freq > 0.15) & (freq < 0.5)
    peak = freq[band][np.argmax(spectrum[band])] * 60
    print(f"breathing in the stream (120 s listening): {pulses / 2:.1f} nostril pulses/min; "
          f"head pitch spectrum peak in 9-30/min at {peak:.1f}/min (head noise and listening "
          f"motion off)")


def main() -> None:
    blinks()
    listening_head()
    look18()
    breathing()


if __name__ == "__main__":
    main()
