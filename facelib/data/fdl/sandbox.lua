-- facelib FDL sandbox bootstrap (trusted code).
--
-- Runs once per Lua state with the full standard library, keeps what the host needs in
-- local upvalues (debug.sethook/getinfo, load, the real libraries), removes every global,
-- and returns the host's entry points. User chunks never see these locals: they run with
-- their own environment table holding only the whitelist below (plus facelib's recorders).
--
-- Arguments from the host: log (a Python callable receiving one string per print) and
-- clock (a Python callable giving monotonic seconds).

local host_log, host_clock = ...

local debug_sethook, debug_getinfo = debug.sethook, debug.getinfo
local raw_load, raw_pcall, raw_xpcall, raw_error = load, pcall, xpcall, error
local raw_type, raw_select, raw_tostring, raw_tonumber = type, select, tostring, tonumber
local raw_pairs, raw_ipairs, raw_assert = pairs, ipairs, assert
local raw_setmetatable, raw_getmetatable, raw_collect = setmetatable, getmetatable, collectgarbage
local string_lib, table_lib, math_lib, utf8_lib = string, table, math, utf8
local table_concat, str_gsub, str_find = table.concat, string.gsub, string.find
local table_sort = table.sort
local math_randomseed = math.randomseed
local string_mt = raw_getmetatable("")

-- Instructions between two calls of the count hook.
local STEP = 1000
-- Pattern functions run in C where the hook cannot stop them: refuse calls whose
-- worst-case backtracking (subject length ^ (quantifiers + 1)) exceeds this many steps.
local PATTERN_WORK = 1e8
-- string.rep and table.move loop in C even when nothing is allocated: bound their counts.
local MAX_REPEAT = 1 << 24
-- Work done in C by the string and table libraries is charged to the instruction budget:
-- one instruction per byte (or element) it touches, before the call where the size is known
-- and after it otherwise, so loops of cheap-looking library calls end like any other loop.
local BYTES_PER_INSTRUCTION = 1

-- Unique error value that marks a sandbox limit; user code can never obtain it.
local FATAL = raw_setmetatable({}, { __tostring = function() return "sandbox limit" end })

local state = { used = 0, budget = 0, source = "", line = -1, fatal = false, err_line = -1,
                deadline = 0 }

local function over_limits()
  if state.used > state.budget then
    if not state.fatal then state.fatal = "instructions" end
    raw_error(FATAL, 0)
  end
  if host_clock() > state.deadline then
    if not state.fatal then state.fatal = "time" end
    raw_error(FATAL, 0)
  end
end

local function hook()
  state.used = state.used + STEP
  local info = debug_getinfo(2, "Sl")
  if info and info.source == state.source and info.currentline > 0 then
    state.line = info.currentline
  end
  over_limits()
end

-- Charge ``n`` units of C work (bytes or elements) to the budget; stops the script when the
-- budget or the time limit is spent.
local function charge(n)
  state.used = state.used + 16 + n // BYTES_PER_INSTRUCTION
  over_limits()
end

local function charged_after(fn)
  return function(...)
    local r1, r2, r3 = fn(...)
    if raw_type(r1) == "string" then charge(#r1) else charge(0) end
    return r1, r2, r3
  end
end

local function check_fatal(ok, ...)
  if not ok then
    local e = ...
    if e == "not enough memory" and not state.fatal then state.fatal = "memory" end
    if e == FATAL or state.fatal then raw_error(FATAL, 0) end
  end
  return ok, ...
end

-- pcall for user code: catches ordinary errors, never a sandbox limit.
local function safe_pcall(f, ...)
  return check_fatal(raw_pcall(f, ...))
end

-- Every table and function a chunk can reach gets a birth number in creation order: the
-- chunk's constructors are marked (__fdl_at for tables, __fdl_fn for functions), the
-- libraries are numbered when the environment is built, and anything else on first sight.
-- pairs orders keys that have no value order by it, and tostring prints it instead of an
-- address, so neither leaks the allocator's addresses into a storyboard.
local birth = raw_setmetatable({}, { __mode = "k" })
local births = 0

local function born(v)
  local n = birth[v]
  if n == nil then
    births = births + 1
    n = births
    birth[v] = n
  end
  return n
end

local function renumber(v)
  births = births + 1
  birth[v] = births
end

local OBJECT = { table = true, ["function"] = true, userdata = true, thread = true }

local function safe_tostring(v)
  local kind = raw_type(v)
  if OBJECT[kind] then return kind .. ": #" .. born(v) end
  return raw_tostring(v)
end

local function safe_print(...)
  local n = raw_select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = safe_tostring((raw_select(i, ...))) end
  local text = table_concat(parts, "\t")
  charge(#text)
  host_log(text)
end

-- pairs in a stable order, whatever the string hash seed of this Lua state and whatever
-- the addresses of its objects: numbers first (ascending), then strings (byte order), then
-- booleans (false first), then tables and functions in the order they were made. The
-- snapshot of keys is taken when the loop starts, so assigning to existing fields while
-- iterating is safe, as with pairs.
local KEY_RANK = { number = 1, string = 2, boolean = 3 }
local function key_before(a, b)
  local ta, tb = raw_type(a), raw_type(b)
  local ra, rb = KEY_RANK[ta] or 4, KEY_RANK[tb] or 4
  if ra ~= rb then return ra < rb end
  if ra == 4 then return born(a) < born(b) end
  if ta == "boolean" then return (not a) and b end
  return a < b
end

local function stable_pairs(t)
  local keys = {}
  for k in raw_pairs(t) do keys[#keys + 1] = k end
  charge(#keys * 20)
  table_sort(keys, key_before)
  local i = 0
  local function step()
    i = i + 1
    local k = keys[i]
    if k == nil then return nil end
    return k, t[k]
  end
  born(step)
  return step, t, nil
end

local function copy(t, drop)
  local c = {}
  for k, v in raw_pairs(t) do
    if not (drop and drop[k]) then c[k] = v end
  end
  return c
end

local function guard_pattern(fn, name, pattern_arg)
  return function(s, p, ...)
    local n = #raw_tostring(s)
    charge(n)
    if raw_type(p) == "string" or raw_type(p) == "number" then
      local plain = name == "find" and raw_select(2, ...)
      if not plain then
        local text = raw_tostring(p)
        local _, q = str_gsub(text, "[%*%+%-%?]", "")
        -- %b and %f scan ahead from every start position; a back-reference rescans a capture
        local _, scans = str_gsub(text, "%%[bf1-9]", "")
        q = q + scans
        if pattern_arg and n > 0 and (n + 1.0) ^ (q + 1) > PATTERN_WORK then
          raw_error("string." .. name .. ": pattern with " .. q .. " quantifiers on a "
            .. n .. "-byte string is too costly for the sandbox", 2)
        end
      end
    end
    return fn(s, p, ...)
  end
end

-- string.format without addresses: %p (an object's or a string's address) is refused and
-- tables and functions given to %s are shown as tostring shows them.
local function safe_format(fmt, ...)
  if raw_type(fmt) == "string" then
    local bare = str_gsub(fmt, "%%%%", "")
    if str_find(bare, "%%[-+ #0]*%d*%.?%d*p") then
      raw_error("string.format: %p (an address) is not available in the sandbox", 2)
    end
  end
  local n = raw_select("#", ...)
  local args = { ... }
  for i = 1, n do
    if OBJECT[raw_type(args[i])] then args[i] = safe_tostring(args[i]) end
  end
  return string_lib.format(fmt, table_lib.unpack(args, 1, n))
end

local function guarded_string()
  local s = copy(string_lib, { dump = true })
  s.find = guard_pattern(string_lib.find, "find", true)
  s.match = guard_pattern(string_lib.match, "match", true)
  s.gmatch = guard_pattern(string_lib.gmatch, "gmatch", true)
  s.gsub = guard_pattern(string_lib.gsub, "gsub", true)
  local rep = string_lib.rep
  s.rep = function(str, count, sep)
    local c = raw_tonumber(count)
    if c and c > MAX_REPEAT then
      raw_error("string.rep: count " .. raw_tostring(count) .. " is larger than the sandbox allows ("
        .. MAX_REPEAT .. ")", 2)
    end
    if c and c > 0 then
      charge(c * (#raw_tostring(str) + (sep and #raw_tostring(sep) or 0)))
    end
    return rep(str, count, sep)
  end
  for _, name in raw_ipairs({ "upper", "lower", "reverse", "sub", "char", "byte",
                              "pack", "unpack" }) do
    s[name] = charged_after(string_lib[name])
  end
  s.format = charged_after(safe_format)
  local gmatch = s.gmatch
  s.gmatch = function(...)
    local iterator = gmatch(...)
    born(iterator)
    return iterator
  end
  return s
end

local function guarded_table()
  local t = copy(table_lib)
  local move = table_lib.move
  t.move = function(a1, f, e, tpos, a2)
    local ff, ee = raw_tonumber(f), raw_tonumber(e)
    if ff and ee and ee - ff >= MAX_REPEAT then
      raw_error("table.move: range " .. raw_tostring(f) .. ".." .. raw_tostring(e)
        .. " is larger than the sandbox allows", 2)
    end
    if ff and ee and ee >= ff then charge(ee - ff + 1) end
    return move(a1, f, e, tpos, a2)
  end
  t.concat = charged_after(table_lib.concat)
  local unpack = table_lib.unpack
  t.unpack = function(list, i, j)
    local ii, jj = raw_tonumber(i) or 1, raw_tonumber(j) or #list
    if jj >= ii then charge(jj - ii + 1) end
    return unpack(list, i, j)
  end
  local pack = table_lib.pack
  t.pack = function(...)
    local packed = pack(...)
    born(packed)
    return packed
  end
  local sort = table_lib.sort
  t.sort = function(list, cmp)
    local n = #list
    charge(n * 20)
    return sort(list, cmp)
  end
  return t
end

-- Recorder for facelib's storyboard functions (say, show, look, ...): remembers the call,
-- its first argument and the user line it came from; the host validates afterwards.
local function recorder(calls, kind)
  return function(...)
    local info = debug_getinfo(2, "Sl")
    local line = (info and info.source == state.source) and info.currentline or -1
    calls[#calls + 1] = { kind, (...), line, raw_select("#", ...) }
  end
end

-- Birth numbers for what the environment holds, in name order (libraries and their
-- functions), and for the static iterators ipairs and utf8.codes return.
local function sorted_names(t)
  local names = {}
  for k in raw_pairs(t) do names[#names + 1] = k end
  table_sort(names)
  return names
end

local function number_env(env)
  renumber(env)
  for _, name in raw_ipairs(sorted_names(env)) do
    local value = env[name]
    renumber(value)
    if raw_type(value) == "table" then
      for _, inner in raw_ipairs(sorted_names(value)) do
        if OBJECT[raw_type(value[inner])] then renumber(value[inner]) end
      end
    end
  end
  renumber((raw_ipairs({})))
  renumber((utf8_lib.codes("")))
end

local function new_env(api_names, calls)
  local s = guarded_string()
  string_mt.__index = s
  local env = {
    string = s,
    table = guarded_table(),
    math = copy(math_lib, { randomseed = true }),
    utf8 = copy(utf8_lib),
    pairs = stable_pairs,
    ipairs = raw_ipairs,
    select = raw_select,
    type = raw_type,
    tostring = safe_tostring,
    tonumber = raw_tonumber,
    error = raw_error,
    pcall = safe_pcall,
    assert = raw_assert,
    print = safe_print,
  }
  for _, name in raw_ipairs(api_names) do env[name] = recorder(calls, name) end
  number_env(env)
  return env
end

local function handler(e)
  if e == FATAL or state.fatal then return FATAL end
  for level = 2, 200 do
    local info = debug_getinfo(level, "Sl")
    if not info then break end
    if info.source == state.source and info.currentline > 0 then
      state.err_line = info.currentline
      break
    end
  end
  if raw_type(e) ~= "string" then
    e = "error object is a " .. raw_type(e) .. " value"
  end
  return e
end

-- run(original, marked, chunkname, budget, seed, api_names, seconds)
--   original: the user's text, compiled once to report its own syntax errors.
--   marked: the same text with table constructors wrapped in __fdl_at(line, {...}) and
--   function constructors in __fdl_fn(function ... end).
-- Returns true, env, lines, calls, used  or  false, kind, message, line, used
-- with kind one of "syntax", "runtime", "instructions", "memory".
local function run(original, marked, chunkname, budget, seed, api_names, seconds)
  local f, err = raw_load(original, chunkname, "t", {})
  if not f then return false, "syntax", err, -1, 0 end
  f = nil
  local calls = {}
  local lines = raw_setmetatable({}, { __mode = "k" })
  births = 0
  local env = new_env(api_names, calls)
  local function at(line, t)
    if raw_type(t) == "table" and raw_type(line) == "number" then lines[t] = line end
    born(t)
    return t
  end
  local function fn(f)
    born(f)
    return f
  end
  renumber(at)
  renumber(fn)
  f, err = raw_load(marked, chunkname, "t", env)
  if not f then return false, "syntax", err, -1, 0 end
  math_randomseed(seed)
  state.used, state.budget, state.source = 0, budget, chunkname
  state.line, state.fatal, state.err_line = -1, false, -1
  state.deadline = host_clock() + seconds
  debug_sethook(hook, "", STEP)
  local ok, e = raw_xpcall(f, handler, at, fn)
  debug_sethook()
  if ok then return true, env, lines, calls, state.used end
  f, env, lines, calls = nil, nil, nil, nil
  raw_collect("collect")
  if state.fatal then return false, state.fatal, "", state.line, state.used end
  if e == "not enough memory" then return false, "memory", "", state.line, state.used end
  return false, "runtime", raw_tostring(e), state.err_line, state.used
end

local function collect()
  raw_collect("collect")
end

-- The user must not reach the real libraries through the global table or the string
-- metatable; lock the latter against getmetatable (never exposed anyway).
string_mt.__metatable = false
local G = _G
for k in raw_pairs(G) do G[k] = nil end

return run, collect
