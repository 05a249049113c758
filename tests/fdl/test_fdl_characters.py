"""Storyboards with characters: ``characters { ... }`` and cues addressed with ``who``."""

import pytest

from facelib import fdl
from facelib.cues import TWO_SHOT
from facelib.errors import FdlError

CAST = '''characters {
  ada = { hair = "long" },
  ben = { face = "default", hair = "short" },
}
'''


def _load(body: str, **kw):
    return fdl.loads(CAST + body, name="t.fdl", **kw)


def test_characters_stand_in_the_order_of_their_lines_and_get_their_own_cues():
    sb = _load('say { who = "ben", "Hi, Ada.", at = 2 }\n'
               'say { who = "ada", "Hello, Ben.", at = 0.5 }\n'
               'show { who = "ben", "joy", dur = 1 }\n'
               'show { who = "ben", "sadness", dur = 1 }\n'
               'look { who = "ada", "lookTo", "left", 10, dur = 1, at = 1 }\n'
               'mood { who = "ada", "happy", at = 0 }\n'
               'camera { who = "ben", framing = "head", at = 2 }\n'
               'camera { "two_shot", at = 3 }\n')
    ada, ben = sb.characters
    assert (ada.name, ada.hair, ada.face, ada.origin) == ("ada", "long", None, ("t.fdl", 2))
    assert (ben.name, ben.hair, ben.face) == ("ben", "short", None)  # "default": bundled
    assert ada.part.speech.text == "Hello, Ben." and ada.part.speech.start_ms == 500
    assert ben.part.speech.text == "Hi, Ada." and ben.part.speech.start_ms == 2000
    # each character's cues follow on from its own previous ones
    assert [(c.name, c.start_ms) for c in ben.part.expressions] == [("joy", 0),
                                                                   ("sadness", 1000)]
    assert ada.part.expressions == () and ada.part.gaze[0].args == ("left", 10.0)
    assert [m.name for m in ada.part.moods] == ["happy"] and ben.part.moods == ()
    assert (ada.part.hair, ben.part.hair) == ("long", "short")
    assert ada.part.setting_lines == {"hair": 2} and ada.part.seed != ben.part.seed
    # the scene itself has no cues of its own, only the camera cuts
    assert sb.speech is None and sb.expressions == () and sb.gaze == ()
    cut, both = sb.camera
    assert (cut.who, cut.framing, cut.start_ms) == ("ben", "head", 2000)
    assert (both.who, both.framing, both.start_ms) == (None, TWO_SHOT, 3000)
    assert sb.cues_end_ms == 3000


def test_a_character_face_is_a_file_inside_the_storyboard_folder(tmp_path):
    (tmp_path / "ben.json").write_text("{}")
    sb = fdl.loads('characters { ada = {}, ben = { face = "ben.json" } }', base_dir=tmp_path)
    assert sb.characters[0].face is None
    assert sb.characters[1].face == (tmp_path / "ben.json").resolve()
    assert sb.characters[1].part.face == sb.characters[1].face
    with pytest.raises(FdlError, match=r"t\.fdl:1: characters: ada: face"):
        fdl.loads('characters { ada = { face = "../x.json" } }', name="t.fdl",
                  base_dir=tmp_path)


@pytest.mark.parametrize(("body", "message"), [
    ('say { who = "bne", "Hi." }',
     (r"t\.fdl:5: say: who = 'bne' is not one of the characters \(ada, ben\); "
      r"did you mean 'ben'\?")),
    ('show { who = "adda", "joy", dur = 1 }',
     r"t\.fdl:5: show: who = 'adda' is not one of the characters .*did you mean 'ada'\?"),
    ('look { "lookTo", "left", 10, dur = 1 }',
     (r"t\.fdl:5: look: this storyboard names characters \(ada, ben\); say whose it is "
      r"with who = \"ada\"")),
    ('say { who = "ada", "a" }\nsay { who = "ada", "b" }',
     r"t\.fdl:6: say: ada's turns on lines 5 and 6 both start at 0 ms"),
    ('camera { "head", at = 1 }',
     r"t\.fdl:5: camera: with characters a cue names who = \.\.\. .* got framing 'head'"),
    ('camera { who = "ben", at = 1, dur = 1 }',
     r"t\.fdl:5: camera: with characters the camera cuts between shots; leave out dur"),
    ('camera { "two_shot", who = "ben" }', r't\.fdl:5: camera: "two_shot" shows every'),
    ('say { who = 3, "Hi." }', r"t\.fdl:5: say: who must be a character name"),
    ('hair = "long"', r"t\.fdl:5: hair: with characters, give each character's hair"),
    ('characters { cy = {} }', r"t\.fdl:5: characters is called a second time"),
])
def test_bad_cast_storyboards_name_the_line(body, message):
    with pytest.raises(FdlError, match=message):
        _load(body)


@pytest.mark.parametrize(("text", "message"), [
    ('say { who = "ada", "Hi." }',
     r"t\.fdl:1: say: who = 'ada', but the storyboard names no characters"),
    ('camera { "two_shot" }', r't\.fdl:1: camera: "two_shot" needs characters'),
    ('characters { ada = { hiar = "long" } }',
     r"t\.fdl:1: characters: ada: unknown field 'hiar'; did you mean 'hair'\?"),
    ('characters { ada = "long" }', r"t\.fdl:1: characters: ada must be a table"),
    ('characters { "ada", "ben" }', r"t\.fdl:1: characters names each character"),
    ('characters { ada = {} }\nexpressions = { {"joy", 10} }',
     r"t\.fdl:1: the thesis's FDL table and lists have no characters"),
])
def test_cues_and_casts_that_do_not_fit_are_errors(text, message):
    with pytest.raises(FdlError, match=message):
        fdl.loads(text, name="t.fdl")


def test_a_storyboard_without_characters_is_read_as_before():
    sb = fdl.loads('say "Hello."\nshow { "joy", dur = 1 }\ncamera { "head", at = 0.5 }')
    assert sb.characters == () and sb.speech.text == "Hello."
    assert sb.camera[0].who is None and sb.camera[0].framing == "head"


def test_describe_lists_each_character_and_its_cues():
    text = fdl.describe(_load('say { who = "ben", "Hi.", at = 1 }\ncamera { who = "ben" }'))
    assert "character ada: face bundled, hair long" in text
    assert "character ben: face bundled, hair short" in text
    assert "speech at 1.000s" in text and "ben (render framing) (cut)" in text


def test_a_character_may_speak_several_turns_in_time_order():
    sb = _load('say { who = "ada", "Coffee?", at = 4 }\n'
               'say { who = "ada", "Morning.", at = 0.5 }\n'
               'say { who = "ben", "Please.", at = 2 }\n')
    ada, ben = sb.characters
    assert ada.part.speech.text == "Morning." and ada.part.speech.start_ms == 500
    assert [t.text for t in ada.part.turns] == ["Coffee?"]
    assert ada.part.turns[0].origin == ("t.fdl", 5)
    assert ben.part.turns == ()
    assert fdl.describe(sb).count("speech at") == 3


def test_a_storyboard_of_one_face_still_has_one_say():
    with pytest.raises(FdlError, match=r"t\.fdl:2: say is called a second time \(the first "
                                       r"call is on line 1\); a storyboard has one speech"):
        fdl.loads('say "a"\nsay "b"', name="t.fdl")
