"""Rendering speed on this machine: offscreen frames per second, per-frame mesh update cost,
and the time to turn a 10 s ``.fap`` into an MP4 relative to its duration.

Run: ``PYTHONPATH=. python benchmarks/render_speed.py [--platform osmesa|egl] [--size 640x480]
[--antialias auto|msaa|supersample|off]`` (the platform must be chosen before OpenGL loads, so
each platform is its own run). The anti-aliasing mode (``FaceRenderer(antialias=...)``)
applies to every figure; the line per mesh update names the mode in use. The CPU time a frame
(all threads of the process, llvmpipe's included) varies less with other jobs on a shared
machine than the wall time does: on two idle cores a frame takes between half of it (both
cores busy rendering) and all of it.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np


def _stream(seconds: float, fps: int):
    from facelib.mpeg4.stream import FapStream

    t = np.arange(int(seconds * fps)) / fps
    values = np.zeros((len(t), 84), np.float32)
    values[:, 2] = 400 * (1 + np.sin(2 * np.pi * 3 * t))  # jaw, 3 Hz like syllables
    values[:, 11] = values[:, 12] = 150 * np.sin(2 * np.pi * 0.3 * t)  # lip corners
    values[:, 22] = values[:, 23] = 30000 * np.sign(np.sin(2 * np.pi * 0.5 * t))  # saccades
    values[:, 48] = 10000 * np.sin(2 * np.pi * 0.2 * t)  # head yaw
    return FapStream(fps, values)


def _timed(fn, repeat: int) -> float:
    start = time.perf_counter()
    for i in range(repeat):
        fn(i)
    return (time.perf_counter() - start) / repeat


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--platform", choices=["osmesa", "egl"], default=None)
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--antialias", default="auto",
                        choices=["auto", "msaa", "supersample", "off"])
    args = parser.parse_args()
    if args.platform:
        os.environ["PYOPENGL_PLATFORM"] = args.platform
    width, height = (int(v) for v in args.size.split("x"))

    from facelib.engine import load_face
    from facelib.mpeg4.fapfile import read_fap, write_fap
    from facelib.rendering.frames import render
    from facelib.rendering.platform import choose_platform
    from facelib.rendering.scene import FaceRenderer

    face = load_face(None)
    stream = _stream(args.seconds, 25)
    vertices = face.deform(stream[: args.frames])
    print(f"platform {choose_platform()}, face {len(face.vertices)} vertices "
          f"{len(face.triangles)} triangles, {width}x{height}, {os.cpu_count()} CPUs")

    for method in ("buffers", "swap"):
        with FaceRenderer(face, width=width, height=height, mesh_update=method,
                          antialias=args.antialias) as r:
            r.frame(vertices[0])
            update = _timed(lambda i, r=r: r.set_vertices(vertices[i % len(vertices)]),
                            args.frames)
            draw = _timed(lambda i, r=r: r.frame(), args.frames // 2)
            cpu_start = time.process_time()  # all threads of this process (llvmpipe's too)
            both = _timed(lambda i, r=r: r.frame(vertices[i % len(vertices)]), args.frames)
            cpu = (time.process_time() - cpu_start) / args.frames
        print(f"mesh update '{method}' ({r.antialias}): set_vertices {update * 1e3:6.2f} ms, "
              f"render only {draw * 1e3:6.1f} ms, update+render {both * 1e3:6.1f} ms "
              f"= {1 / both:5.1f} frames/s; CPU {cpu * 1e3:.1f} ms a frame")

    deform = _timed(lambda i: face.deform(stream[i * 32 : i * 32 + 32]), 4) / 32
    print(f"face.deform: {deform * 1e3:.2f} ms per frame (in chunks of 32)")

    with tempfile.TemporaryDirectory() as tmp:
        fap = write_fap(stream, Path(tmp) / "ten.fap")
        start = time.perf_counter()
        out = render(read_fap(fap), face=face, out=Path(tmp) / "ten.mp4", width=width,
                     height=height, progress=False)
        elapsed = time.perf_counter() - start
        size = out.stat().st_size
    print(f"{args.seconds:g} s .fap -> MP4 ({stream.n_frames} frames, render() defaults): "
          f"{elapsed:.1f} s "
          f"= {elapsed / args.seconds:.2f} x real time, {stream.n_frames / elapsed:.1f} frames/s, "
          f"{size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
