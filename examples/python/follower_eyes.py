"""Follower eyes (the thesis's case study): the eyes pursue a target moving around the face.

A target circles in front of the face at 60 cm, 20 degrees wide, once every 4 seconds;
``facelib.gaze.pursue`` gives smooth pursuit with catch-up saccades and vergence on the near
target. The eye track becomes a FapStream and is rendered.

    python examples/python/follower_eyes.py [OUT.mp4]
"""

import sys

import numpy as np

import facelib
from facelib.sync import to_stream

fps, seconds = 25, 8.0
t = np.arange(round(seconds * fps)) / fps
target = np.stack([20 * np.cos(2 * np.pi * t / 4), 10 * np.sin(2 * np.pi * t / 4)], axis=1)
eyes = facelib.gaze.pursue(target, fps=fps, seed=1, head=True, distance_m=0.6)
stream = to_stream(eyes.track)
error = np.abs(eyes.gaze - target)[fps:].mean()  # after the first second
print(f"{stream.n_frames} frames, mean pursuit error {error:.1f} degrees, "
      f"{sum(s.kind == 'catch_up' for s in eyes.saccades)} catch-up saccades")
out = sys.argv[1] if len(sys.argv) > 1 else "out/follower_eyes.mp4"
facelib.render(stream, out=out, width=480, height=360)
print("wrote", out)
