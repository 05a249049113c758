"""The thesis's FDL format (section 4.2.5), loaded verbatim."""

from pathlib import Path

import pytest

from facelib import fdl
from facelib.errors import FdlError

DATA = Path(__file__).parents[1] / "data" / "fdl" / "thesis"


def test_thesis_storyboard_verbatim():
    sb = fdl.load(DATA / "storyboard.fdl")
    assert sb.fps == 25.0
    assert sb.seed == 0
    assert sb.path == (DATA / "storyboard.fdl").resolve()
    assert sb.output == (DATA / "animation.fap").resolve()
    assert sb.speech is not None
    assert sb.speech.audio == (DATA / "hastalavista.wav").resolve()
    assert sb.speech.audio.is_absolute()
    assert sb.speech.text == "Hasta la vista, baby."
    assert sb.speech.visemes is None
    names = [c.name for c in sb.expressions]
    assert names == [
        "joy",
        "sadness",
        "surprise",
        "anger",
        "disgust",
        "fear",
        "trust",
        "tongueout",
        "inlove",
        "worry",
        "sleepy",
    ]
    # durations are frames at 25 fps, one cue after the other
    frames = [100, 100, 100, 50, 50, 100, 100, 100, 100, 100, 100]
    starts = [sum(frames[:i]) * 40 for i in range(len(frames))]
    assert [c.start_ms for c in sb.expressions] == starts
    assert [c.duration_ms for c in sb.expressions] == [f * 40 for f in frames]
    sb_file = str((DATA / "expressions.sb").resolve())
    assert [c.origin for c in sb.expressions] == [(sb_file, i + 2) for i in range(11)]


def test_thesis_eyes_args_and_lines():
    sb = fdl.load(DATA / "storyboard.fdl")
    first, second, *_, last = sb.gaze
    assert (first.behaviour, first.args, first.start_ms, first.duration_ms) == (
        "lookTo",
        ("left", 17.0, "yes"),
        0,
        2000,
    )
    assert (second.behaviour, second.args, second.start_ms) == ("default", ("talking", 0.9), 2000)
    assert sb.gaze[3].args == (0.99, 0.6)
    assert last.behaviour == "pursuit"
    assert last.start_ms == (50 + 500 + 50 + 500 + 400 + 50) * 40
    assert last.origin == (str((DATA / "eyes.sb").resolve()), 8)


def test_viseme_script_at_storyboard_fps():
    sb = fdl.load(DATA / "with_sentence.fdl")
    assert sb.fps == 30.0
    assert sb.output is None
    assert sb.gaze == ()
    assert sb.speech.text is None
    vis = sb.speech.visemes
    assert [v.viseme for v in vis] == ["silence", "A", "kg", "Q", "nl", "sz", "I", "A", "silence"]
    frames = [11, 6, 1, 1, 3, 3, 6, 2, 27]
    bounds = [round(sum(frames[:i]) * 1000 / 30) for i in range(len(frames) + 1)]
    assert [v.start_ms for v in vis] == bounds[:-1]
    assert [v.end_ms for v in vis] == bounds[1:]  # no drift: cues tile exactly
    assert vis[0].origin == (str((DATA / "sentence.sb").resolve()), 3)
    assert sb.cues_end_ms == max(bounds[-1], sb.expressions[-1].end_ms)


def test_sub_script_loaded_directly():
    sb = fdl.load(DATA / "eyes.sb")
    assert len(sb.gaze) == 7
    assert sb.expressions == ()
    assert sb.speech is None


@pytest.mark.parametrize(
    ("text", "needle", "line"),
    [
        ('FDL = {\n  speakSond = "hastalavista.wav",\n}', "did you mean 'speakSound'", 2),
        ("FDL = { eyesScript = 3 }", "must be a file name", 1),
        ('expressions = {\n {"joy", 100},\n {"joy"},\n}', "expressions[2] has 1 values", 3),
        ('expressions = {\n {"joy", -5},\n}', "duration in frames", 2),
        ('eyes = { {"lookTo", {}, 5} }', "must be a string or a number", 1),
        ('Sentence = {\n{"silence", 3},\n{"Ah", 2}}', "unknown viseme 'Ah'", 3),
        ('outptu = "x.fap"', "did you mean 'output'", 1),
        ('FDL = { expressionScript = "missing.sb" }', "not found", 1),
    ],
)
def test_thesis_errors_name_file_and_line(text, needle, line):
    with pytest.raises(FdlError) as info:
        fdl.loads(text, name="story.fdl", base_dir=DATA)
    assert needle in str(info.value)
    assert info.value.path == "story.fdl"
    assert info.value.line == line


def test_sub_script_must_define_its_list(tmp_path):
    (tmp_path / "e.sb").write_text('expresions = { {"joy", 1} }\n')
    with pytest.raises(FdlError, match="did you mean 'expresions'") as info:
        fdl.loads('FDL = { expressionScript = "e.sb" }', base_dir=tmp_path)
    assert info.value.path == str((tmp_path / "e.sb").resolve())


def test_sub_script_error_points_into_sub_script(tmp_path):
    (tmp_path / "e.sb").write_text('expressions = {\n  {"joy", 1},\n  {"joy", nil .. "x"},\n}\n')
    with pytest.raises(FdlError, match="concatenate") as info:
        fdl.loads('FDL = { expressionScript = "e.sb" }', base_dir=tmp_path)
    assert (info.value.path, info.value.line) == (str((tmp_path / "e.sb").resolve()), 3)


def test_describe_lists_every_cue():
    sb = fdl.load(DATA / "with_sentence.fdl")
    text = fdl.describe(sb)
    lines = text.splitlines()
    assert sum(1 for x in lines if x.strip().startswith("viseme")) == 9
    assert sum(1 for x in lines if x.strip().startswith("express")) == 11
    assert "fps: 30  seed: 0  output: none" in text
    assert f"{(DATA / 'sentence.sb').resolve()}:3" in text
