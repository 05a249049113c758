"""The ``camera`` storyboard function (issue 14, item 5): cuts and moves between framings."""

import pytest

from facelib import fdl
from facelib.cues import CameraCue
from facelib.errors import FdlError
from facelib.fdl.camera import framing_names
from facelib.fdl.describe import describe


def test_cuts_and_moves_become_timed_cues_with_their_lines():
    sb = fdl.loads(
        'show { "joy", dur = 1 }\n'
        'camera { framing = "head", at = 2.0 }\n'
        'camera { "bust", at = "3s", dur = 0.5 }\n'
        'camera { framing = "face", dur = "10f" }\n',  # no at: after the move before it
        name="cam.fdl",
    )
    assert sb.camera == (
        CameraCue("head", 2000, 0, ("cam.fdl", 2)),
        CameraCue("bust", 3000, 500, ("cam.fdl", 3)),
        CameraCue("face", 3500, 400, ("cam.fdl", 4)),
    )
    assert sb.cues_end_ms == 3900  # the last move is part of the animation
    listing = describe(sb)
    assert "camera      2.000s +0.000s  head (cut)  (cam.fdl:2)" in listing
    assert "camera      3.000s +0.500s  bust  (cam.fdl:3)" in listing


def test_framings_are_the_renderers():
    assert framing_names() == ("face", "head", "bust")


@pytest.mark.parametrize(("script", "message"), [
    ('camera { framing = "haed", at = 1 }',
     r"t\.fdl:2: camera: framing 'haed' is not one of face, head, bust; did you mean 'head'"),
    ('camera { at = 1 }', r"t\.fdl:2: camera needs a framing"),
    ('camera { framing = 3 }', r"t\.fdl:2: camera: framing 3 is not one of"),
    ('camera { "head", framing = "face" }', r"t\.fdl:2: camera takes one framing"),
    ('camera { framing = "head", zoom = 2 }', r"t\.fdl:2: camera: unknown field 'zoom'"),
    ('camera { framing = "head", at = -1 }', r"t\.fdl:2: camera: at must be a finite time"),
    ('camera { framing = "head", dur = "soon" }', r"t\.fdl:2: camera: dur 'soon' is not a time"),
    ('camera { "head", at = 1, dur = 2 }\ncamera { "face", at = 2 }',
     (r"t\.fdl:3: camera: the move to 'face' at 2000 ms starts before the move to 'head' "
     r"arrives \(3000 ms\)")),
])
def test_bad_camera_cues_name_the_line(script, message):
    with pytest.raises(FdlError, match=message):
        fdl.loads('show { "joy", dur = 1 }\n' + script, name="t.fdl")
