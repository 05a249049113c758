"""The brows' image shifts: known brow motion rendered on the default head comes back from
the frames, head turns alone move nothing; the observation model's image part learns
from them what the landmarks do not show."""

from __future__ import annotations

import importlib.util
import io

import numpy as np
import pytest
from test_observation import camera, random_stream

from facelib.errors import ParameterError
from facelib.mpeg4 import ANGLE_UNIT, FAPU_SCALE, N_FAPS, FapStream
from facelib.tracking.faps import measure_faps
from facelib.tracking.observation import (
    learn_observation,
    load_observation,
    save_observation,
    solve_observation,
)

NEUTRAL = 4


def brow_stream(n: int) -> FapStream:
    """Neutral, then both inner brows raised to 120 and back, then squeezed by 120, then a
    head turn of 15 degrees yaw and 8 pitch with the brows at rest."""
    values = np.zeros((n, N_FAPS), np.float32)
    quarter = (n - NEUTRAL) // 3
    bump = 120 * np.sin(np.linspace(0, np.pi, quarter))
    raise_at = slice(NEUTRAL, NEUTRAL + quarter)
    squeeze_at = slice(NEUTRAL + quarter, NEUTRAL + 2 * quarter)
    values[raise_at, 30] = values[raise_at, 31] = bump
    values[squeeze_at, 36] = values[squeeze_at, 37] = bump
    turn = np.sin(np.linspace(0, np.pi, n - NEUTRAL - 2 * quarter))
    values[NEUTRAL + 2 * quarter:, 48] = np.radians(15) * turn / ANGLE_UNIT
    values[NEUTRAL + 2 * quarter:, 47] = np.radians(8) * turn / ANGLE_UNIT
    return FapStream(25.0, values)


@pytest.fixture(scope="module")
def rendered():
    """The stream, landmarks, brow shifts and frames of :func:`brow_stream` on the default
    head."""
    if importlib.util.find_spec("pyrender") is None:  # importing it would pick OpenGL
        pytest.skip("needs the render extra")
    pytest.importorskip("mediapipe")
    from facelib.engine import default_face
    from facelib.rendering import FaceRenderer, iter_frames
    from facelib.tracking.browimage import track_brows
    from facelib.tracking.mediapipe import FaceMeshTracker
    from facelib.tracking.observation import default_observation

    stream = brow_stream(64)
    face = default_face()
    with FaceRenderer(face, width=640, height=480, framing="head") as renderer, \
            FaceMeshTracker(video=True, max_faces=1) as tracker:
        frames = list(iter_frames(renderer, face, stream))
        landmarks = np.stack([tracker.detect(f).points for f in frames])
    brows = track_brows(lambda: iter(frames), landmarks, neutral=(0, NEUTRAL),
                        model=default_observation())
    return stream, landmarks, brows, frames


@pytest.mark.render
def test_a_rendered_brow_raise_comes_back(rendered):
    stream, landmarks, brows, _frames = rendered
    # the neutral frames: about a pixel (0.007 with the hair's fringe near the patches), the
    # first, which MediaPipe's video mode reads without a previous frame, under 1.5 (0.018)
    assert np.abs(brows[1:NEUTRAL]).max() < 0.015
    assert np.abs(brows[0]).max() < 0.025
    raised = stream.values[:, 30]
    for up in (1, 3):  # left and right brow
        assert np.corrcoef(brows[:24, up], raised[:24])[0, 1] > 0.97
    # the mesh lifts the inner brow's feature point by FAP 31 x ENS0 / 1024 (the user's
    # ENS0 and ES0 measured on the landmarks, in pixels); the patch, which also covers the
    # skin above the brow, moves by a half to all of that (measured: two thirds)
    fapu = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL)).fapu
    peak = int(np.argmax(raised))
    point = raised[peak] * fapu["ENS"] / (fapu["ES"] * FAPU_SCALE)
    assert (0.5 * point < brows[peak, [1, 3]]).all() and (brows[peak, [1, 3]] < point).all()


@pytest.mark.render
def test_a_squeeze_moves_the_brows_toward_each_other_and_down(rendered):
    stream, _, brows, _ = rendered
    squeezed = int(np.argmax(stream.values[:, 36]))
    # across = toward the face's left (+x): the left brow moves right (-), the right left (+)
    assert brows[squeezed, 0] < -0.05 and brows[squeezed, 2] > 0.05
    assert (brows[squeezed, [1, 3]] < -0.04).all()


@pytest.mark.render
def test_a_head_turn_alone_reads_as_little_raise(rendered):
    stream, _, brows, _ = rendered
    turned = np.abs(stream.values[:, 48]) > 0
    assert np.radians(14) < stream.values[turned, 48].max() * ANGLE_UNIT
    raise_peak = brows[:24, [1, 3]].max()
    # 15 degrees of yaw with 8 of pitch shift the patches by under 40 % of a raise of 120
    # (measured: a third; the across shift drifts more)
    assert np.abs(brows[turned][:, [1, 3]]).max() < 0.4 * raise_peak


