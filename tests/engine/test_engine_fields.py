"""The learned displacement-field deformer (issue 14, item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib import engine
from facelib.engine.deformers.fields import field_weights
from facelib.errors import FaceModelError
from facelib.mpeg4.tables import fap


def test_field_is_scaled_so_the_point_moves_one_fapu_along_the_direction():
    d = np.array([[0.0, 0.004, -0.003], [0.0, 0.002, 0.0], [0.001, 0.0, 0.0]])
    w = field_weights(d, 0, np.array([0.0, 1.0, 0.0]), 1e-5)
    assert w[0] @ [0, 1, 0] == pytest.approx(1e-5)
    assert w[0, 2] == pytest.approx(-0.75e-5)  # the depth comes along, in proportion
    np.testing.assert_allclose(w / w[0, 1], d / d[0, 1])
    with pytest.raises(FaceModelError, match="along the FAP"):
        field_weights(d, 2, np.array([0.0, 1.0, 0.0]), 1e-5, name="sideways")


def test_default_head_records_which_deformer_drives_each_fap():
    face = engine.default_face()
    kinds = face.fap_deformers
    assert kinds["raise_l_cornerlip"] == "field"
    assert kinds["lift_r_cheek"] == "field"
    assert kinds["lower_t_midlip"] == "rbf"  # lip heights stay with the RBF of the lips
    assert kinds["close_t_l_eyelid"] == "eyelid"
    field_faps = {r.field_fap for r in face.regions if r.deformer == "field"}
    assert field_faps == {k for k, v in kinds.items() if v == "field"}


def test_smile_field_has_depth_and_moves_the_cheek():
    """AU12 from the target: the corner goes up *and back*; the cheek above it rises."""
    face = engine.default_face()
    values = np.zeros(84, np.float32)
    values[fap("raise_l_cornerlip").index] = 400
    moved = face.deform_frame(values) - face.vertices
    corner = moved[face.feature_points["2.4"]]
    assert corner[1] == pytest.approx(400 * face.fapu["MNS"], rel=1e-4)
    assert corner[2] < -0.002  # back by more than 2 mm
    cheek = moved[face.feature_points["5.3"]]
    assert cheek[1] > 0.001
    right = moved[face.feature_points["2.5"]]
    assert np.abs(right).max() < 1e-4  # the left smile leaves the right corner alone


def test_a_field_region_must_contain_its_feature_point(tmp_path):
    import json
    import shutil

    from facelib.engine.definition import _default_path

    src = _default_path()
    shutil.copy(src.parent / "default_head.npz", tmp_path / "default_head.npz")
    doc = json.loads(src.read_text())
    for region in doc["regions"]:
        if region["deformer"] == "field" and region["params"]["fap"] != "depress_chin":
            region["params"]["fap"] = "depress_chin"  # a FAP on another feature point
            break
    (tmp_path / "head.json").write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="field FAP depress_chin moves"):
        engine.load_face(tmp_path / "head.json")
