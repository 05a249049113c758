"""The render-speed paths keep the picture: hair cards lying on the head drawn single-sided
(facelib/rendering/hair.py), rigidly moving pieces posed by their node instead of re-uploaded
(facelib/rendering/rigid_pieces.py), the colour-only read-back."""

from __future__ import annotations

import dataclasses
from types import MappingProxyType

import numpy as np
import pytest

from facelib.rendering.hair import split_hair
from facelib.rendering.rigid_pieces import rigid_groups, rigid_pose

W, H = 160, 120


def test_cards_on_the_body_turn_away_from_it_and_loose_ones_stay_double_sided() -> None:
    body = np.array([[x, y, 0.0] for x in range(-2, 3) for y in range(-2, 3)], float)
    normals = np.tile([0.0, 0.0, 1.0], (len(body), 1))
    # two quads: one 0.1 above the body, wound toward it; one 5 above it
    hair = np.array([[0, 0, .1], [1, 0, .1], [0, 1, .1], [1, 1, .1],
                     [0, 0, 5], [1, 0, 5], [0, 1, 5], [1, 1, 5]], float)
    tris = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6]])
    single, double = split_hair(hair, tris, body, normals, within=0.5)
    assert double.tolist() == [[4, 5, 6], [5, 7, 6]]
    a, b, c = (hair[single[:, k]] for k in range(3))
    assert (np.cross(b - a, c - a)[:, 2] > 0).all()  # now facing away from the body
    assert sorted(map(sorted, single.tolist())) == [[0, 1, 2], [1, 2, 3]]
    none, everything = split_hair(hair, tris, body[:0], normals[:0], within=0.5)
    assert len(none) == 0 and len(everything) == 4


def test_a_rigid_motion_is_found_and_a_deformation_is_not() -> None:
    rng = np.random.default_rng(4)
    rest = rng.normal(size=(50, 3))
    tris = np.array([[0, 1, 2], [2, 3, 4]])
    (group,) = rigid_groups([np.arange(50)], rest, tris)
    a = 0.4
    rot = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    moved = (rest @ rot.T + [0.1, -0.2, 0.3]).astype(np.float32)
    pose = rigid_pose(group, moved)
    assert pose is not None
    np.testing.assert_allclose(pose[:3, :3], rot, atol=1e-6)
    np.testing.assert_allclose(pose[:3, 3], [0.1, -0.2, 0.3], atol=1e-6)
    bent = moved.copy()
    bent[7] += 1e-3
    assert rigid_pose(group, bent) is None


@pytest.mark.render
def test_the_fast_paths_keep_the_picture() -> None:
    from facelib.engine import load_face
    from facelib.mpeg4.tables import fap
    from facelib.rendering.scene import FaceRenderer, load_look

    face = load_face(None)
    frame = np.zeros(84, np.float32)
    frame[fap("head_yaw").index] = np.radians(30) / face.fapu["AU"]
    frame[2] = 300  # jaw open
    moved = face.deform_frame(frame)
    look = load_look()
    parts = {k: {n: v for n, v in s.items() if n != "single_sided_within_es"}
             for k, s in look.parts.items()}
    slow_look = dataclasses.replace(look, parts=MappingProxyType(parts))
    images = []
    for options in ({}, {"rigid_pieces": False}, {"rigid_pieces": False, "look": slow_look}):
        with FaceRenderer(face, width=W, height=H, framing="head", **options) as renderer:
            renderer.frame(face.vertices)
            images.append(renderer.frame(moved).astype(int))
            if not options:
                hair = [k for k, p in enumerate(renderer._pieces) if p.name == "hair"]
                assert len(hair) == 2  # lying on the head / loose
                assert not renderer._materials[hair[0]].doubleSided
                posed = renderer.scene.get_pose(renderer._nodes[hair[0]])
                assert not np.allclose(posed, np.eye(4))  # moved by its node
    fast, uploaded, double = images
    # posing instead of uploading: float rounding at most
    assert (np.abs(fast - uploaded).max(axis=2) > 8).mean() < 0.001
    # single-sided cards on the head: only the edges of cards seen edge-on change
    changed = np.abs(uploaded - double).max(axis=2) > 8
    assert changed.mean() < 0.005
    assert np.abs(fast - double).mean() < 0.2


@pytest.mark.render
def test_cached_uniforms_keep_the_picture() -> None:
    from facelib.engine import load_face
    from facelib.rendering.scene import FaceRenderer

    face = load_face(None)
    values = np.zeros((3, 84), np.float32)
    values[1, 2] = 300  # jaw open
    values[2, 48] = 20000  # head yaw
    poses = [face.deform_frame(v) for v in values]
    with FaceRenderer(face, width=W, height=H, framing="head") as renderer:
        fast = [renderer.frame(v, faps=f) for v, f in zip(poses, values, strict=True)]
        # pyrender's own uniform setting, on the same programs
        for program in renderer._renderer._renderer._program_cache._by_source.values():
            del program.set_uniform
        plain = [renderer.frame(v, faps=f) for v, f in zip(poses, values, strict=True)]
    for a, b in zip(fast, plain, strict=True):
        assert np.array_equal(a, b)
