"""Storyboard camera cues in a render (issue 14, item 5): the face's size in the frame
changes at a cut and over a move, on the real default head."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from facelib.cues import CameraCue
from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream

pytestmark = pytest.mark.render

engine = pytest.importorskip("facelib.engine")
W, H = 96, 72


def _coverage(frames: np.ndarray) -> np.ndarray:
    """(n,) share of each frame's pixels that show skin: bright and red over blue (sRGB
    red > 120 and red - blue > 50), which the dark background, the blue garment and the
    brown hair are not. The face's size, not that of all that is not background: the bust
    framing shows more garment, which fills the frame as the face shrinks."""
    f = frames.astype(int)
    return ((f[..., 0] > 120) & (f[..., 0] - f[..., 2] > 50)).mean(axis=(1, 2))


def _source(cues: tuple[CameraCue, ...], n_frames: int) -> SimpleNamespace:
    stream = FapStream(10.0, np.zeros((n_frames, 84), np.float32))
    return SimpleNamespace(faps=stream, storyboard=SimpleNamespace(camera=cues))


def test_a_cut_and_a_move_change_the_face_size(default_face):
    from facelib.rendering import render

    cues = (CameraCue("head", 500), CameraCue("bust", 1000, 500), CameraCue("face", 1800))
    frames = render(_source(cues, 20), face=default_face, width=W, height=H, progress=False)
    cover = _coverage(frames)
    face, head, bust = cover[0], cover[7], cover[16]
    assert np.allclose(cover[:5], face) and np.allclose(cover[5:10], head)  # the cut at 0.5 s
    assert face > 1.5 * head > 1.5 * 1.2 * bust
    moving = cover[10:16]  # 1.0-1.5 s: the move, easing from head to bust
    assert np.all(np.diff(cover[9:16]) <= 1e-9) and head > moving[2] > bust
    assert np.allclose(cover[15:18], bust) and np.allclose(cover[18:], face)
    # without cues nothing moves
    still = _coverage(render(_source((), 4), face=default_face, width=W, height=H,
                             progress=False))
    assert np.allclose(still, face)


def test_a_storyboard_camera_cue_reaches_the_video(default_face):
    from facelib import fdl
    from facelib.animation import animate
    from facelib.rendering import render

    sb = fdl.loads('fps = 10\nshow { "joy", dur = 1 }\ncamera { framing = "head", at = 0.5 }\n')
    cover = _coverage(render(animate(sb), face=default_face, width=W, height=H,
                             progress=False))
    assert cover[4] > 1.5 * cover[5]


def test_an_unknown_framing_in_a_cue_is_refused(default_face):
    from facelib.rendering import render

    with pytest.raises(ParameterError, match="camera cue framing 'wide'"):
        render(_source((CameraCue("wide", 0),), 2), face=default_face, width=W, height=H,
               progress=False)


def test_a_refused_cue_names_its_storyboard_line(default_face):
    from facelib.rendering import render

    cue = CameraCue("wide", 0, origin=("story.fdl", 7))
    with pytest.raises(ParameterError, match=r"^story\.fdl:7: camera cue framing 'wide'"):
        render(_source((cue,), 2), face=default_face, width=W, height=H, progress=False)
