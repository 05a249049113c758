"""The examples in docs/fdl.md run and mean what the text says."""

import re
from pathlib import Path

from facelib import fdl

DOC = Path(__file__).parents[2] / "docs" / "fdl.md"
DATA = Path(__file__).parents[1] / "data" / "fdl" / "thesis"
EXAMPLES = re.findall(r"```lua\n(.*?)```", DOC.read_text(), re.DOTALL)


def test_docs_have_examples():
    assert len(EXAMPLES) >= 5


def test_doc_modern_example_values():
    text = next(e for e in EXAMPLES if "say {" in e and "show" in e)
    sb = fdl.loads(text, name="hello.fdl", base_dir=DATA)
    assert (sb.fps, sb.seed, sb.output) == (25.0, 7, (DATA / "hello.fap").resolve())
    assert sb.speech.start_ms == 500
    assert sb.speech.text == "Hasta la vista, baby."
    joy, surprise, anger = sb.expressions
    assert (joy.start_ms, joy.duration_ms, joy.intensity) == (0, 2000, 0.8)
    assert (joy.ramp_in_ms, joy.ramp_out_ms) == (300, 500)
    assert (surprise.start_ms, surprise.duration_ms) == (2000, 1500)
    assert (anger.start_ms, anger.duration_ms) == (2500, 1000)
    look_to, default = sb.gaze
    assert look_to.args == ("left", 17.0, "yes")
    assert (default.start_ms, default.duration_ms) == (3000, 3000)
    assert joy.origin == ("hello.fdl", 7)
    assert default.origin == ("hello.fdl", 12)


def test_doc_definitions_example_animates():
    """The define_* example is not only loaded but run through the generators, which
    check expression names and eye-behaviour parameters."""
    from facelib import animate

    text = next(e for e in EXAMPLES if "define_gaze" in e)
    animation = animate(fdl.loads(text, name="defs.fdl", base_dir=DATA))
    assert animation.faps.n_frames > 0
    assert animation.gaze_events
