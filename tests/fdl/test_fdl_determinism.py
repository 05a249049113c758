"""The same storyboard gives the same ``.fap`` in every process (issue 38, class 9):
``pairs`` ordered table and function keys by address, and ``tostring({})`` printed one,
so a script that scheduled cues from either differed from run to run."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from facelib import fdl
from facelib.errors import FdlError

ROOT = Path(__file__).resolve().parents[2]

STORY = """\
fps = 25
local names = {"joy", "sadness", "fear", "anger", "surprise", "disgust"}
local t = {}
for i, n in ipairs(names) do
  local key = (i % 2 == 0) and {} or function() return n end
  t[key] = n
end
local at = 0
for _, n in pairs(t) do show { n, at = at, dur = 0.2 }; at = at + 0.2 end
local text = tostring({}) .. tostring(print) .. string.format("%s %s", t, show)
local sum = 0
for digit in text:gmatch("%x") do sum = sum + tonumber(digit, 16) end
look { "default", "talking", 1.0, at = sum % 13 / 10, dur = 0.5 }
show { "joy", at = 1.4 + sum % 7 / 10, dur = 0.2 }
"""


def test_two_processes_write_the_same_fap(tmp_path):
    story = tmp_path / "story.fdl"
    story.write_text(STORY)
    outputs = []
    for i in range(2):
        (tmp_path / f"run{i}").mkdir()
        out = tmp_path / f"run{i}" / "story.fap"
        code = ("import sys; from facelib.cli import main; "
                f"sys.exit(main(['run', {str(story)!r}, '-o', {str(out)!r}]))")
        subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, capture_output=True)
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]


def test_table_and_function_keys_come_in_creation_order():
    story = fdl.loads(STORY, name="story.fdl")
    assert [c.name for c in story.expressions][:6] == [
        "joy", "sadness", "fear", "anger", "surprise", "disgust"]


def test_tostring_shows_no_address():
    box = fdl.Sandbox()
    fdl.loads('print(tostring({}), {}, print, string.format("%s", {}))\n'
              "local function f() end\nprint(f, tostring(f))\n", name="x.fdl", sandbox=box)
    assert "0x" not in "".join(box.printed)
    first, second = box.printed
    assert first.startswith("table: #") and second.split("\t")[0] == second.split("\t")[1]


@pytest.mark.parametrize("fmt", ["%p", "%10p", "%-p"])
def test_format_refuses_addresses(fmt):
    with pytest.raises(FdlError, match=r"%p \(an address\) is not available"):
        fdl.loads(f'local s = string.format("{fmt}", {{}})\n', name="x.fdl")
    fdl.loads('assert(string.format("%%p %d", 3) == "%p 3")\n', name="x.fdl")


def test_function_statements_keep_their_meaning():
    fdl.loads("""\
local function fact(n) if n <= 1 then return 1 end return n * fact(n - 1) end
local obj = { k = 2 }
function obj:m(x) return self.k + x end
function obj.n() return 5 end
function obj:z() return self.k end
g = function(...) return select("#", ...) end
function h
  (a, b) -- a comment with function and end in it
  for i = 1, 2 do while false do end end
  repeat until true
  return a .. b
end
assert(fact(5) == 120 and obj:m(3) == 5 and obj.n() == 5 and obj:z() == 2)
assert(g(1, nil, 3) == 3 and h("x", "y") == "xy" and [[function]] == "function")
""", name="x.fdl")
