"""Storyboards facelib writes quote every string by Lua's rules (issue 38, class 10): a
dataset's expression or behaviour name was pasted into ``clip.fdl`` as it was, so a name
could end the literal and run Lua; JSON escapes (``\\u00e9``) are not Lua's either."""

from __future__ import annotations

import lupa.lua54 as lua
import numpy as np
import pytest

from facelib import fdl
from facelib.dataset import ClipDraw, DatasetSpec, clip_storyboard
from facelib.fdl.literals import lua_string

HOSTILE = [
    'joy" } error("injected") show { "joy',
    'joy", at = 0 } os = nil --',
    "a\\\" } error(1) --",
    "]] error(2) --[[",
    "line\nbreak\r\0nul\x1b[31m\x7f",
    "\\0659",  # a backslash then digits: must not become an escape
    "Grüße, ça va? 你好 😀",
    "lone \ud800 surrogate",
    "\u2028\u0085\u200b",
]


def _lua_bytes(literal: str) -> bytes:
    runtime = lua.LuaRuntime(encoding=None)
    value = runtime.execute(("return " + literal).encode("utf-8", "surrogatepass"))
    assert isinstance(value, bytes)
    return value


@pytest.mark.parametrize("text", HOSTILE)
def test_lua_reads_the_literal_back_as_the_text(text):
    literal = lua_string(text)
    assert "\n" not in literal and "\r" not in literal
    assert _lua_bytes(literal) == text.encode("utf-8", "surrogatepass")


def test_random_texts_round_trip():
    rng = np.random.default_rng(38)
    for _ in range(300):
        codes = rng.integers(0, 0x11000, rng.integers(0, 40))
        text = "".join(chr(int(c)) for c in codes)
        assert _lua_bytes(lua_string(text)) == text.encode("utf-8", "surrogatepass")


@pytest.mark.parametrize("name", HOSTILE[:4])
def test_a_hostile_dataset_name_stays_a_name(name):
    spec = DatasetSpec(clips=1, expressions=(name,), behaviours=(name,), texts=(name,))
    draw = ClipDraw(0, 7, ((name, 0.0, 1.0, 0.5),), name, "talking", name, (0.0, 0.0, 0.0),
                    1.0, (0.0, 0.0))
    story = fdl.loads(clip_storyboard(spec, draw), name="clip.fdl")
    assert [c.name for c in story.expressions] == [name]
    assert [g.behaviour for g in story.gaze] == [name]
    assert story.speech is not None and story.speech.text == name
