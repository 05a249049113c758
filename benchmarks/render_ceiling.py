"""The ceiling for ``render_speed.py``: a minimal moderngl renderer of the same mesh.

One vertex buffer (position, normal, colour) rewritten every frame with the deformed
vertices and their smooth normals (the same ``vertex_normals`` as the face renderer), one
draw call of every triangle (no face culling), a one-light Lambert shader, a 4x multisampled
framebuffer resolved and read back as RGB, on Mesa's llvmpipe, the software rasteriser
pyrender uses here, through the same context type as the face renderer in that run (OSMesa,
made as pyrender makes it, or EGL). What a renderer of this mesh at this size cannot do much
better than; pyrender's frame time is given as a ratio to it (issue 30, item 9). With
``"shading": "face"`` it shades with facelib's own face shader instead (its plain branch,
under the look's lights): what the renderer's look costs, apart from pyrender.

moderngl is not a dependency of facelib: ``pip install moderngl`` for this benchmark only.
It runs in a child process (``python render_ceiling.py FACE WIDTHxHEIGHT SAMPLES FRAMES
CAMERA``, CAMERA a JSON object: see :class:`Ceiling`; started by ``render_speed.py``): two
OpenGL libraries (PyOpenGL's and moderngl's) in one process share Mesa's dispatch and draw
into each other's contexts. The child reads a command a line from stdin: ``run`` (render
the frames, answer ``cpu main`` seconds a frame), ``image PATH`` (write the first frame),
``quit``.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from facelib.engine.colours import srgb_to_linear
from facelib.rendering.normals import normal_operator, vertex_normals

VERTEX = """
#version 330 core
uniform mat4 mvp;
in vec3 position;
in vec3 normal;
in vec3 colour;
out vec3 n;
out vec3 albedo;
void main() {
    gl_Position = mvp * vec4(position, 1.0);
    n = normal;
    albedo = colour;
}
"""

FRAGMENT = """
#version 330 core
in vec3 n;
in vec3 albedo;
out vec4 frag_colour;
void main() {
    float lit = abs(dot(normalize(n), normalize(vec3(0.4, 0.5, 0.8))));
    frag_colour = vec4(albedo * (0.25 + 0.75 * lit), 1.0);
}
"""


class OSMesaContext:
    """An OSMesa context made current on a ``width x height`` RGBA buffer, as pyrender's
    OSMesa platform makes it (core profile 3.3, 24 depth bits), and the function loader
    ``moderngl.init_context`` asks for: the ceiling on the context type facelib renders on
    by default on a machine without a GPU (PyOpenGL is not imported in this process)."""

    def __init__(self, width: int, height: int):
        import ctypes

        lib = ctypes.CDLL("libOSMesa.so.8")
        lib.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
        lib.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int),
                                                   ctypes.c_void_p]
        lib.OSMesaMakeCurrent.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint,
                                          ctypes.c_int, ctypes.c_int]
        lib.OSMesaGetProcAddress.restype = ctypes.c_void_p
        lib.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
        lib.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]
        # OSMESA_FORMAT RGBA, OSMESA_DEPTH_BITS 24, OSMESA_PROFILE core, version 3.3
        attributes = [0x22, 0x1908, 0x30, 24, 0x33, 0x34, 0x36, 3, 0x37, 3, 0]
        self.lib = lib
        self.context = lib.OSMesaCreateContextAttribs(
            (ctypes.c_int * len(attributes))(*attributes), None)
        if not self.context:
            raise RuntimeError("OSMesaCreateContextAttribs failed")
        self.buffer = (ctypes.c_ubyte * (width * height * 4))()
        if not lib.OSMesaMakeCurrent(self.context, self.buffer, 0x1401, width, height):
            raise RuntimeError("OSMesaMakeCurrent failed")

    def load_opengl_function(self, name: str) -> int:
        return self.lib.OSMesaGetProcAddress(name.encode()) or 0

    def release(self) -> None:
        if self.context:
            self.lib.OSMesaDestroyContext(self.context)
            self.context = None

    def __enter__(self) -> None:
        pass

    def __exit__(self, *args: object) -> None:
        pass


def face_shaders(look: Any) -> tuple[str, str]:
    """facelib's face.vert and face.frag as pyrender would compile them for a primitive with
    normals and colours only (the shader's plain branch: no hair cards, no skin factors or
    wrinkles), with the look's shading numbers: the face renderer's own per-pixel work, for
    the ceiling that shades as facelib does."""
    import re

    from facelib import data

    defines: dict[str, Any] = {"NORMAL_LOC": 1, "COLOR_0_LOC": 2, "MAX_DIRECTIONAL_LIGHTS": 4,
                               "LOOK_LIGHTS": min(len(look.lights), 4), "WRINKLE_BUMP": 0.0,
                               "WRINKLE_CREASE": 0.0, "SKIN_SCATTER": 0.0, "INST_M_LOC": 3}
    defines.update({k.upper(): float(v) for k, v in look.shading.items()})

    def load(name: str) -> str:
        text = Path(str(data.path(f"shaders/{name}"))).read_text()
        text = re.sub(r"#ifdef\s+(\w+)\s*$", lambda m: "#if 1" if m.group(1) in defines
                      else "#if 0", text, flags=re.MULTILINE)
        text = re.sub(r"#ifndef\s+(\w+)\s*$", lambda m: "#if 0" if m.group(1) in defines
                      else "#if 1", text, flags=re.MULTILINE)
        for key, value in defines.items():  # pyrender's substitution, plain text
            text = text.replace(key, str(value))
        return text

    return load("face.vert"), load("face.frag")


class Ceiling:
    """Renders ``(V, 3)`` vertices of a mesh to ``(height, width, 3) uint8``.

    ``triangles`` ``(F, 3)``, ``colours`` ``(V, 3)`` sRGB in [0, 1]; ``camera``: ``P`` and
    ``V`` (4 x 4 projection and view matrices, as lists), ``position`` (the camera's, 3);
    ``samples``: 4 (MSAA) or 0; ``backend``: ``"egl"`` or ``"osmesa"``; ``shading``:
    ``"lambert"`` (one light, no gamma: the minimal shader) or ``"face"`` (facelib's face
    shader, its plain branch, under the look's lights: :func:`face_shaders`).
    """

    def __init__(self, triangles: np.ndarray, colours: np.ndarray, camera: dict, *,
                 width: int, height: int, samples: int = 4, backend: str = "egl",
                 shading: str = "lambert"):
        import moderngl

        if backend == "osmesa":
            self._osmesa: OSMesaContext | None = OSMesaContext(width, height)
            moderngl.init_context(self._osmesa)
            self.ctx: Any = moderngl.get_context()
        else:
            self._osmesa = None
            self.ctx = moderngl.create_standalone_context(backend="egl")
        self.renderer = self.ctx.info["GL_RENDERER"]
        self.width, self.height = width, height
        self.triangles = np.asarray(triangles, np.int64)
        self.operator = normal_operator(len(colours), self.triangles)
        projection = np.asarray(camera["P"], np.float32).reshape(4, 4)
        view = np.asarray(camera["V"], np.float32).reshape(4, 4)
        if shading == "face":
            program, layout = self._face_program(camera, projection, view)
            self.data = np.zeros((len(colours), 10), np.float32)
            self.data[:, 6:9] = srgb_to_linear(np.asarray(colours, np.float32))
            self.data[:, 9] = 1.0
        else:
            program = self.ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
            program["mvp"].write((projection @ view).T.tobytes())
            layout = ("3f 3f 3f", "position", "normal", "colour")
            self.data = np.zeros((len(colours), 9), np.float32)
            self.data[:, 6:9] = colours
        self.vbo = self.ctx.buffer(reserve=self.data.nbytes, dynamic=True)
        ibo = self.ctx.buffer(self.triangles.astype(np.uint32).tobytes())
        self.vao = self.ctx.vertex_array(program, [(self.vbo, *layout)], ibo)
        size = (width, height)
        self.target = self.ctx.framebuffer(
            self.ctx.renderbuffer(size, samples=samples),
            self.ctx.depth_renderbuffer(size, samples=samples))
        self.resolved = self.ctx.framebuffer(self.ctx.renderbuffer(size)) if samples else None

    def _face_program(self, camera: dict, projection: np.ndarray,
                      view: np.ndarray) -> tuple[Any, tuple]:
        from facelib.rendering.scene import _light_pose, load_look

        look = load_look()
        vertex, fragment = face_shaders(look)
        program = self.ctx.program(vertex_shader=vertex, fragment_shader=fragment)
        values: dict[str, Any] = {
            "M": np.eye(4, dtype=np.float32), "V": view, "P": projection,
            "cam_pos": np.asarray(camera["position"], np.float32),
            "ambient_light": np.asarray(look.ambient, np.float32),
            "material.base_color_factor": np.ones(4, np.float32),
            "material.roughness_factor": float(look.material("skin")["roughness"]),
        }
        for i, light in enumerate(look.lights[:4]):
            pose = _light_pose(light["azimuth_deg"], light["elevation_deg"])
            values[f"directional_lights[{i}].color"] = np.asarray(light["color"], np.float32)
            values[f"directional_lights[{i}].intensity"] = float(light["intensity"])
            values[f"directional_lights[{i}].direction"] = (-pose[:3, 2]).astype(np.float32)
        for name, value in values.items():
            if name not in program:
                continue
            if isinstance(value, float):
                program[name].value = value
            else:  # moderngl takes matrices column by column
                program[name].write(np.ascontiguousarray(np.asarray(value).T, np.float32))
        return program, ("3f 3f 4f", "position", "normal", "color_0")

    def frame(self, vertices: np.ndarray) -> np.ndarray:
        vertices = np.asarray(vertices, np.float32)
        self.data[:, 0:3] = vertices
        self.data[:, 3:6] = vertex_normals(vertices, self.triangles, self.operator)
        self.vbo.write(self.data.tobytes())
        self.target.use()
        self.ctx.enable(self.ctx.DEPTH_TEST)
        self.ctx.clear(0.16, 0.17, 0.19, 1.0)
        self.vao.render()
        source = self.target
        if self.resolved is not None:
            self.ctx.copy_framebuffer(self.resolved, self.target)
            source = self.resolved
        raw = source.read(components=3)
        return np.frombuffer(raw, np.uint8).reshape(self.height, self.width, 3)[::-1]

    def close(self) -> None:
        self.ctx.release()
        if self._osmesa is not None:
            self._osmesa.release()


def serve(label: str, size: str, samples: int, frames: int, camera: dict) -> None:
    """The child process's loop (see the module's docs); ``camera``: the face renderer's
    ``P``, ``V`` and ``position``, and the ceiling's ``backend`` and ``shading``."""
    from render_speed import _bare_face, _stream

    from facelib.engine import load_face

    width, height = (int(v) for v in size.split("x"))
    face = _bare_face() if label == "bare" else load_face(None)
    vertices = face.deform(_stream(frames / 25.0, 25))
    backend, shading = camera.get("backend", "egl"), camera.get("shading", "lambert")
    ceiling = Ceiling(face.triangles, face.vertex_colors, camera, width=width, height=height,
                      samples=samples, backend=backend, shading=shading)
    print(f"{backend}, {shading} shading, {ceiling.renderer}", flush=True)
    ceiling.frame(vertices[0])
    for line in sys.stdin:
        command, _, argument = line.strip().partition(" ")
        if command == "run":
            start, start_main = time.process_time(), time.thread_time()
            for i in range(frames):
                ceiling.frame(vertices[i % len(vertices)])
            print((time.process_time() - start) / frames,
                  (time.thread_time() - start_main) / frames, flush=True)
        elif command == "image":
            import imageio.v3 as iio

            iio.imwrite(argument, ceiling.frame(vertices[0]))
            print("ok", flush=True)
        else:
            break
    ceiling.close()


if __name__ == "__main__":
    serve(sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), json.loads(sys.argv[5]))
