"""Rendering speed on this machine: offscreen frames per second of the bare head and of the
default character (hair and bust), against a minimal renderer of the same mesh; per-frame
mesh update cost; the time to turn a 10 s ``.fap`` into an MP4 relative to its duration.

Run: ``PYTHONPATH=. python benchmarks/render_speed.py [--platform osmesa|egl] [--size 640x480]
[--antialias auto|msaa|supersample|off] [--rounds 5] [--images DIR]`` (the platform must be
chosen before OpenGL loads, so each platform is its own run). The anti-aliasing mode
(``FaceRenderer(antialias=...)``) applies to every figure. The ceiling is
``render_ceiling.py`` (moderngl on llvmpipe through the same context type as this run, with
its one-light shader and with facelib's face shader; ``pip install moderngl``, or it is left
out).

The CPU time a frame (all threads of the process, llvmpipe's included) varies less with
other jobs on a shared machine than the wall time does, so every figure is a median of
``--rounds`` rounds that alternate the renderers in one process. llvmpipe draws on the main
thread (vertex shading, binning) and rasterises on one thread per core, so on two idle cores
a frame takes about the main thread's CPU time plus half the rest: the "2 idle cores"
estimate. "hair double-sided, all uploaded" is the renderer before the speed work of issue
33 (every hair card drawn from both sides, every vertex uploaded and its normal recomputed
each frame), kept to show what that work buys. "the ceiling's shader" is the face renderer
drawing with the ceiling's one-light Lambert shader instead of facelib's (everything else
the same): what is left of pyrender's own cost once the look's shading is taken out.
``--side-by-side-only`` leaves out the mesh-update and MP4 figures.
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


def _bare_face():
    """The default head without bust and hair: its definition minus those two entries, in a
    temporary folder beside copies of its files."""
    import json
    import shutil

    from facelib import data
    from facelib.engine import load_face

    folder = Path(tempfile.mkdtemp())
    head = data.path("head")
    for name in (p.name for p in Path(str(head)).iterdir()):
        shutil.copy(str(head / name), folder / name)
    doc = json.loads((folder / "default_head.json").read_text())
    doc.pop("bust", None)
    doc.pop("hair", None)
    (folder / "default_head.json").write_text(json.dumps(doc))
    face = load_face(folder / "default_head.json")
    shutil.rmtree(folder)
    return face


def _double_sided_look():
    """The look with the hair drawn double-sided everywhere (before issue 33's speed work)."""
    import dataclasses
    from types import MappingProxyType

    from facelib.rendering.scene import load_look

    look = load_look()
    parts = {k: {n: v for n, v in spec.items() if n != "single_sided_within_es"}
             for k, spec in look.parts.items()}
    return dataclasses.replace(look, parts=MappingProxyType(parts))


class _InProcess:
    """A FaceRenderer measured in this process."""

    def __init__(self, renderer, vertices: np.ndarray, faps: np.ndarray):
        self.renderer, self.vertices, self.faps = renderer, vertices, faps
        self.mode = renderer.antialias
        renderer.frame(vertices[0])  # warm up: shaders compiled, buffers made

    def measure(self, frames: int) -> tuple[float, float]:
        # each frame with its FAPs, as render() draws it (they deepen the skin's wrinkles)
        start, start_main = time.process_time(), time.thread_time()
        for i in range(frames):
            k = i % len(self.vertices)
            self.renderer.frame(self.vertices[k], faps=self.faps[k])
        return ((time.process_time() - start) / frames,
                (time.thread_time() - start_main) / frames)

    def image(self, path: Path) -> None:
        import imageio.v3 as iio

        iio.imwrite(path, self.renderer.frame(self.vertices[0]))

    def close(self) -> None:
        self.renderer.close()


class _Child:
    """The ceiling (render_ceiling.py) in a child process, measured there: on the context
    type this process renders on, with the minimal shader or facelib's (``shading``)."""

    def __init__(self, label: str, args, samples: int, renderer, shading: str = "lambert"):
        import json
        import subprocess
        import sys

        from facelib.rendering.platform import choose_platform

        here = Path(__file__).resolve().parent
        camera = renderer.scene.main_camera_node.camera
        config = {
            "P": camera.get_projection_matrix(renderer.width, renderer.height).tolist(),
            "V": np.linalg.inv(renderer.camera_pose).tolist(),
            "position": renderer.camera_pose[:3, 3].tolist(),
            "backend": choose_platform(), "shading": shading}
        command = [sys.executable, str(here / "render_ceiling.py"), label, args.size,
                   str(samples), str(args.frames), json.dumps(config)]
        self.process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            env={**os.environ, "PYTHONPATH": os.pathsep.join(
                [str(here), os.environ.get("PYTHONPATH", "")])})
        self.mode = self._answer()

    def _answer(self) -> str:
        line = self.process.stdout.readline()
        if not line:
            raise RuntimeError("the ceiling's process ended (is moderngl installed, does "
                               "EGL work?)")
        return line.strip()

    def measure(self, frames: int) -> tuple[float, float]:
        self.process.stdin.write("run\n")
        self.process.stdin.flush()
        cpu, main = self._answer().split()
        return float(cpu), float(main)

    def image(self, path: Path) -> None:
        self.process.stdin.write(f"image {path}\n")
        self.process.stdin.flush()
        self._answer()

    def close(self) -> None:
        self.process.stdin.write("quit\n")
        self.process.stdin.close()
        self.process.wait()


