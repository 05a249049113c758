"""Performance-driven animation on the default head: speed and the closed loop.

Run from the repository root (one thread, so the figures are per core)::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/tracking.py

Renders ``examples/hello/hello.fdl`` (speech, expressions, gaze, blinks) at 640x480 with
added head turns (yaw up to 20 degrees, pitch 10, roll 8), tracks the video with MediaPipe,
recovers the FAPs and prints: MediaPipe frames/s, landmarks-to-FAPs frames/s, and per FAP
the correlation and gain of the recovered against the true curve, blink and lip-closure
recall; then the same without the added head turns; then both on the SOMA-X head of
``examples/heads`` (set up with ``facelib.setup_face``), which the default head's rig
model has never seen.
"""

from __future__ import annotations

import time

import numpy as np

import facelib
from facelib.engine import Face, default_face
from facelib.mpeg4 import FapStream
from facelib.tracking.closedloop import (
    closed_loop,
    closure_events,
    event_recall,
    lip_closures,
    lip_gap,
    with_head_turns,
)
from facelib.tracking.faps import measure_faps
from facelib.tracking.mediapipe import FaceMeshTracker

FAPS = (3, 53, 54, 59, 60, 31, 32, 19, 20, 21, 22, 48, 49, 50, 23, 24)


def report(title: str, truth: FapStream, face: Face | None = None) -> None:
    started = time.perf_counter()
    loop = closed_loop(truth, face=face, keep_frames=True)
    print(f"\n{title}: {truth.n_frames} frames, closed loop in "
          f"{time.perf_counter() - started:.1f} s")
    print(f"  {'FAP':>3}  {'name':<22} {'corr':>6} {'gain':>6}")
    for fap_id in FAPS:
        print(f"  {fap_id:>3}  {facelib.fap(fap_id).name:<22} {loop.correlation(fap_id):6.3f} "
              f"{loop.gain(fap_id):6.2f}")
    for fap_id in (19, 20):
        events = closure_events(truth.values[:, fap_id - 1], 600)
        recall = event_recall(events, loop.tracked.stream.values[:, fap_id - 1])
        print(f"  blinks (FAP {fap_id}): {len(events)}, recalled {recall:.0%}")
    face = default_face() if face is None else face
    truth_gap = lip_gap(face, truth)
    events = lip_closures(truth_gap, truth.fps)
    recall = event_recall(events, -lip_gap(face, loop.tracked.stream))
    print(f"  lip closures (p/b/m): {len(events)}, recalled {recall:.0%}")
    assert loop.frames is not None
    speed(loop.frames, loop.landmarks, truth.fps)


def speed(frames: np.ndarray, landmarks: np.ndarray, fps: float) -> None:
    with FaceMeshTracker(video=True, max_faces=1) as tracker:
        started = time.perf_counter()
        for image in frames:
            tracker.detect(image)
        track_s = time.perf_counter() - started
    measure_faps(landmarks[:10], fps=fps)  # warm the cached rig model
    started = time.perf_counter()
    measure_faps(landmarks, fps=fps)
    faps_s = time.perf_counter() - started
    n = len(frames)
    print(f"  MediaPipe face mesh, 640x480: {n / track_s:.0f} frames/s; landmarks to FAPs: "
          f"{n / faps_s:.0f} frames/s; whole path without decoding: "
          f"{n / (track_s + faps_s):.0f} frames/s")


def main() -> None:
    hello = facelib.run_fdl("examples/hello/hello.fdl").faps
    report("hello.fdl with head turns (yaw 20, pitch 10, roll 8 degrees)",
           with_head_turns(hello))
    report("hello.fdl as scripted (small head motion)", hello)
    soma = facelib.setup_face("examples/heads/soma_head.ply",
                              landmarks="examples/heads/soma_landmarks.json")
    report("SOMA-X head, hello.fdl with head turns", with_head_turns(hello), soma)
    report("SOMA-X head, hello.fdl as scripted", hello, soma)


if __name__ == "__main__":
    main()
