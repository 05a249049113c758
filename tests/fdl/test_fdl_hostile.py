"""Hostile storyboards: each ends promptly in an FdlError, writes nothing, and the same
sandbox runs the next script."""

import pytest

from facelib import fdl
from facelib.errors import FdlError
from facelib.fdl.sandbox import Sandbox

GOOD = 'fps = 30\nshow { "joy", at = 0, dur = 1 }\n'

ESCAPES = {
    "os_execute": 'os.execute("touch pwned")',
    "io_open": 'io.open("pwned", "w"):write("x")',
    "require": 'require("os")',
    "package": 'package.loadlib("libc.so.6", "system")',
    "load_text": 'load("x = 1")()',
    "load_bytecode": 'load("\\27Lua\\84\\0", "b", "b")()',
    "dofile": 'dofile("/etc/passwd")',
    "loadfile": 'loadfile("/etc/passwd")',
    "string_dump": "local s = string.dump(function() end)",
    "method_dump": 'local s = ("").dump(print)',
    "getmetatable_string": 'getmetatable("").__index = {}',
    "setmetatable_gc": "setmetatable({}, { __gc = function() while true do end end })",
    "debug": "debug.sethook()",
    "collectgarbage": 'collectgarbage("stop")',
    "python_eval": "python.eval(\"__import__('os').system('touch pwned')\")",
    "python_builtins": 'python.builtins.open("pwned", "w")',
    "print_attributes": "local g = print.__globals__",
    "rawset_G": 'rawset(_G, "x", 1)',
    "G_os": '_G.os.execute("touch pwned")',
    "coroutine_loop": "coroutine.wrap(function() while true do end end)()",
    "env_upvalue": "local f = string.rep; f.x = 1",
    "error_table": "error({ code = 1 })",
}

LIMITS = {
    "endless_loop": "while true do end",
    "endless_in_pcall": "while true do pcall(function() while true do end end) end",
    "pcall_catching_budget": "for i = 1, 10 do pcall(function() while true do end end) end "
    "while true do end",
    "endless_tail_recursion": "local function f() return f() end f()",
    "endless_gsub_callback": 'string.gsub(string.rep("a", 10), "a", function() while true '
    "do end end)",
    "sort_comparator_loop": "table.sort({3, 2, 1}, function(a, b) while true do end end)",
    "string_doubling": 'local s = "x" while true do s = s .. s end',
    "table_growth": "local t = {} for i = 1, 1e12 do t[i] = {i} end",
    "rep_2_40": 'local s = string.rep("x", 2^40)',
    "rep_empty_huge": 'local s = string.rep("", 2^50)',
    "memory_in_pcall": 'while true do pcall(function() local s = "x" while true do '
    "s = s .. s end end) end",
    "deep_recursion": "local function f(n) return 1 + f(n + 1) end f(1)",
    "table_move_huge": "table.move({}, 1, 1e15, 1, {})",
    "pattern_bomb": 'local s = string.rep("a", 1e5) s:find(".-.-.-.-b")',
    "concat_nested": "local t = {} t[1] = t local s = table.concat(t)",
}


@pytest.fixture(scope="module")
def box():
    return Sandbox(max_instructions=5_000_000, max_memory=32 * 1024 * 1024)


@pytest.mark.parametrize("name", sorted({**ESCAPES, **LIMITS}))
def test_hostile_script_fails_cleanly(name, box, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    story = tmp_path / "story.fdl"
    story.write_text(f"-- hostile: {name}\n{ESCAPES.get(name) or LIMITS[name]}\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    with pytest.raises(FdlError) as info:
        fdl.load(story, sandbox=box)
    assert info.value.path == str(story.resolve())
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # wrote nothing
    # the same runtime keeps working
    sb = fdl.loads(GOOD, sandbox=box)
    assert sb.fps == 30.0
    assert sb.expressions[0].duration_ms == 1000


def test_escape_errors_name_the_line(box):
    with pytest.raises(FdlError, match=r"global 'os'") as info:
        fdl.loads("x = 1\n\nos.execute('ls')\n", sandbox=box)
    assert info.value.line == 3


def test_budget_error_names_the_loop_line(box):
    with pytest.raises(FdlError, match="instruction budget") as info:
        fdl.loads("local n = 0\nwhile true do\n  n = n + 1\nend\n", sandbox=box)
    assert info.value.line in (2, 3)


def test_default_sandbox_stops_endless_loop():
    with pytest.raises(FdlError, match="instruction budget"):
        fdl.loads("while true do end")


def test_memory_error_message(box):
    with pytest.raises(FdlError, match="memory limit"):
        fdl.loads("local t = {} for i = 1, 1e9 do t[i] = i end", sandbox=box)


def test_string_metatable_points_to_sandbox_copy(box):
    # changing the string library in one script does not leak into the next
    fdl.loads('string.upper = nil; assert(("a").upper == nil)', sandbox=box)
    sb = fdl.loads('fps = #("abc"):upper() * 10', sandbox=box)
    assert sb.fps == 30.0


def test_globals_are_a_whitelist(box):
    text = (
        "local names = {}\n"
        "for k in pairs(_ENV or {}) do names[#names + 1] = k end\n"
        "assert(_G == nil and _ENV ~= nil)\n"
        "assert(load == nil and require == nil and os == nil and io == nil and debug == nil)\n"
        "assert(string.dump == nil and math.randomseed == nil and coroutine == nil)\n"
        "assert(getmetatable == nil and setmetatable == nil and rawset == nil)\n"
    )
    fdl.loads(text, sandbox=box)


@pytest.mark.parametrize(
    "field",
    [
        'FDL = { speakSound = "../outside.wav" }',
        'FDL = { speakText = "/etc/passwd" }',
        'FDL = { expressionScript = "../../thesis/expressions.sb" }',
        'FDL = { eyesScript = "sub/../../x.sb" }',
        'FDL = { visemeScript = "link.sb" }',
        'FDL = { output = "../animation.fap" }',
        'output = "/tmp/animation.fap"',
        'say { "hi", audio = "../x.wav" }',
        'say { transcript = "../x.txt" }',
    ],
)
def test_path_traversal_refused(field, tmp_path, box):
    story_dir = tmp_path / "story"
    story_dir.mkdir()
    (tmp_path / "outside.wav").write_bytes(b"RIFF")
    (tmp_path / "x.wav").write_bytes(b"RIFF")
    (tmp_path / "x.txt").write_text("secret")
    (tmp_path / "x.sb").write_text("eyes = {}")
    (story_dir / "link.sb").symlink_to(tmp_path / "x.sb")
    with pytest.raises(FdlError, match=r"leaves the storyboard|must be relative") as info:
        fdl.loads(field, base_dir=story_dir, name="s.fdl", sandbox=box)
    assert info.value.line == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "outside.wav",
        "story",
        "x.sb",
        "x.txt",
        "x.wav",
    ]


def test_path_needs_a_folder(box):
    with pytest.raises(FdlError, match="no folder"):
        fdl.loads('FDL = { speakSound = "a.wav" }', sandbox=box)


def test_sandbox_reused_after_many_failures(box):
    for _ in range(3):
        with pytest.raises(FdlError):
            fdl.loads('local s = "x" while true do s = s .. s end', sandbox=box)
        with pytest.raises(FdlError):
            fdl.loads("while true do end", sandbox=box)
    assert fdl.loads(GOOD, sandbox=box).fps == 30.0
