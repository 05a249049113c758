"""Bad arguments to the public API raise the facelib error that names the mistake.

One table: a public call with a bad argument, the facelib error it must raise and a
fragment of the message. No bare built-in exception (ZeroDivisionError, TypeError from
numpy, a raw OSError, ...) may escape instead.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import facelib
from facelib import expressions, fdl, gaze, sync, visemes
from facelib.cues import ExpressionCue, GazeCue, SpeechSpec, VisemeCue
from facelib.errors import (
    DataError,
    FacelibError,
    FapFormatError,
    FdlError,
    FileError,
    ParameterError,
    SpeechError,
)
from facelib.mpeg4 import FapStream, FapTrack, read_fap, write_fap

JOY = [ExpressionCue("joy", 0, 1000)]
CARTOON = Path(__file__).parents[1] / "examples" / "heads" / "cartoon_head.obj"
SAID = SpeechSpec(visemes=(VisemeCue("A", 0, 200),))
STREAM = FapStream(25, np.zeros((2, 84), np.float32))
EMPTY = FapTrack.empty(2, fps=25)


def _a_file(tmp: Path) -> Path:
    """A plain file, so that ``file / "x"`` is a path whose folder cannot be made."""
    path = tmp / "not_a_folder"
    path.write_text("x")
    return path


# (id, call(tmp_path), error, message fragment)
CASES: list[tuple[str, Callable[[Path], object], type[FacelibError], str]] = [
    # frame rates, counts and seeds: the shared checks
    ("expressions fps 0", lambda _: expressions.animate(JOY, fps=0, n_frames=5),
     ParameterError, "fps must be a positive number"),
    ("expressions fps nan", lambda _: expressions.animate(JOY, fps=float("nan"), n_frames=5),
     ParameterError, "fps must be a positive number"),
    ("expressions n_frames -1", lambda _: expressions.animate(JOY, fps=25, n_frames=-1),
     ParameterError, "n_frames must be an integer >= 0"),
    ("expressions n_frames 2.5", lambda _: expressions.animate(JOY, fps=25, n_frames=2.5),
     ParameterError, "n_frames must be an integer"),
    ("visemes fps -25", lambda _: visemes.animate(SAID, fps=-25),
     ParameterError, "fps must be a positive number"),
    ("visemes fps str", lambda _: visemes.animate(SAID, fps="25"),
     ParameterError, "fps must be a positive number"),
    ("visemes rate 0", lambda _: visemes.animate(SAID, fps=25, rate=0),
     ParameterError, "rate must be a finite number in [0.25, 4]"),
    ("text rate 10", lambda _: visemes.timeline_from_text("hello", rate=10),
     ParameterError, "rate must be a finite number in [0.25, 4]"),
    ("gaze seed -1", lambda _: gaze.animate([], fps=25, n_frames=5, seed=-1),
     ParameterError, "seed must be an integer from 0 to 2^63-1"),
    ("gaze seed 1.5", lambda _: gaze.animate([], fps=25, n_frames=5, seed=1.5),
     ParameterError, "seed must be an integer"),
    ("gaze fps 0", lambda _: gaze.animate([], fps=0, n_frames=5, seed=0),
     ParameterError, "fps must be a positive number"),
    ("gaze simulate seconds 0", lambda _: gaze.simulate("default", seconds=0),
     ParameterError, "seconds must be a finite number in (0, inf]"),
    ("gaze pursue shape", lambda _: gaze.pursue(np.zeros((4, 3)), fps=25),
     ParameterError, "target_deg must be a finite (n_frames, 2) array"),
    ("sync seed bool", lambda _: sync.combine(expressions=EMPTY, visemes=EMPTY, gaze=EMPTY,
                                              seed=True),
     ParameterError, "seed must be an integer"),
    ("sync blinks without lids", lambda _: sync.combine(
        expressions=EMPTY, visemes=EMPTY, gaze=EMPTY, blinks=np.zeros(2)),
     ParameterError, "blinks need blink_lids"),
    ("animate seed -3", lambda _: facelib.animate(fdl.loads('show { "joy", dur = 1 }'), seed=-3),
     ParameterError, "seed must be an integer"),
    ("timeline fps 0", lambda _: visemes.timeline_to_sentence(
        visemes.timeline_from_text("hi"), fps=0),
     ParameterError, "fps must be a positive number"),
    # storyboards: API arguments are ParameterErrors, script problems FdlErrors
    ("loads bytes", lambda _: fdl.loads(b"show {}"), ParameterError, "must be a str"),
    ("loads base_dir", lambda tmp: fdl.loads("x = 1", base_dir=_a_file(tmp)),
     ParameterError, "is not a folder"),
    ("sandbox memory", lambda _: fdl.Sandbox(max_memory=10),
     ParameterError, "max_memory must be an integer >= 1048576"),
    ("sandbox seconds", lambda _: fdl.Sandbox(max_seconds=0),
     ParameterError, "max_seconds must be a finite number in (0, 3600]"),
    ("script line", lambda _: fdl.loads("x = 1\nfps = -5", name="s.fdl"),
     FdlError, "s.fdl:2: fps must be a number from 1 to 1000"),
    # wrong kinds of arguments
    ("expression cues not a list", lambda _: expressions.animate(5, fps=25, n_frames=3),
     ParameterError, "cues must be a sequence of ExpressionCue"),
    ("gaze cue of the wrong kind", lambda _: gaze.animate(JOY, fps=25, n_frames=3, seed=0),
     ParameterError, "cues[0] must be a GazeCue, got ExpressionCue"),
    ("visemes not a SpeechSpec", lambda _: visemes.animate("hello", fps=25),
     ParameterError, "speech must be a SpeechSpec, got str"),
    ("text not a str", lambda _: visemes.timeline_from_text(5), ParameterError,
     "text must be a str"),
    ("write_fap not a stream", lambda tmp: write_fap("x", tmp / "a.fap"), ParameterError,
     "stream must be a FapStream"),
    ("deform_frame text", lambda _: facelib.load_face().deform_frame("x"), ParameterError,
     "needs 84 FAP values"),
    ("between nan", lambda _: STREAM.between(float("nan"), 1), ParameterError,
     "start must be a finite number"),
    # streams and tracks
    ("stream shape", lambda _: FapStream(25, np.zeros((2, 80))),
     ParameterError, "values must have shape (n_frames, 84)"),
    ("stream fps inf", lambda _: FapStream(float("inf"), np.zeros((2, 84))),
     ParameterError, "fps must be a positive number"),
    # names: one "did you mean"
    ("FAP name", lambda _: facelib.fap("open_jaww"),
     ParameterError, "did you mean 'open_jaw'"),
    ("FAP id 99", lambda _: facelib.fap(99), ParameterError, "outside 1-84"),
    ("expression misspelt", lambda _: expressions.animate(
        [ExpressionCue("joyy", 0, 1000, origin=("story.fdl", 3))], fps=25, n_frames=5),
     FdlError, "story.fdl:3: unknown expression 'joyy'; did you mean 'joy'?"),
    ("eye behaviour misspelt", lambda _: gaze.animate(
        [GazeCue("lookto", ("left", 10.0, "yes"), 0, 500, origin=("s.fdl", 2))],
        fps=25, n_frames=5, seed=0),
     FdlError, "did you mean 'lookTo'"),
    ("storyboard function misspelt", lambda _: fdl.loads('shwo { "joy", dur = 1 }'),
     FdlError, "did you mean 'show'"),
    ("storyboard field misspelt", lambda _: fdl.loads('show { "joy", dur = 1, intensty = 1 }'),
     FdlError, "did you mean 'intensity'"),
    # files: OSError wrapped with the path
    ("write_fap into a file", lambda tmp: write_fap(STREAM, _a_file(tmp) / "x.fap"),
     FileError, "not_a_folder/x.fap: cannot write"),
    ("write_timeline into a file", lambda tmp: visemes.write_timeline(
        visemes.timeline_from_text("hi"), _a_file(tmp) / "t.json"),
     FileError, "cannot write"),
    ("read_fap missing", lambda tmp: read_fap(tmp / "nothing.fap"),
     FapFormatError, "nothing.fap"),
    ("write_fap dialect", lambda tmp: write_fap(STREAM, tmp / "x.fap", dialect="mpeg"),
     ParameterError, "unknown .fap dialect 'mpeg'"),
    ("write_fap fps 24.5", lambda tmp: write_fap(STREAM.resample(24.5), tmp / "x.fap"),
     ParameterError, "whole frame rate"),
    ("sync rules missing", lambda tmp: sync.SyncRules.load(tmp / "none.json"),
     FileError, "none.json: cannot read"),
    ("sync rules not JSON", lambda tmp: sync.SyncRules.load(_write(tmp, "r.json", "{")),
     DataError, "r.json:1: invalid JSON"),
    ("sync rules malformed", lambda tmp: sync.SyncRules.load(_write(tmp, "r.json", "{}")),
     DataError, "bad synchronizer rules"),
    ("storyboard missing", lambda tmp: fdl.load(tmp / "none.fdl"),
     FdlError, "not found"),
    ("face missing", lambda tmp: facelib.load_face(tmp / "none.json"),
     facelib.FaceModelError, "cannot read face definition"),
    ("deformer override of no region", lambda _: facelib.load_face(deformers={"mouth": "rbf"}),
     ParameterError, "names no region or group"),
    ("unknown deformer", lambda _: facelib.load_face(deformers={"lips": "spline"}),
     facelib.FaceModelError, "unknown deformer 'spline'"),
    ("evaluate unknown deformer", lambda _: _evaluate(("spline",)),
     ParameterError, "unknown deformer 'spline'"),
    ("evaluate unknown pose kind", lambda _: _poses(("visemes",)),
     ParameterError, "pose kinds must be some of"),
    ("speech without content", lambda _: visemes.animate(SpeechSpec(), fps=25),
     SpeechError, "neither audio, text nor a viseme script"),
    ("setup_face mesh format", lambda tmp: facelib.setup_face(tmp / "head.fbx", landmarks={}),
     facelib.FaceModelError, "unknown mesh format '.fbx'"),
    ("setup_face landmarks missing", lambda tmp: facelib.setup_face(
        CARTOON, landmarks=tmp / "none.json"), facelib.FaceModelError, "cannot read landmarks"),
    ("setup_face 3 landmarks", lambda _: facelib.setup_face(
        CARTOON, landmarks={"9.3": 1, "2.1": 2, "4.1": 3}),
     facelib.FaceModelError, "a 3-D warp needs at least 4"),
    ("setup_face unit", lambda _: facelib.setup_face(
        CARTOON, landmarks=CARTOON.with_name("cartoon_landmarks.json"), unit="km"),
     ParameterError, "unit 'km' is not one of"),
]


def _evaluate(names: tuple[str, ...]) -> object:
    from facelib.evaluate import evaluate_deformers

    return evaluate_deformers(names)


def _poses(kinds: tuple[str, ...]) -> object:
    from facelib.evaluate import evaluation_poses

    return evaluation_poses(kinds)


def _write(tmp: Path, name: str, text: str) -> Path:
    path = tmp / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(("call", "error", "fragment"), [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_bad_input_raises_the_facelib_error(tmp_path, call, error, fragment):
    with pytest.raises(error) as info:
        call(tmp_path)
    assert fragment in str(info.value)
    assert isinstance(info.value, FacelibError)


def test_the_table_names_each_error_class():
    named = {c[2] for c in CASES}
    assert {ParameterError, FdlError, FileError, DataError, FapFormatError,
            SpeechError} <= named


# The command line: the same errors, reported on one line with exit status 1.
CLI_CASES: list[tuple[str, Callable[[Path], list[str]], str]] = [
    ("info missing", lambda tmp: ["info", str(tmp / "none.fap")], "none.fap"),
    ("run missing", lambda tmp: ["run", str(tmp / "none.fdl")], "not found"),
    ("run into a file", lambda tmp: ["run", str(_story(tmp)), "-o",
                                      str(_a_file(tmp) / "x.fap")], "cannot write"),
    ("align transcript missing", lambda tmp: ["align", str(tmp / "a.wav"), "--text-file",
                                              str(tmp / "none.txt"), "-o", str(tmp / "o.sb")],
     "none.txt: cannot read the transcript"),
    ("check misspelt", lambda tmp: ["check", str(_story(tmp, 'shwo { "joy", dur = 1 }'))],
     "did you mean 'show'"),
    ("run misspelt expression", lambda tmp: ["run", str(_story(tmp, 'show { "joyy", dur = 1 }')),
                                             "-o", str(tmp / "o.fap")],
     "s.fdl:1: unknown expression 'joyy'; did you mean 'joy'?"),
]


def _story(tmp: Path, text: str = 'show { "joy", dur = 1 }') -> Path:
    return _write(tmp, "s.fdl", text)


@pytest.mark.parametrize(("argv", "fragment"), [c[1:] for c in CLI_CASES],
                         ids=[c[0] for c in CLI_CASES])
def test_bad_input_on_the_command_line(tmp_path, capsys, argv, fragment):
    from facelib.cli import main

    assert main(argv(tmp_path)) == 1
    err = capsys.readouterr().err
    assert err.startswith("facelib: error: ")
    assert fragment in err
    assert "Traceback" not in err
