"""The learned observation model on exact, model-made landmark motion (no rendering): the
default head deformed by known FAPs, its MediaPipe-embedded vertices projected like a
640x480 camera, learned on one random stream and read back on another."""

from __future__ import annotations

import io

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.errors import DataError, ParameterError, TrackingWarning
from facelib.mpeg4 import ANGLE_UNIT, N_FAPS, FapStream
from facelib.tracking.embedding import default_head_embedding
from facelib.tracking.faps import measure_faps
from facelib.tracking.observation import (
    MODEL_FAPS,
    LandmarkRegion,
    default_observation,
    gaze_region,
    learn_observation,
    load_observation,
    pose_correction,
    save_observation,
    solve_observation,
)

FAPS = (3, 5, 12, 13, 19, 20, 31, 32, 23, 24)
PIXELS_PER_METRE = 1500.0


def random_stream(n: int, seed: int, *, turns: bool = True) -> np.ndarray:
    """``(n, 84)`` FAP values: FAPS at random, head turns up to 15 degrees, 4 neutral
    frames first."""
    rng = np.random.default_rng(seed)
    values = np.zeros((n, N_FAPS), np.float32)
    reach = {3: 500, 5: 200, 12: 400, 13: 400, 19: 900, 20: 900, 31: 150, 32: 150,
             23: np.radians(25) / ANGLE_UNIT, 24: np.radians(25) / ANGLE_UNIT}
    for fap_id in FAPS:
        low = 0.0 if fap_id == 3 else -1.0
        values[4:, fap_id - 1] = rng.uniform(low, 1.0, n - 4) * reach[fap_id]
    if turns:
        for fap_id, degrees in ((48, 8), (49, 15), (50, 6)):
            values[4:, fap_id - 1] = np.radians(rng.uniform(-degrees, degrees, n - 4)) / ANGLE_UNIT
    return values


def camera(values: np.ndarray) -> np.ndarray:
    """``(n, 478, 3)`` image coordinates of the default head's embedded landmarks."""
    face = default_face()
    moved = face.deform(FapStream(25.0, values))[:, default_head_embedding()]
    return np.asarray(moved, np.float64) * PIXELS_PER_METRE * [1, -1, -1] + [320, 240, 0]


@pytest.fixture(scope="module")
def learned():
    values = random_stream(400, seed=1)
    return learn_observation(camera(values), values, neutral=(0, 4), faps=FAPS,
                             components=40)


def test_model_reads_back_a_fresh_stream(learned):
    values = random_stream(120, seed=2)
    result = measure_faps(camera(values), fps=25, neutral=(0, 4), rig=learned, smooth=False,
                          relations=False, close_lips=False)
    for fap_id in FAPS:
        truth, found = values[4:, fap_id - 1], result.stream.values[4:, fap_id - 1]
        assert np.corrcoef(truth, found)[0, 1] > 0.97, fap_id
        gain = np.polyfit(truth, found, 1)[0]
        assert 0.85 < gain < 1.15, (fap_id, gain)
    yaw = result.stream.values[4:, 48] * ANGLE_UNIT
    assert np.abs(yaw - values[4:, 48] * ANGLE_UNIT).max() < np.radians(1.0)


def test_neutral_reads_zero_and_size_does_not_matter(learned):
    values = random_stream(40, seed=3)
    points = camera(values)
    near = (points - [320, 240, 0]) * 1.7 + [300, 250, 0]   # closer to the camera, shifted
    # the observation model alone: the closed-mouth state (lipclosure) would press the
    # default head's resting lips, which touch
    a = measure_faps(points, fps=25, neutral=(0, 4), rig=learned, smooth=False,
                     close_lips=False).stream
    b = measure_faps(near, fps=25, neutral=(0, 4), rig=learned, smooth=False,
                     close_lips=False).stream
    cols = np.asarray(FAPS) - 1
    np.testing.assert_allclose(a.values[:4, cols], 0.0, atol=1e-6)
    np.testing.assert_allclose(b.values[:, cols], a.values[:, cols], rtol=1e-4, atol=1e-3)


def test_solve_keeps_the_training_range(learned):
    big = np.full((1, 478, 2), 1e3)
    found = solve_observation(learned, big, {"ES": 0.1, "ENS": 0.1, "MNS": 0.05,
                                             "MW": 0.05, "IRISD": 0.01, "AU": 1e-5})
    assert (found >= learned.bounds[:, 0] - 1e-9).all()
    assert (found <= learned.bounds[:, 1] + 1e-9).all()


