"""Face.deform_chunks: the chunked form of deform, for long streams."""

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream


def test_chunks_stack_to_deform_within_float32_rounding():
    face = default_face()
    rng = np.random.default_rng(3)
    values = np.zeros((37, 84), np.float32)
    values[:, [2, 3, 4, 18, 47]] = rng.normal(0, 200, (37, 5))
    stream = FapStream(25, values)
    whole = face.deform(stream)
    parts = list(face.deform_chunks(stream, frames=10))
    assert [first for first, _ in parts] == [0, 10, 20, 30]
    assert max(block.shape[0] for _, block in parts) == 10
    stacked = np.concatenate([b for _, b in parts])
    assert stacked.shape == whole.shape and stacked.dtype == whole.dtype
    # the BLAS product may sum in another order for another block size: a few ulps of the
    # largest coordinate at most (measured: 1 ulp, 7.5e-9 m, on some machines; 0 on others)
    ulp = np.spacing(np.abs(whole).max())
    np.testing.assert_allclose(stacked, whole, rtol=0, atol=4 * ulp)
    moved = np.abs(whole - face.vertices).max()
    assert moved > 1000 * ulp  # the FAPs moved the mesh far beyond that tolerance
    again = list(face.deform_chunks(stream, frames=10))  # deterministic, block by block
    assert all(np.array_equal(a, b) for (_, a), (_, b) in zip(parts, again, strict=True))


def test_chunk_size_is_checked():
    face = default_face()
    with pytest.raises(ParameterError):
        list(face.deform_chunks(FapStream(25, np.zeros((3, 84), np.float32)), frames=0))