# the ceiling's shader (render_ceiling.py: one Lambert light, no gamma) where pyrender's
# attributes and uniforms are, for the face renderer drawn with it ("the ceiling's shader")
_LAMBERT_VERT = """#version 330 core
layout(location = 0) in vec3 position;
layout(location = NORMAL_LOC) in vec3 normal;
#ifdef COLOR_0_LOC
layout(location = COLOR_0_LOC) in vec4 color_0;
#endif
uniform mat4 M;
uniform mat4 V;
uniform mat4 P;
out vec3 n;
out vec3 albedo;
void main() {
    gl_Position = P * V * (M * vec4(position, 1.0));
    n = mat3(M) * normal;
#ifdef COLOR_0_LOC
    albedo = color_0.rgb;
#else
    albedo = vec3(0.8);
#endif
}
"""


def _lambert_shaders() -> Path:
    """A temporary folder with the ceiling's shader as face.vert and face.frag."""
    from render_ceiling import FRAGMENT

    folder = Path(tempfile.mkdtemp())
    (folder / "face.vert").write_text(_LAMBERT_VERT)
    (folder / "face.frag").write_text(FRAGMENT)
    return folder


def _renderers(faces: dict, stream, args, width: int, height: int) -> dict:
    """name -> measured renderer: per face, the FaceRenderer, the same drawn with the
    ceiling's shader, for the default face also the renderer before issue 33's speed work,
    and the ceiling with its own shader and with facelib's."""
    from facelib.rendering.scene import FaceRenderer

    out: dict = {}
    lambert = _lambert_shaders()
    for label, face in faces.items():
        vertices = face.deform(stream[: args.frames])
        for tag, options in (("", {}), (", the ceiling's shader", {}),
                             (", hair double-sided, all uploaded",
                              {"look": _double_sided_look(), "rigid_pieces": False})):
            if "hair" in tag and label == "bare":
                continue
            r = FaceRenderer(face, width=width, height=height, antialias=args.antialias,
                             **options)
            if "shader" in tag:
                _serve_shaders(r, lambert)
            out[f"{label}{tag}"] = _InProcess(r, vertices, stream.values[: args.frames])
        if args.shaders_before and label == "default":
            r = FaceRenderer(face, width=width, height=height, antialias=args.antialias)
            _serve_shaders(r, Path(args.shaders_before))
            out[f"{label}, shaders before"] = _InProcess(r, vertices,
                                                         stream.values[: args.frames])
        samples = 0 if out[label].mode == "off" else 4
        for shading, tag in (("lambert", ""), ("face", ", face shader")):
            try:
                out[f"{label}: ceiling{tag}"] = _Child(label, args, samples,
                                                       out[label].renderer, shading)
            except RuntimeError as exc:
                print(f"no ceiling for {label}: {exc}")
    return out