@pytest.mark.render
def test_the_packaged_model_reads_the_brows_with_them(rendered):
    stream, landmarks, brows, _frames = rendered
    found = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL), brows=brows).stream.values
    plain = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL)).stream.values
    truth = stream.values
    for col in (30, 31):  # inner brows: the image shifts make the difference
        assert np.corrcoef(found[:, col], truth[:, col])[0, 1] > 0.9
        assert np.corrcoef(found[:, col], truth[:, col])[0, 1] > np.corrcoef(
            plain[:, col], truth[:, col])[0, 1] + 0.05
    turned = truth[:, 48] != 0  # the turn's angle terms keep the brows nearly still
    assert np.abs(found[turned][:, [30, 31]]).max() < 0.3 * 120


def brow_signal(values: np.ndarray) -> np.ndarray:
    """``(n, 4)`` made-up image shifts that carry FAPs 31/32 (and nothing the landmarks
    show), with a little noise."""
    rng = np.random.default_rng(4)
    out = np.zeros((len(values), 4))
    out[:, 1], out[:, 3] = values[:, 30] * 4e-4, values[:, 31] * 4e-4
    return out + rng.normal(0, 1e-3, out.shape)


@pytest.mark.slow  # learns from images
def test_the_image_part_learns_what_the_landmarks_do_not_show():
    values = random_stream(400, seed=8)
    hidden = values.copy()
    hidden[:, 30:32] = 0  # the landmarks do not see the inner brows move
    landmarks = camera(hidden)
    model = learn_observation(landmarks, values, neutral=(0, 4), components=40,
                              faps=(3, 31, 32), image_faps=(31, 32),
                              brows=brow_signal(values))
    fresh = random_stream(200, seed=9)
    seen = camera(np.where(np.isin(np.arange(N_FAPS), [30, 31]), 0, fresh))
    with_brows = measure_faps(seen, fps=25, neutral=(0, 4), rig=model, smooth=False,
                              brows=brow_signal(fresh)).stream.values
    without = measure_faps(seen, fps=25, neutral=(0, 4), rig=model,
                           smooth=False).stream.values
    for col in (30, 31):
        assert np.corrcoef(with_brows[4:, col], fresh[4:, col])[0, 1] > 0.98
        assert abs(np.corrcoef(without[4:, col], fresh[4:, col])[0, 1]) < 0.3
    again = load_observation(_saved(model))
    assert again.image_faps is not None and list(again.image_faps) == [31, 32]
    frame_motion = np.zeros((2, 478, 2))
    fapu = {"ES": 60 / FAPU_SCALE, "ENS": 50 / FAPU_SCALE, "MNS": 30 / FAPU_SCALE,
            "MW": 50 / FAPU_SCALE, "IRISD": 12 / FAPU_SCALE}
    found = solve_observation(again, frame_motion, fapu, brows=np.zeros((2, 4)),
                              angles=np.zeros((2, 3)))
    np.testing.assert_allclose(found, 0, atol=1e-9)


def _saved(model) -> io.BytesIO:
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as scratch:
        path = save_observation(model, Path(scratch) / "m.npz")
        return io.BytesIO(path.read_bytes())


def test_brows_of_another_length_are_named():
    landmarks = camera(random_stream(10, seed=1))
    with pytest.raises(ParameterError, match=r"brows must be \(10, 4\)"):
        measure_faps(landmarks, fps=25, brows=np.zeros((9, 4)))
    with pytest.raises(ParameterError, match="brows must be"):
        learn_observation(landmarks, random_stream(10, seed=1), components=3,
                          brows=np.full((10, 4), np.nan))


@pytest.mark.render
def test_live_faps_read_the_brows_as_the_recorded_path(rendered):
    from facelib.tracking.live import LiveFaps

    _stream, landmarks, brows, frames = rendered
    live = LiveFaps(fps=25, neutral_frames=NEUTRAL, smooth=False)
    rows = [live.push(points, image) for points, image in zip(landmarks, frames, strict=True)]
    recorded = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL), smooth=False,
                            brows=brows).stream.values
    np.testing.assert_allclose(np.stack(rows[NEUTRAL:]), recorded[NEUTRAL:], atol=1e-9)
    np.testing.assert_allclose(live.neutral_brows, brows[:NEUTRAL], atol=1e-12)


@pytest.mark.render
def test_chunks_of_frames_change_no_shift(rendered, monkeypatch):
    from facelib.tracking import browimage
    from facelib.tracking.observation import default_observation

    _, landmarks, brows, frames = rendered
    monkeypatch.setattr(browimage, "_CHUNK_FRAMES", 7)
    again = browimage.track_brows(lambda: iter(frames), landmarks, neutral=(0, NEUTRAL),
                                  model=default_observation())
    np.testing.assert_allclose(again, brows, atol=1e-12)
    with pytest.raises(browimage.TrackingError, match="more images than the 10"):
        browimage.brow_features(frames[:12], landmarks[:10], _patches(landmarks, frames),
                                _neutral(landmarks), default_observation())


def _neutral(landmarks):
    from facelib.tracking.headframe import neutral_face
    from facelib.tracking.layouts import landmark_layout

    return neutral_face(landmarks, layout=landmark_layout("mediapipe"), span=slice(0, NEUTRAL))


def _patches(landmarks, frames):
    from facelib.tracking.browimage import brow_patches
    from facelib.tracking.observation import default_observation

    return brow_patches(frames[:NEUTRAL], landmarks[:NEUTRAL], _neutral(landmarks),
                        default_observation())
