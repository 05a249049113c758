"""Loading and validating face definitions: every broken item raises FaceModelError."""

from __future__ import annotations

import json
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from head_files import copy_head_files

from facelib.engine import load_face, required_feature_points
from facelib.errors import FaceModelError

HEAD = Path(str(resources.files("facelib.data").joinpath("head")))


def broken(tmp_path: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    doc = copy_head_files(tmp_path)
    edit(doc)
    out = tmp_path / "face.json"
    out.write_text(json.dumps(doc))
    return out


def test_default_and_explicit_path_agree(tmp_path: Path) -> None:
    a = load_face()
    b = load_face(broken(tmp_path, lambda d: None))
    np.testing.assert_array_equal(a.vertices, b.vertices)
    assert dict(a.feature_points) == dict(b.feature_points)
    assert set(required_feature_points()) <= set(a.feature_points)
    assert "7.1" not in required_feature_points()


def _del_fp(d: dict) -> None:
    del d["feature_points"]["2.3"]


def _fp_range(d: dict) -> None:
    d["feature_points"]["4.1"] = 10**7


def _fp_type(d: dict) -> None:
    d["feature_points"]["4.1"] = "12"


def _empty_region(d: dict) -> None:
    d["regions"][3]["vertices"] = []


def _region_range(d: dict) -> None:
    d["regions"][0]["vertices"].append(-4)


def _bad_deformer(d: dict) -> None:
    d["regions"][1]["deformer"] = "spline"


def _unknown_fp_in_region(d: dict) -> None:
    d["regions"][1]["feature_points"] = ["2.2", "99.1"]


def _missing_pivot(d: dict) -> None:
    del d["pivots"]["jaw"]


def _bad_weights(d: dict) -> None:
    d["regions"][0]["weights"] = d["regions"][0]["weights"][:-1]


def _bad_part(d: dict) -> None:
    d["parts"]["eye_l"] = [5, 2]


def _version(d: dict) -> None:
    d["version"] = 99


def _lid_pivot(d: dict) -> None:
    next(r for r in d["regions"] if r["deformer"] == "eyelid")["pivot"] = "nose"


def _lids_share(d: dict) -> None:
    lids = {r["name"]: r for r in d["regions"] if r["deformer"] == "eyelid"}
    lids["upper_lid_l"]["vertices"].append(lids["upper_lid_r"]["vertices"][0])
    lids["upper_lid_l"]["weights"].append(0.5)


@pytest.mark.parametrize(("edit", "match"), [
    (_del_fp, "feature point 2.3 is missing"),
    (_fp_range, "feature point 4.1 is 10000000"),
    (_fp_type, "feature point 4.1 is '12'"),
    (_empty_region, "non-empty list"),
    (_region_range, "contains -4"),
    (_bad_deformer, "deformer 'spline'"),
    (_unknown_fp_in_region, "'99.1'"),
    (_missing_pivot, "pivot 'jaw'"),
    (_bad_weights, "weights must be"),
    (_bad_part, r"parts\['eye_l'\]"),
    (_version, "version 99"),
    (_lid_pivot, "pivot 'nose'"),
    (_lids_share, "about another pivot"),
])
def test_broken_definition_names_the_item(tmp_path: Path, edit, match: str) -> None:
    path = broken(tmp_path, edit)
    with pytest.raises(FaceModelError, match=match) as info:
        load_face(path)
    assert info.value.path == str(path)


def test_bad_json_reports_the_line(tmp_path: Path) -> None:
    path = tmp_path / "face.json"
    path.write_text('{\n "format": "facelib-face",\n "version": 1,,\n}\n')
    with pytest.raises(FaceModelError) as info:
        load_face(path)
    assert info.value.line == 3


def test_missing_files(tmp_path: Path) -> None:
    with pytest.raises(FaceModelError, match="cannot read"):
        load_face(tmp_path / "nope.json")
    path = broken(tmp_path, lambda d: d.update(mesh="other.npz"))
    with pytest.raises(FaceModelError, match=r"other\.npz"):
        load_face(path)


def test_mesh_with_bad_triangles(tmp_path: Path) -> None:
    path = broken(tmp_path, lambda d: None)
    with np.load(tmp_path / "default_head.npz") as data:
        arrays = dict(data)
    arrays["triangles"][0, 0] = len(arrays["vertices"]) + 5
    np.savez(tmp_path / "default_head.npz", **arrays)
    with pytest.raises(FaceModelError, match="triangle index"):
        load_face(path)


def test_integer_occlusion_is_read_into_the_unit_range(tmp_path: Path) -> None:
    path = broken(tmp_path, lambda d: None)
    with np.load(tmp_path / "default_head.npz") as data:
        arrays = dict(data)
    ao = np.full(len(arrays["vertices"]), 128, np.int16)
    ao[:2] = (300, -5)  # outside 0-255: clipped like the colours, not past [0, 1]
    arrays["vertex_ao"] = ao
    np.savez(tmp_path / "default_head.npz", **arrays)
    face = load_face(path)
    assert face.vertex_ao is not None
    np.testing.assert_allclose(face.vertex_ao[:3], [1.0, 0.0, 128 / 255], rtol=1e-6)