def _serve_shaders(renderer, folder: Path) -> None:
    """Make ``renderer`` (a FaceRenderer) draw with ``folder``'s face.vert and face.frag
    (an earlier version of facelib's shaders: ``git show main:facelib/data/shaders/...``),
    everything else the same, so a shader change is measured side by side in one process."""
    from facelib.rendering.scene import install_program_cache

    install_program_cache(renderer._pr, renderer._renderer._renderer, renderer.look,
                          shaders=str(folder))


def _side_by_side(renderers: dict, rounds: int, frames: int) -> dict:
    """name -> (median CPU a frame, median main-thread CPU a frame), seconds."""
    cpu: dict[str, list[float]] = {k: [] for k in renderers}
    main: dict[str, list[float]] = {k: [] for k in renderers}
    for _ in range(rounds):
        for name, renderer in renderers.items():
            c, m = renderer.measure(frames)
            cpu[name].append(c)
            main[name].append(m)
    return {k: (float(np.median(cpu[k])), float(np.median(main[k]))) for k in renderers}


def _report(renderers: dict, figures: dict, images: str | None) -> None:
    for name, (cpu, main) in figures.items():
        label = name.split(":")[0].split(",")[0]
        ratio = ""
        for key, what in ((f"{label}: ceiling", "the ceiling"),
                          (f"{label}: ceiling, face shader", "with face shader")):
            if key in figures and ":" not in name:
                ratio += f", {figures[key][0] / cpu:4.2f} of {what}"
        idle = main + (cpu - main) / 2
        print(f"  {name:38s} CPU {cpu * 1e3:6.1f} ms a frame = {1 / cpu:5.1f} frames/s; "
              f"2 idle cores ~{idle * 1e3:5.1f} ms = {1 / idle:5.1f} frames/s{ratio}")
    if images:
        Path(images).mkdir(parents=True, exist_ok=True)
        for name, renderer in renderers.items():
            slug = "".join(c if c.isalnum() else "_" for c in name)
            renderer.image(Path(images).resolve() / f"{slug}.png")


def _side_by_side_figures(faces: dict, stream, args, width: int, height: int) -> None:
    renderers = _renderers(faces, stream, args, width, height)
    ceiling = "; ".join(dict.fromkeys(r.mode for r in renderers.values()
                                      if isinstance(r, _Child)))
    print(f"side by side ({renderers['default'].mode}; medians of {args.rounds} rounds of "
          f"{args.frames} frames{'; ceilings: ' + ceiling if ceiling else ''}):")
    _report(renderers, _side_by_side(renderers, args.rounds, args.frames), args.images)
    for renderer in renderers.values():
        renderer.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--platform", choices=["osmesa", "egl"], default=None)
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--antialias", default="auto",
                        choices=["auto", "msaa", "supersample", "off"])
    parser.add_argument("--images", default=None, help="write each renderer's first frame here")
    parser.add_argument("--shaders-before", default=None,
                        help="a folder with earlier face.vert/face.frag: also measure the "
                             "default character drawn with them, side by side")
    parser.add_argument("--side-by-side-only", action="store_true",
                        help="leave out the mesh-update and .fap -> MP4 figures")
    args = parser.parse_args()
    if args.platform:
        os.environ["PYOPENGL_PLATFORM"] = args.platform
    width, height = (int(v) for v in args.size.split("x"))

    from machine import describe

    from facelib.engine import load_face
    from facelib.rendering.platform import choose_platform

    faces = {"bare": _bare_face(), "default": load_face(None)}
    stream = _stream(args.seconds, 25)
    print(f"platform {choose_platform()}, {width}x{height}; {describe()}")
    for label, face in faces.items():
        print(f"  {label}: {len(face.vertices)} vertices, {len(face.triangles)} triangles")
    _side_by_side_figures(faces, stream, args, width, height)
    if not args.side_by_side_only:
        _update_figures(faces["default"], stream, args, width, height)


def _update_figures(face, stream, args, width: int, height: int) -> None:
    from facelib.mpeg4.fapfile import read_fap, write_fap
    from facelib.rendering.frames import render
    from facelib.rendering.scene import FaceRenderer

    vertices = face.deform(stream[: args.frames])
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