def test_save_and_load_round_trip(learned, tmp_path):
    path = save_observation(learned, tmp_path / "model.npz")
    back = load_observation(path)
    np.testing.assert_array_equal(back.faps, learned.faps)
    np.testing.assert_allclose(back.estimator, learned.estimator, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(back.bounds, learned.bounds, rtol=1e-6)
    assert back.pose is not None and learned.pose is not None
    np.testing.assert_allclose(back.pose, learned.pose, rtol=1e-6, atol=1e-9)
    (tmp_path / "bad.npz").write_bytes(b"not an npz")
    with pytest.raises(DataError):
        load_observation(tmp_path / "bad.npz")


def test_packaged_model():
    model = default_observation()
    assert tuple(model.faps) == MODEL_FAPS
    assert model.estimator.shape == (478, 2, len(MODEL_FAPS))
    assert np.isfinite(model.estimator).all()
    assert (model.bounds[:, 0] < model.bounds[:, 1]).all()
    assert model.pose is not None and model.pose.shape == (478, 2, 3)
    assert model.pose_bounds is not None
    assert (np.abs(model.pose_bounds) < np.radians(20)).all()   # corrections of a few degrees


@pytest.mark.slow  # learns a model
def test_a_region_reads_its_faps_from_its_landmarks_alone(learned):
    values = random_stream(400, seed=1)
    region = LandmarkRegion((23, 24), gaze_region().landmarks, 30)   # the eyes and outline
    model = learn_observation(camera(values), values, neutral=(0, 4), faps=FAPS,
                              components=40, regions=(region,))
    gaze = [FAPS.index(f) for f in (23, 24)]
    elsewhere = np.setdiff1d(np.arange(478), region.landmarks)
    assert not model.estimator[elsewhere][..., gaze].any()
    assert np.abs(model.estimator[list(region.landmarks)][..., gaze]).max() > 0
    others = [i for i in range(len(FAPS)) if i not in gaze]   # the rest as learned before
    np.testing.assert_allclose(model.estimator[..., others], learned.estimator[..., others])
    fresh = random_stream(120, seed=2)
    found = measure_faps(camera(fresh), fps=25, neutral=(0, 4), rig=model, smooth=False,
                         relations=False, close_lips=False).stream.values
    for fap_id in (23, 24):
        assert np.corrcoef(fresh[4:, fap_id - 1], found[4:, fap_id - 1])[0, 1] > 0.97
    points = camera(values)
    with pytest.raises(ParameterError, match=r"region FAPs \(25,\) must be among faps"):
        learn_observation(points, values, neutral=(0, 4), faps=FAPS, components=40,
                          regions=(LandmarkRegion((25,), (468, 473), 2),))
    for landmarks, components in (((468, 468), 2), ((468, -1), 2), ((468, 478), 2),
                                  ((468, 473), 5), ((468, 473), 0)):
        with pytest.raises(ParameterError, match=r"region (landmarks|components)"):
            learn_observation(points, values, neutral=(0, 4), faps=FAPS, components=40,
                              regions=(LandmarkRegion((23,), landmarks, components),))


def test_packaged_gaze_reads_no_expression_landmarks():
    model, region = default_observation(), gaze_region()
    gaze = [MODEL_FAPS.index(f) for f in region.faps]
    elsewhere = np.setdiff1d(np.arange(478), region.landmarks)
    assert not model.estimator[elsewhere][..., gaze].any()   # lips and brows: nothing


def test_pose_correction_learns_a_fit_error():
    # the rigid fit's stable points are moved by an expression (the nostrils lift with
    # FAP 61/62 here), so the fit reads a nod: the model learns it from the landmark motion
    rng = np.random.default_rng(5)
    values = np.zeros((300, N_FAPS), np.float32)
    values[4:, 60] = values[4:, 61] = rng.uniform(0, 300, 296)      # stretch the nose wings
    values[4:, 2] = rng.uniform(0, 400, 296)                        # open_jaw
    values[4:, 47] = np.radians(rng.uniform(-8, 8, 296)) / ANGLE_UNIT   # pitch
    points = camera(values)
    model = learn_observation(points, values, neutral=(0, 4), faps=(3, 61, 62), components=20)
    plain = measure_faps(points, fps=25, neutral=(0, 4), rig=learned_without_pose(model),
                         smooth=False).stream.values[4:, 47]
    fixed = measure_faps(points, fps=25, neutral=(0, 4), rig=model,
                         smooth=False).stream.values[4:, 47]
    before = np.abs(plain - values[4:, 47]).mean() * ANGLE_UNIT
    after = np.abs(fixed - values[4:, 47]).mean() * ANGLE_UNIT
    assert before > np.radians(0.1)      # the fit alone is fooled (0.23 degrees)
    assert after < 0.1 * before


def learned_without_pose(model):
    return type(model)(model.faps, model.estimator, model.bounds)


def test_observed_needs_mediapipe_in_3d():
    with pytest.raises(ParameterError):
        measure_faps(np.zeros((3, 478, 2)), fps=25, rig="observed")
    with pytest.raises(ParameterError):
        learn_observation(camera(random_stream(6, seed=4)), random_stream(6, seed=4),
                          neutral=(0, 4), components=10)


def test_load_names_the_arrays_that_disagree(tmp_path):
    faps, estimator = np.array([3, 4]), np.zeros((478, 2, 2))
    base = {"faps": faps, "estimator": estimator}
    cases = {"bounds.npz": {**base, "bounds": np.zeros((3, 2))},  # 3 rows for 2 FAPs
             "pose.npz": {**base, "bounds": np.zeros((2, 2)),  # pose without pose_bounds
                          "pose": np.ones((478, 2, 3))}}
    for name, arrays in cases.items():
        np.savez(tmp_path / name, **arrays)
        with pytest.raises(DataError, match=rf"{name}: observation model arrays disagree "
                                            r"in shape: faps \(2,\), estimator \(478, 2, 2\)"):
            load_observation(tmp_path / name)
    np.savez(tmp_path / "good.npz", faps=faps, estimator=estimator, bounds=np.zeros((2, 2)),
             pose=np.ones((478, 2, 3)), pose_bounds=np.zeros((3, 2)))
    assert load_observation(tmp_path / "good.npz").pose is not None


def test_learn_refuses_values_of_other_frames():
    values = random_stream(60, seed=3)
    with pytest.raises(ParameterError, match=r"values must be \(60, 84\).* got \(59, 84\)"):
        learn_observation(camera(values), values[1:], neutral=(0, 4), faps=FAPS,
                          components=10)


def test_learn_refuses_fap_ids_outside_the_table():
    values = random_stream(60, seed=3)
    for bad in ((0, 3), (3, 85), (3, 3)):  # 0 read column -1 (FAP 84) without a word
        with pytest.raises(ParameterError, match=r"faps must be distinct FAP ids in 1-84"):
            learn_observation(camera(values), values, neutral=(0, 4), faps=bad,
                              components=10)


def test_solve_names_displacements_of_another_layout(learned):
    fapu = {"ES": 1.0, "MNS": 1.0, "MW": 1.0, "ENS": 1.0, "IRISD": 1.0}
    wrong = np.zeros((5, 468, 2))  # MediaPipe without the irises: the model reads 478
    with pytest.raises(ParameterError, match=r"\(n, 478, 2\).* got \(5, 468, 2\)"):
        solve_observation(learned, wrong, fapu)
    with pytest.raises(ParameterError, match=r"\(n, 478, 2\).* got \(5, 468, 2\)"):
        pose_correction(learned, wrong, fapu)


def test_a_bad_stream_is_not_blamed_on_the_packaged_model():
    with pytest.raises(DataError) as caught:
        load_observation(io.BytesIO(b"not an npz"))
    assert "observation_mediapipe" not in str(caught.value)
    assert str(caught.value).startswith("<stream>: not an observation model")


@pytest.mark.parametrize("rig", ["observed", "default", None])
def test_long_tracks_are_measured_in_chunks_with_the_same_result(rig, monkeypatch):
    """Chunks of frames share the neutral face: how a track is cut changes no value."""
    from facelib.tracking import faps

    values = random_stream(40, seed=5)
    landmarks = camera(values)
    landmarks[17:20] = np.nan  # a lost stretch across a chunk boundary
    with pytest.warns(TrackingWarning, match="no face in frames 17-19"):
        whole = measure_faps(landmarks, fps=25.0, neutral=(0, 4), rig=rig)
    monkeypatch.setattr(faps, "_CHUNK_FRAMES", 7)
    with pytest.warns(TrackingWarning, match="no face in frames 17-19"):
        cut = measure_faps(landmarks, fps=25.0, neutral=(0, 4), rig=rig)
    np.testing.assert_allclose(cut.stream.values, whole.stream.values, atol=1e-9)
    np.testing.assert_array_equal(cut.stream.mask, whole.stream.mask)
    np.testing.assert_allclose(cut.pose.rotation, whole.pose.rotation, atol=1e-12)
    assert cut.filled_frames == whole.filled_frames == (17, 18, 19)
    assert whole.stream.values[:, 2].std() > 10  # the track moves: open_jaw varies
