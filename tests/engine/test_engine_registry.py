"""The deformer registry: names, parameters, per-region overrides, custom deformers."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import Face, load_face
from facelib.engine.deformers import Deformer, RegionSetup, deformer, deformer_names
from facelib.errors import FaceModelError, ParameterError


@pytest.fixture(scope="module")
def face() -> Face:
    return load_face()


def test_builtin_names_and_alias() -> None:
    names = deformer_names()
    assert names[:3] == ("raised_cosine", "rbf", "weights")
    assert deformer("cosine") is deformer("raised_cosine")
    with pytest.raises(FaceModelError, match="unknown deformer 'spline'"):
        deformer("spline")


def test_definition_names_the_deformer_per_region(face: Face) -> None:
    kinds = {r.name: (r.deformer, r.group) for r in face.regions}
    assert kinds["upper_lip"] == ("rbf", "lips") and kinds["lower_lip"] == ("rbf", "lips")
    assert kinds["chin"] == ("raised_cosine", "")  # the definition's "cosine", by its alias
    assert kinds["upper_lid_l"][0] == "eyelid"


def test_same_deformer_override_keeps_the_operator(face: Face) -> None:
    same = load_face(deformers={"lips": "rbf", "chin": {"deformer": "raised_cosine"}})
    assert (same.operator != face.operator).nnz == 0


def test_override_by_group_and_name(face: Face) -> None:
    other = load_face(deformers={"lips": {"deformer": "rbf", "kernel": "thin_plate_spline"},
                                 "lower_lip": "rbf"})
    kinds = {r.name: dict(r.params) for r in other.regions}
    assert kinds["upper_lip"] == {"kernel": "thin_plate_spline"}
    assert kinds["lower_lip"] == {}  # the region's own key wins over its group
    diff = abs(other.operator - face.operator)
    upper = face.regions[[r.name for r in face.regions].index("upper_lip")].vertices
    cols = np.unique(diff.nonzero()[1]) // 3
    assert cols.size and set(cols.tolist()) <= set(upper.tolist())


def test_bad_overrides_are_named() -> None:
    with pytest.raises(ParameterError, match="'mouth' names no region or group"):
        load_face(deformers={"mouth": "rbf"})
    with pytest.raises(FaceModelError, match="no parameter 'kernal'"):
        load_face(deformers={"lips": {"deformer": "rbf", "kernal": "gaussian"}})
    with pytest.raises(FaceModelError, match="kernel 'spline' is unknown"):
        load_face(deformers={"lips": {"deformer": "rbf", "kernel": "spline"}})
    with pytest.raises(ParameterError, match="eyelid"):
        load_face(deformers={"upper_lid_l": "rbf"})
    with pytest.raises(ParameterError, match="must be a deformer name"):
        load_face(deformers={"lips": 3})  # type: ignore[dict-item]


def test_custom_deformer_object(face: Face) -> None:
    """An application's own deformer: lips move rigidly with their first control."""

    def first_control(setup: RegionSetup) -> np.ndarray:
        w = np.zeros((setup.members.size, setup.controls.size))
        w[:, 0] = 1.0
        return w

    rigid = Deformer("first_control", first_control, summary="test")
    custom = load_face(deformers={"upper_lip": rigid})
    f = np.zeros(84, np.float32)
    fp = custom.feature_points["2.2"]  # first control of upper_lip, moved by FAP 4
    f[3] = 100.0
    moved = custom.deform_frame(f) - custom.vertices
    members = next(r for r in custom.regions if r.name == "upper_lip").vertices
    np.testing.assert_allclose(moved[members], np.broadcast_to(moved[fp], (members.size, 3)),
                               atol=1e-7)
    assert np.abs(moved[fp]).max() > 0


def test_definition_params_and_group_keys(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import json

    from head_files import copy_head_files

    doc = copy_head_files(tmp_path)
    lip = next(r for r in doc["regions"] if r["name"] == "upper_lip")
    lip["deformer"] = "soffd"
    lip["params"] = {"local": 3.0}
    path = tmp_path / "face.json"
    path.write_text(json.dumps(doc))
    face = load_face(path)
    region = next(r for r in face.regions if r.name == "upper_lip")
    assert region.deformer == "soffd" and dict(region.params) == {"local": 3.0}
    lip["params"] = [1]
    path.write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="params must be an object"):
        load_face(path)
    lip["params"] = {"mode": "sometimes"}
    path.write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="mode must be"):
        load_face(path)
