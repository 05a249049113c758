"""Storyboard functions are declared once (facelib.fdl.functions) and every part of the
loader reads that one registry; unknown globals are not silently ignored."""

import warnings

import pytest

from facelib import fdl
from facelib.errors import FdlError, FdlWarning
from facelib.fdl import functions
from facelib.fdl.sandbox import Sandbox


def test_the_sandbox_exposes_exactly_the_registry():
    box = Sandbox()
    chunk = box.run("x = 1", path="t.fdl", functions=functions.function_names())
    calls = [name for name in functions.FUNCTIONS if chunk.env[name] is not None]
    assert calls == list(functions.FUNCTIONS)
    assert chunk.env["print_faps"] is None


@pytest.mark.parametrize("name", list(functions.FUNCTIONS))
def test_each_function_is_dispatched_and_checks_the_registry_fields(name):
    spec = functions.FUNCTIONS[name]
    if spec.fields is None:
        return  # open field names (FAP names, behaviour parameters)
    field = spec.fields[0]
    with pytest.raises(FdlError, match=rf"{name}: unknown field 'zz_{field}'"):
        fdl.loads(f'{name} {{ "joy", zz_{field} = 1 }}')


def test_a_misspelt_call_suggests_a_registered_function():
    with pytest.raises(FdlError, match="did you mean 'define_gaze'"):
        fdl.loads('define_gase { "shy", p_mutual = 0.1 }')


def test_known_globals_are_the_registry_and_the_settings():
    assert set(functions.known_globals()) == {
        *functions.FUNCTIONS, *functions.SETTINGS, "FDL", "expressions", "eyes", "Sentence"}


def test_a_global_close_to_a_setting_warns_with_a_suggestion():
    with pytest.warns(FdlWarning, match=r"t\.fdl:1: global 'fsp' is not a setting and is "
                                        r"ignored; did you mean 'fps'\?"):
        sb = fdl.loads("fsp = 30\nshow { 'joy', dur = 1 }", name="t.fdl")
    assert sb.fps == 25.0  # the misspelt setting was ignored, as the warning says


def test_a_very_close_global_is_an_error_and_far_ones_pass_silently():
    with pytest.raises(FdlError, match="unknown setting 'seeed'; did you mean 'seed'"):
        fdl.loads("seeed = 3")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fdl.loads("beat = 0.5\nshow { 'joy', dur = 2 * beat }")


def test_docs_describe_every_function_and_field():
    from pathlib import Path

    doc = (Path(__file__).parents[2] / "docs" / "fdl.md").read_text(encoding="utf-8")
    for spec in functions.FUNCTIONS.values():
        assert f"`{spec.name}" in doc or f"{spec.name} {{" in doc, spec.name
        for field in spec.fields or ():
            assert f"`{field}" in doc or f"{field} =" in doc, (spec.name, field)
    for setting in functions.SETTINGS:
        assert f"`{setting}`" in doc, setting


def test_fields_come_in_name_order_whatever_the_lua_state():
    text = 'define_gaze { "n", zeta = 1, alpha = 2, mid = 3, beta = 4 }'
    orders = {tuple(fdl.loads(text, sandbox=Sandbox()).gaze_defs["n"]) for _ in range(4)}
    assert orders == {("alpha", "beta", "mid", "zeta")}
