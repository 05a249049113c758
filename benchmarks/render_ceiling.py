"""The ceiling for ``render_speed.py``: a minimal moderngl renderer of the same mesh.

One vertex buffer (position, normal, colour) rewritten every frame with the deformed
vertices and their smooth normals (the same ``vertex_normals`` as the face renderer), one
draw call of every triangle (no face culling), a one-light Lambert shader, a 4x multisampled
framebuffer resolved and read back as RGB, on moderngl's EGL context: Mesa's llvmpipe, the
same software rasteriser pyrender uses through OSMesa or EGL here. What a renderer of this
mesh at this size cannot do much better than; pyrender's frame time is given as a ratio to
it (issue 30, item 9).

moderngl is not a dependency of facelib: ``pip install moderngl`` for this benchmark only.
It runs in a child process (``python render_ceiling.py FACE WIDTHxHEIGHT SAMPLES FRAMES MVP``,
started by ``render_speed.py``): two OpenGL libraries (PyOpenGL's OSMesa and moderngl's EGL)
in one process share Mesa's dispatch and draw into each other's contexts. The child reads a
command a line from stdin: ``run`` (render the frames, answer ``cpu main`` seconds a frame),
``image PATH`` (write the first frame), ``quit``.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import numpy as np

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


class Ceiling:
    """Renders ``(V, 3)`` vertices of a mesh to ``(height, width, 3) uint8``.

    ``triangles`` ``(F, 3)``, ``colours`` ``(V, 3)`` in [0, 1], ``mvp`` ``(4, 4)`` the
    projection times view matrix; ``samples``: 4 (MSAA) or 0.
    """

    def __init__(self, triangles: np.ndarray, colours: np.ndarray, mvp: np.ndarray, *,
                 width: int, height: int, samples: int = 4, backend: str = "egl"):
        import moderngl

        if backend == "osmesa":
            self._osmesa = OSMesaContext(width, height)
            moderngl.init_context(self._osmesa)
            self.ctx: Any = moderngl.get_context()
        else:
            self.ctx = moderngl.create_standalone_context(backend="egl")
        self.renderer = self.ctx.info["GL_RENDERER"]
        self.width, self.height = width, height
        self.triangles = np.asarray(triangles, np.int64)
        self.operator = normal_operator(len(colours), self.triangles)
        self.data = np.zeros((len(colours), 9), np.float32)
        self.data[:, 6:9] = colours
        program = self.ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
        program["mvp"].write(np.asarray(mvp, np.float32).T.tobytes())
        self.vbo = self.ctx.buffer(reserve=self.data.nbytes, dynamic=True)
        ibo = self.ctx.buffer(self.triangles.astype(np.uint32).tobytes())
        self.vao = self.ctx.vertex_array(
            program, [(self.vbo, "3f 3f 3f", "position", "normal", "colour")], ibo)
        size = (width, height)
        self.target = self.ctx.framebuffer(
            self.ctx.renderbuffer(size, samples=samples),
            self.ctx.depth_renderbuffer(size, samples=samples))
        self.resolved = self.ctx.framebuffer(self.ctx.renderbuffer(size)) if samples else None

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
        if getattr(self, "_osmesa", None) is not None:
            self._osmesa.release()


def serve(label: str, size: str, samples: int, frames: int, mvp: np.ndarray, *,
          backend: str = "egl") -> None:
    """The child process's loop (see the module's docs); ``mvp`` ``(4, 4)`` the face
    renderer's projection times view matrix."""
    from render_speed import _bare_face, _stream

    from facelib.engine import load_face

    width, height = (int(v) for v in size.split("x"))
    face = _bare_face() if label == "bare" else load_face(None)
    vertices = face.deform(_stream(frames / 25.0, 25))
    ceiling = Ceiling(face.triangles, face.vertex_colors, mvp, width=width, height=height,
                      samples=samples, backend=backend)
    print(f"{backend}/{ceiling.renderer}", flush=True)
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
    serve(sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]),
          np.array([float(v) for v in sys.argv[5].split(",")]).reshape(4, 4),
          backend=sys.argv[6] if len(sys.argv) > 6 else "egl")
