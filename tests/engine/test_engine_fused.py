"""The compiled deformation kernel (facelib.engine.fused, numba) against the numpy path.

Both run on streams that move every step: the operator's product, eyelids, eyeballs
(turns and thrust), the jaw (open, thrust, shift) and the head (pitch, yaw, roll, with the
neck's partial turn), on the default head and on a character with another mesh, and on a
face whose lips take another deformer. The kernel must equal the numpy path to float32
rounding, and a stream deformed in chunks must be bit for bit the stream deformed at once.
"""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import default_face, fused, load_face
from facelib.engine import face as face_module
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap_table

pytest.importorskip("numba")

# a stream moves a FAP in this share of its frames, so that some frames hold every step
# still and the kernel's per-frame choices are tried both ways
MOVING = 0.7


def _stream(n: int = 48, *, seed: int = 5) -> FapStream:
    """Every FAP that moves a mesh, as smooth random curves, each still in some frames."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 25.0
    values = np.zeros((n, 84), np.float32)
    for f in fap_table():
        if f.id in (1, 2):
            continue
        amp = 15000.0 if f.kind == "rotation" else 250.0
        curve = amp * np.sin(2 * np.pi * rng.uniform(0.3, 2.0) * t + rng.uniform(0, 6.3))
        values[:, f.index] = np.where(rng.random(n) < MOVING, curve, 0.0)
    values[:, 2] = np.abs(values[:, 2])  # the jaw opens
    values[:, 18:22] = np.abs(values[:, 18:22])  # the lids close
    return FapStream(25.0, values, values != 0)


def _faces():
    yield "default", default_face()
    yield "ada", load_face("ada")
    yield "soffd lips", load_face(None, deformers={"lips": "soffd"})


@pytest.fixture(scope="module")
def faces():
    if not fused.available():
        pytest.skip("the kernel is turned off (FACELIB_JIT=0)")
    return dict(_faces())


@pytest.fixture
def short_streams_too(monkeypatch):
    """Short streams take the kernel too (normally from about 1,000 frames)."""
    monkeypatch.setattr(face_module, "_KERNEL_FROM", 0)


@pytest.mark.parametrize("name", ["default", "ada", "soffd lips"])
def test_kernel_equals_the_numpy_path_to_float32_rounding(faces, short_streams_too,
                                                           name: str) -> None:
    face = faces[name]
    stream = _stream()
    assert face._kernel_for(stream.n_frames)  # no exact per-frame step: the kernel runs
    values = np.asarray(stream.values, np.float32)
    kernel = face.deform(stream)
    reference = face._deform_numpy(values)
    assert kernel.shape == reference.shape and kernel.dtype == np.float32
    size = float(np.ptp(face.vertices, axis=0).max())
    # measured: 6e-8 m on a 0.79 m default head (one or two float32 rounding steps)
    assert np.abs(kernel - reference).max() <= 1e-6 * size
    # every step moved the mesh far beyond that bound
    moved = np.abs(reference - face.vertices).max(axis=2)
    for part in ("skin", "eye_l", "eye_r", "teeth_lower", "tongue"):
        assert moved[:, face.parts[part].vertex_ids].max() > 1000 * 1e-6 * size, part


def test_still_frames_are_the_rest_shape(faces, short_streams_too) -> None:
    face = faces["default"]
    values = np.zeros((3, 84), np.float32)
    out = face.deform(FapStream(25.0, values, values != 0))
    assert np.array_equal(out, np.broadcast_to(face.vertices, out.shape))


def test_chunks_are_bit_for_bit_the_whole_stream(faces, short_streams_too) -> None:
    face = faces["default"]
    stream = _stream(53)
    whole = face.deform(stream)
    for frames in (1, 7, 32):
        stacked = np.concatenate([b for _, b in face.deform_chunks(stream, frames=frames)])
        assert np.array_equal(stacked, whole), frames


def test_short_streams_and_single_frames_take_the_numpy_path(faces) -> None:
    face = faces["default"]
    assert not face._kernel_for(500)  # 500 frames: loading the kernel would cost more
    assert face._kernel_for(1500)
    stream = _stream(5)
    values = np.asarray(stream.values, np.float32)
    assert np.array_equal(face.deform(stream), face._deform_numpy(values))
    assert np.array_equal(face.deform_frame(values[3]), face._deform_numpy(values[3:4])[0])


def test_sines_and_cosines_are_those_of_numpy() -> None:
    from numba import njit

    from facelib.engine.fused_kernel import _sincos

    @njit
    def both(x):  # type: ignore[no-untyped-def]
        s, c = np.empty_like(x), np.empty_like(x)
        for i in range(x.size):
            s[i], c[i] = _sincos(x[i])
        return s, c

    x = np.linspace(-40.0, 40.0, 200001)
    s, c = both(x)
    assert np.abs(s - np.sin(x)).max() < 1e-13
    assert np.abs(c - np.cos(x)).max() < 1e-13
