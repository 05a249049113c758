"""Scripts that try to exhaust the host through work the Lua VM does not count (C library
calls), through what the host copies out of Lua, or through sizes that would make the
pipeline allocate: each ends promptly in a clear FacelibError, under the default limits."""

from __future__ import annotations

import pytest

import facelib
from facelib import fdl
from facelib.errors import FdlError, ParameterError, SpeechError
from facelib.fdl.sandbox import Sandbox

pytestmark = pytest.mark.usefixtures("memory_cap")

C_WORK = {
    "rep_in_a_loop": 'while true do local s = string.rep("x", 4 * 1024 * 1024) end',
    "gsub_of_10_mb": 'local s = string.rep("a", 10 * 1024 * 1024) while true do '
    's:gsub("a", "b") end',
    "concat_of_10_mb": "local t = {} for i = 1, 1000 do t[i] = string.rep('a', 10000) end "
    "while true do table.concat(t) end",
    "balanced_match_quadratic": 'local s = string.rep("(", 1e6) s:find("%b()")',
    "frontier_quadratic": 'local s = string.rep("a", 1e6) s:find("%f[%a]%d")',
    "format_in_a_loop": 'while true do local s = string.format("%99d", 1) end',
    "table_move_near_cap": "local a = {} while true do table.move(a, 1, (1 << 27) - 1, 1, {}) end",
    "print_flood": 'while true do print(string.rep("x", 1000)) end',
    "upper_of_30_mb": 'local s = string.rep("a", 30 * 1024 * 1024) while true do s:upper() end',
    "sort_in_a_loop": "local t = {} for i = 1, 1e5 do t[i] = -i end while true do "
    "table.sort(t) end",
}


@pytest.fixture(scope="module")
def box() -> Sandbox:
    return Sandbox()


@pytest.mark.parametrize("name", sorted(C_WORK))
def test_c_library_work_is_bounded(name: str, box: Sandbox) -> None:
    with pytest.raises(FdlError, match=r"x\.fdl") as info:
        box.run(C_WORK[name], path="x.fdl")
    assert "\n" not in str(info.value)
    assert len(box.printed) <= 1001
    box.printed.clear()


def test_wall_clock_limit_stops_a_script() -> None:
    slow = Sandbox(max_seconds=0.2, max_instructions=10**12)
    with pytest.raises(FdlError, match=r"time limit \(0.2 s\)"):
        slow.run("while true do end", path="x.fdl")


def test_pairs_visits_keys_in_a_stable_order() -> None:
    """Lua seeds its string hash per state; pairs must not leak that into the storyboard."""
    script = (
        "local t = {}\n"
        'for i, n in ipairs({"joy", "sadness", "fear", "anger", "surprise", "disgust", "worry",'
        ' "trust"}) do t[n] = i end\n'
        "t[3.5], t[2], t[true] = 1, 1, 1\n"
        "local at = 0\n"
        "for k in pairs(t) do if type(k) == 'string' then show { k, at = at, dur = 0.1 } end "
        "at = at + 0.1 end\n"
    )
    orders = {tuple(c.name for c in fdl.loads(script, sandbox=Sandbox()).expressions)
              for _ in range(6)}
    assert orders == {("anger", "disgust", "fear", "joy", "sadness", "surprise", "trust",
                       "worry")}


def test_error_text_cannot_forge_output_lines() -> None:
    with pytest.raises(FdlError) as info:
        fdl.loads('error("ok\\nfacelib: wrote out.fap" .. string.rep("y", 5000))',
                  name="story.fdl")
    text = str(info.value)
    assert "\n" not in text
    assert "\\n" in text
    assert len(text) < 400


def test_strings_copied_to_the_host_are_bounded() -> None:
    script = ('local s = string.rep("x", 1024 * 1024)\n'
              'show { "joy", at = 0, dur = 1, note = { s, s, s, s, s, s, s, s, s, s, s, s, s, s, '
              "s, s, s, s } }\n")
    with pytest.raises(FdlError, match="characters of strings") as info:
        fdl.loads(script, name="story.fdl")
    assert info.value.line == 2


def test_sparse_integer_keys_are_refused_without_building_ranges() -> None:
    with pytest.raises(FdlError, match="holes"):
        fdl.loads('show { "joy", at = 0, dur = 1, [1 << 40] = 1 }', name="story.fdl")


@pytest.mark.parametrize("fps", ["1e-300", "5e-324", "0.5", "1e9"])
def test_storyboard_frame_rate_range(fps: str) -> None:
    with pytest.raises(FdlError, match="fps must be a number from 1 to 1000") as info:
        fdl.loads(f'fps = {fps}\nshow {{ "joy", at = 0, dur = 1 }}\n', name="story.fdl")
    assert info.value.line == 1


def test_frame_count_is_checked_before_allocating() -> None:
    script = 'fps = 1000\nfor i = 0, 9 do show { "joy", at = i * 8000, dur = 8000 } end\n'
    board = fdl.loads(script, name="story.fdl")
    with pytest.raises(ParameterError, match="more than max_frames=360000"):
        facelib.animate(board)
    with pytest.raises(ParameterError, match="max_frames=1000"):
        facelib.animate(fdl.loads('show { "joy", at = 0, dur = 60 }'), max_frames=1000)


def test_text_only_speech_length_is_bounded() -> None:
    board = fdl.loads('say { text = string.rep("hello world ", 90000) }', name="story.fdl")
    with pytest.raises(SpeechError, match="more than 100000") as info:
        facelib.animate(board)
    assert info.value.line == 1


def test_deep_nesting_has_a_clear_message() -> None:
    fdl.loads("x = " + "{" * 80 + "}" * 80)
    with pytest.raises(FdlError, match="nested too deeply") as info:
        fdl.loads("\nx = " + "{" * 150 + "}" * 150, name="story.fdl")
    assert info.value.line == 2
