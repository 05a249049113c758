"""The modern syntax: storyboard functions, times, definitions, seeds, errors."""

from pathlib import Path

import pytest

from facelib import fdl
from facelib.errors import FdlError
from facelib.fdl.marking import mark_tables

DATA = Path(__file__).parents[1] / "data" / "fdl" / "thesis"


def test_definitions_and_local_mix():
    sb = fdl.loads(
        'define_expression { "a", raise_l_cornerlip_o = 100, open_jaw = 40 }\n'
        'define_expression { "b", raise_l_cornerlip_o = 20 }\n'
        'define_expression { "ab", mix = { a = 0.5, b = 2 }, open_jaw = 7 }\n'
        'define_expression { "lib", mix = { joy = 0.5 }, raise_b_midlip = 20 }\n'
        'define_gaze { "nervous", like = "default", rate = 2, spots = {1, 2.5} }\n'
    )
    assert dict(sb.expression_defs["ab"]) == {"raise_l_cornerlip_o": 90.0, "open_jaw": 7.0}
    assert "ab" not in sb.expression_mixes
    assert dict(sb.expression_mixes["lib"]) == {"joy": 0.5}
    assert dict(sb.expression_defs["lib"]) == {"raise_b_midlip": 20.0}
    assert dict(sb.gaze_defs["nervous"]) == {"like": "default", "rate": 2.0, "spots": (1.0, 2.5)}
    with pytest.raises(TypeError):
        sb.expression_defs["x"] = {}  # type: ignore[index]


def test_frames_follow_fps_set_after_cues():
    sb = fdl.loads('show { "joy", at = "10f", dur = "30 frames" }\nfps = 30\n')
    assert (sb.expressions[0].start_ms, sb.expressions[0].duration_ms) == (333, 1000)


def test_say_variants():
    sb = fdl.loads('say "Good morning."')
    assert (sb.speech.text, sb.speech.audio, sb.speech.start_ms) == ("Good morning.", None, 0)
    sb = fdl.loads(
        'say { audio = "hastalavista.wav", transcript = "hastalavista.txt", at = "250ms" }',
        base_dir=DATA,
    )
    assert sb.speech.text.strip() == "Hasta la vista, baby."
    assert sb.speech.audio == (DATA / "hastalavista.wav").resolve()
    assert sb.speech.start_ms == 250
    sb = fdl.loads('say { at = 1, visemes = {\n {"sil", 0.2},\n {10, "120ms"},\n {"pbm", "3f"} } }')
    v = sb.speech.visemes
    assert [(c.viseme, c.start_ms, c.duration_ms) for c in v] == [
        ("sil", 1000, 200),
        ("10", 1200, 120),
        ("pbm", 1320, 120),
    ]
    assert [c.origin[1] for c in v] == [2, 3, 4]


def test_seed_drives_math_random_and_is_overridable():
    text = "seed = 11\nfor i = 1, 4 do show { 'joy', dur = math.random(1, 1000) / 1000 } end\n"
    a = fdl.loads(text)
    b = fdl.loads(text)
    assert a == b and a.seed == 11
    c = fdl.loads(text, seed=12)
    assert c.seed == 12
    assert [e.duration_ms for e in c.expressions] != [e.duration_ms for e in a.expressions]
    d = fdl.loads(text.replace("seed = 11\n", ""), seed=11)
    assert [e.duration_ms for e in d.expressions] == [e.duration_ms for e in a.expressions]


def test_loop_cues_keep_their_line():
    sb = fdl.loads("for i = 1, 3 do\n  look {\n 'default', dur = 1 }\nend\n", name="l.fdl")
    assert [c.origin for c in sb.gaze] == [("l.fdl", 2)] * 3
    assert [c.start_ms for c in sb.gaze] == [0, 1000, 2000]


@pytest.mark.parametrize(
    ("text", "needle", "line"),
    [
        ('x = 1\nshwo { "joy", dur = 1 }', "did you mean 'show'", 2),
        ('show { "joy", dur = 1, intensty = 0.5 }', "did you mean 'intensity'", 1),
        ('show { "joy", dur = 1, intensity = 1.5 }', "from 0 to 1", 1),
        ('show { "joy" }', "needs dur", 1),
        ('show { "joy", dur = "2 sec" }', "is not a time", 1),
        ('show { "joy", dur = -1 }', ">= 0", 1),
        ('show { "joy", dur = 1, ease_in = 0.7, ease_out = 0.7 }', "longer than dur", 1),
        ('show "joy"', "takes a table", 1),
        ("\nlook { dur = 1 }", "needs a name", 2),
        ('say "a"\nsay "b"', "second time", 2),
        ('say { "a", transcript = "hastalavista.txt" }', "not both", 1),
        ('say { visemes = { {"xx", 1} } }', "unknown viseme 'xx'", 1),
        ('define_expression { "s",\n  raise_l_cornerlipp = 1 }', "did you mean", 2),
        ('define_expression { "s", mix = { s = 1 } }', "cannot mix itself", 1),
        ("fps = 0", "fps must be", 1),
        ("seed = -1", "seed must be", 1),
        ("x = {\n  1,\n  2 +\n}", "syntax error", 4),
        ('show({ "joy", dur = 1 }, 2)', "one table", 1),
    ],
)
def test_modern_errors(text, needle, line):
    with pytest.raises(FdlError) as info:
        fdl.loads(text, name="m.fdl", base_dir=DATA)
    assert needle in str(info.value)
    assert (info.value.path, info.value.line) == ("m.fdl", line)
    assert str(info.value).startswith(f"m.fdl:{line}: ")


def test_mixing_both_syntaxes():
    sb = fdl.loads('expressions = { {"joy", 25} }\nshow { "anger", dur = 1 }\n')
    assert [(c.name, c.start_ms) for c in sb.expressions] == [("joy", 0), ("anger", 1000)]


def test_marking_keeps_lines_and_strings():
    src = 'a = { "{", [[\n}]] }\n-- { not a table\nf{ x = {} }\nb = s"{"{1}\n'
    marked = mark_tables(src)
    assert marked.count("\n") == src.count("\n")
    assert '"{"' in marked and "[[\n}]]" in marked and "-- { not a table" in marked
    assert "f(__fdl_at(4,{ x = __fdl_at(4,{}) }))" in marked
    sb = fdl.loads(src.replace("f{", "t = {").replace('s"{"{1}', "2"))
    assert sb.fps == 25.0


def test_say_language_voice_rate_and_pitch():
    sb = fdl.loads('language = "pt"\nsay { "Olá, tudo bem?", voice = "pt-br", rate = 1.2, '
                   'pitch = 60 }')
    assert sb.language == "pt"
    s = sb.speech
    assert (s.text, s.lang, s.voice, s.rate, s.pitch) == ("Olá, tudo bem?", None, "pt-br", 1.2,
                                                          60.0)
    sb = fdl.loads('say { "Hola", lang = "es" }')
    assert sb.language is None and sb.speech.lang == "es"
    assert (sb.speech.rate, sb.speech.pitch) == (1.0, 50.0)


@pytest.mark.parametrize(("text", "message"), [
    ('say { "Hi", rate = 9 }', "rate must be a number from 0.5 to 2.5"),
    ('say { "Hi", pitch = "high" }', "pitch must be a number from 0 to 100"),
    ('say { "Hi", lang = 3 }', "lang must be a string"),
    ('say { "Hi", speed = 2 }', "unknown field 'speed'"),
    ('language = 5\nsay "Hi"', "language must be a language code"),
])
def test_say_speech_options_are_checked(text, message):
    with pytest.raises(FdlError, match=message):
        fdl.loads(text)
