-- fuzz.lua -- random calls of every documented dmech function, method and
-- field with hostile arguments, mutated files for every file reader, and
-- the replay of the corpus of past failures.  Run by dmech-fuzz (see
-- fuzz_host.c; plain dmech works too, without time limits):
--
--   dmech-fuzz fuzz.lua api <calls> [seed]     random API calls
--   dmech-fuzz fuzz.lua files <files> [seed]   mutated input files
--   dmech-fuzz fuzz.lua replay <dir>           tests/data/fuzz: every case
--
-- A call fails when dmech crashes or a sanitizer reports (the process
-- dies: the reproducer of the call was written to ./last.lua first, which
-- tests/fuzz/run.sh keeps), when a call hangs (dmech-fuzz exits 3), or
-- when an error message
-- is malformed: not a string, empty, or showing "'?'" for a function name,
-- "-nan", "(null)", a path inside dmech's Lua library (an internal error
-- leaking out) or a traceback.  A reader's error must name the file.
-- Every failure is written to $FUZZ_OUT as a case for tests/data/fuzz/.
-- $FUZZ_TIME_LIMIT (0.5 s) and $FUZZ_HARD_LIMIT (20 s more) bound a call,
-- $FUZZ_MEMORY_MB (4096; 0: none) the address space.
-- Output is TAP; the script returns the exit status.
local dm = require "dmech"
local here = (arg and arg[0] or "tests/fuzz/fuzz.lua"):match("^(.*)/[^/]*$") or "."
local V = dofile(here .. "/values.lua")
local H, HN = V.hostile, V.names
local host = package.loaded.fuzz
local OUT = os.getenv("FUZZ_OUT") or "."
local LIMIT = tonumber(os.getenv("FUZZ_TIME_LIMIT") or "") or 0.5

-- The file readers.  Adding a reader is one line: a name, how to load a
-- path (returning the object, or nil and a message, or raising), and seed
-- files (shell patterns relative to the source tree; "*gen*" files are
-- written below).
local READERS = {
  {name = "csv", load = function(p) return dm.load_trajectory(p) end, seeds = "gen:*.csv"},
  {name = "mesh", load = function(p) return dm.mesh.load(p) end,
   seeds = "tests/data/dec/*.off tests/data/dec/*.obj tests/data/dec/*.msh"},
  {name = "hdf5", load = function(p) return dm.load_trajectory(p) end, seeds = "tests/data/ensemble/*.h5"},
}

-- Functions not fuzzed: they end the process, print TAP or pass raw
-- commands to gnuplot by design.
local SKIP = {["dm.test"] = true, ["dm.gnuplot"] = true, ["dm.show"] = true}
local function skipped(name)
  return SKIP[name] or name:find("^dm%.test%.") or name:find("^dm%._gp%.")
end

-- {==== utilities ==========================================================

local rng_state = 1
local function seed(s) rng_state = (math.tointeger(s) or 1) % 2147483647 + 1 end
local function rand(n)                     -- 1..n, Park-Miller: the same everywhere
  rng_state = (rng_state * 48271) % 2147483647
  return rng_state % n + 1
end

-- TAP goes to the real standard output (dmech-fuzz points the process's
-- stdout at /dev/null: help() and friends print a lot).
local report = host and host.report or function(s) io.write(s) io.flush() end
local n_tap, n_fail = 0, 0
local function tap(ok, text)
  n_tap = n_tap + 1
  report((ok and "ok " or "not ok ") .. n_tap .. " - " .. text .. "\n")
  if not ok then n_fail = n_fail + 1 end
end
local function diag(text)
  for line in (tostring(text) .. "\n"):gmatch("(.-)\n") do report("# " .. line .. "\n") end
end

-- The reproducer of the call about to run, in ./last.lua: one handle kept
-- open and rewritten in place (opening a file per call costs milliseconds
-- on some disks), padded so that a shorter text leaves no tail behind.
local last_handle, last_len = nil, 0
local function set_last(text)
  if not last_handle then last_handle = assert(io.open("last.lua", "w")) end
  local pad = math.max(0, last_len - #text)
  last_handle:seek("set", 0)
  last_handle:write(text, string.rep(" ", pad))
  last_handle:flush()
  last_len = math.max(last_len, #text)
end
local function clear_last()
  if last_handle then last_handle:close() last_handle = nil end
  os.remove("last.lua")
  last_len = 0
end

local function write_file(path, data)
  local f = assert(io.open(path, "wb"))
  f:write(data)
  f:close()
end
local function read_file(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local s = f:read("a")
  f:close()
  return s
end

-- Lua source for a hostile value or a pool object (for reproducers).
local function src_of(a)
  if a.h then return ("H[%q]"):format(a.h) end
  if a.p then return ("P[%q]"):format(a.p) end
  if a.opts then
    local parts = {}
    for _, kv in ipairs(a.opts) do parts[#parts + 1] = ("[%q] = %s"):format(kv[1], src_of(kv[2])) end
    return "{" .. table.concat(parts, ", ") .. "}"
  end
  return "nil"
end
local function val_of(a, P)
  if a.h then return H[a.h] end
  if a.p then return P[a.p] end
  if a.opts then
    local t = {}
    for _, kv in ipairs(a.opts) do t[kv[1]] = val_of(kv[2], P) end
    return t
  end
end

-- }====

-- {==== judging an error message ===========================================

local BAD = {
  {"to '%?'", "a function named '?'"},
  {"%-nan", "'-nan' printed"},
  {"%(null%)", "'(null)' printed"},
  {"lua/dmech/[%w_]+%.lua:%d+:", "an internal error of dmech's Lua library"},
  {"stack traceback", "a traceback inside the message"},
}

-- nil when fine, else what is wrong.  input: the text of the file read,
-- whose quoted parts may contain anything ("not a number: '-nan1 0'").
local function judge(ok, err, own_errors, input)
  if ok then return nil end
  if own_errors[err] then return nil end   -- a hostile callback's own error object
  if type(err) ~= "string" then return "error object is a " .. type(err) end
  if err == "" then return "empty error message" end
  if err:find("fuzz: time limit", 1, true) or err:find("boom from a callback", 1, true)
     or err:find("evil __", 1, true) then
    return nil
  end
  local own = input and err:gsub("'([^']*)'", function(q)
    if input:find(q, 1, true) then return "''" end
  end) or err
  for _, b in ipairs(BAD) do
    if own:find(b[1]) then return b[2] end
  end
  if #err > 4000 then return "message of " .. #err .. " bytes" end
  return nil
end

-- }====

-- {==== the API ============================================================

-- Every documented name with how to reach it.
local function catalog()
  local docs, vals = dm.docs()
  local byname, entries = {}, {}
  for v, name in pairs(vals) do byname[name] = v end
  for name, d in pairs(docs) do
    if not skipped(name) then
      local kind, sep, member = name:match("^([%w_]+)([:.])([%w_]+)$")
      local e = {name = name, opts = d.opts, sig = d.sig or ""}
      if name:find("^dm%.") then
        e.call = byname[name]
        if type(e.call) ~= "function" then
          local v = dm
          for part in name:gmatch("[^.]+") do if part ~= "dm" then v = type(v) == "table" and v[part] or nil end end
          e.call = type(v) == "function" and v or nil
        end
      elseif kind and sep == ":" then
        e.kind, e.method = kind, member
        e.call = byname[name] or package.loaded[name]   -- see ldoc.c name_methods
      elseif kind then
        e.kind, e.field = kind, member
      end
      if e.call or e.field then entries[#entries + 1] = e end
    end
  end
  table.sort(entries, function(a, b) return a.name < b.name end)
  return entries
end

local function hostile_arg() return {h = HN[rand(#HN)]} end

local function pool_arg(K)
  local kinds = {}
  for k in pairs(K) do kinds[#kinds + 1] = k end
  table.sort(kinds)
  local names = K[kinds[rand(#kinds)]]
  return {p = names[rand(#names)]}
end

local function arg_for(e, K)
  local r = rand(10)
  if r <= 6 then return hostile_arg() end
  if r <= 8 then return pool_arg(K) end
  -- an options table: documented keys with hostile or pool values
  local keys = e.opts or {}
  if #keys == 0 then for k in e.sig:gmatch("([%a_][%w_]*)=") do keys[#keys + 1] = k end end
  if #keys == 0 then return hostile_arg() end
  local t = {}
  for _ = 1, rand(3) do
    t[#t + 1] = {keys[rand(#keys)], rand(4) == 1 and pool_arg(K) or hostile_arg()}
  end
  return {opts = t}
end

-- One random call as a description {name=, self=, args=, field=, set=}.
local function make_call(e, K)
  local c = {entry = e, args = {}}
  if e.kind then
    c.self = (K[e.kind] and rand(10) > 1) and {p = K[e.kind][rand(#K[e.kind])]} or
             (rand(2) == 1 and pool_arg(K) or hostile_arg())
  end
  if e.field then
    c.set = rand(3) == 1 and arg_for(e, K) or nil
    return c
  end
  for i = 1, rand(5) - 1 do c.args[i] = arg_for(e, K) end
  return c
end

local function call_source(c)
  local e, a = c.entry, {}
  for i, x in ipairs(c.args) do a[i] = src_of(x) end
  if e.field then
    if c.set then return ("%s[%q] = %s"):format(src_of(c.self), e.field, src_of(c.set)) end
    return ("local _ = %s[%q]"):format(src_of(c.self), e.field)
  end
  if e.method then
    table.insert(a, 1, src_of(c.self))
    return ("return F[%q](%s)"):format(e.name, table.concat(a, ", "))
  end
  return ("return F[%q](%s)"):format(e.name, table.concat(a, ", "))
end

local function reproducer(c, why, seedtext)
  return ("-- fuzz case: %s\n-- %s\nreturn function(P, H, F)\n%s\nend\n"):format(
    why, seedtext, call_source(c))
end

-- name -> function for every documented function and method, for the
-- cases (methods by name, not through self)
local function functions()
  local F = {}
  for _, e in ipairs(catalog()) do if e.call then F[e.name] = e.call end end
  return F
end

-- Functions are called straight from C (host.call or pcall), as a user's
-- pcall(f, ...) would: error messages must then name them by themselves.
local function run_call(c, P, F)
  local e = c.entry
  local f, args = nil, {}
  if e.field then
    local obj, v = val_of(c.self, P), c.set and val_of(c.set, P)
    f = c.set and function() obj[e.field] = v end or function() local _ = obj[e.field] end
  else
    f = F[e.name] or e.call
    if e.method then args[1] = val_of(c.self, P) end
    for _, x in ipairs(c.args) do args[#args + 1] = val_of(x, P) end
  end
  local n = (e.method and 1 or 0) + #c.args
  local ok, err
  if host then ok, err = host.call(LIMIT, f, table.unpack(args, 1, n))
  else ok, err = pcall(f, table.unpack(args, 1, n)) end
  return judge(ok, err, {}), err, ok
end

local function probe()
  local ok, n = pcall(function() return dm.vec{3, 4}:norm() end)
  return ok and n == 5
end

local function fuzz_api(ncalls, s)
  seed(s)
  local P, K, failed = V.pool()
  local F = functions()
  if #failed > 0 then diag("pool objects not built: " .. table.concat(failed, "; ")) end
  local entries = catalog()
  local bad, interrupted, t0 = 0, 0, os.clock()
  local seen, slow, succeeded = {}, {}, 0
  local now = host and host.now or os.clock
  for i = 1, ncalls do
    local e = entries[rand(#entries)]
    local c = make_call(e, K)
    local seedtext = ("found by: dmech-fuzz fuzz.lua api %d %s (call %d)"):format(ncalls, s, i)
    set_last(reproducer(c, "crash or hang in " .. e.name, seedtext))
    if os.getenv("FUZZ_TRACE") then io.stderr:write(i, ": ", call_source(c), "\n") end
    local tc = now()
    local why, err, ok = run_call(c, P, F)
    if ok then succeeded = succeeded + 1 end
    slow[e.name] = (slow[e.name] or 0) + now() - tc
    if type(err) == "string" and err:find("fuzz: time limit", 1, true) then interrupted = interrupted + 1 end
    if why then
      local key = e.name .. ": " .. why
      if not seen[key] then
        seen[key] = true
        bad = bad + 1
        local file = ("%s/api-%s-%d.lua"):format(OUT, e.name:gsub("[^%w]", "_"), i)
        write_file(file, reproducer(c, why .. ": " .. tostring(err):sub(1, 300), seedtext))
        diag(("%s: %s\n  %s\n  case: %s"):format(e.name, why, tostring(err):sub(1, 300), file))
      end
    end
    if i % 1000 == 0 and not probe() then
      bad = bad + 1
      diag("the session is no longer usable after call " .. i)
      break
    end
    if i % 100 == 0 then collectgarbage() end
  end
  clear_last()
  local names = {}
  for k in pairs(slow) do names[#names + 1] = k end
  table.sort(names, function(a, b) return slow[a] > slow[b] end)
  local top = {}
  for k = 1, math.min(5, #names) do top[k] = ("%s %.1f s"):format(names[k], slow[names[k]]) end
  diag("most time: " .. table.concat(top, ", "))
  tap(bad == 0, ("api: %d calls of %d documented names (seed %s), %d returned, %d stopped at "
                 .. "the time limit, %d distinct failures, %.1f s CPU"):format(ncalls, #entries, s,
                 succeeded, interrupted, bad, os.clock() - t0))
end

-- }====

-- {==== files ================================================================

local TOKENS = {"nan", "-inf", "1e999", "-0", "99999999999999999999", "4294967295", "-1",
  "\0", ",", ",,", "\n", "\r\n", "#", "# kinds q", "# meta x=\\x00", "$", "\"", " ",
  string.rep("9", 400), string.rep("x,", 300), "0x1p-1074", "t", "1.5", "2.385"}

local function mutate(data)
  for _ = 1, rand(4) do
    local n, op = #data, rand(9)
    local i = n > 0 and rand(n) or 1
    local j = math.min(n, i + rand(64) - 1)
    if op == 1 and n > 0 then                      -- flip a byte
      data = data:sub(1, i - 1) .. string.char((data:byte(i) + rand(255)) % 256) .. data:sub(i + 1)
    elseif op == 2 then data = data:sub(1, i - 1) .. data:sub(j + 1)            -- delete
    elseif op == 3 then data = data:sub(1, j) .. data:sub(i, j) .. data:sub(j + 1) -- duplicate
    elseif op == 4 then data = data:sub(1, i - 1) .. TOKENS[rand(#TOKENS)] .. data:sub(i)
    elseif op == 5 then data = data:sub(1, i)                                  -- truncate
    elseif op == 6 then                                                      -- a line 200 times
      local line = data:match("[^\n]*\n", i) or "0\n"
      data = data .. line:rep(200)
    elseif op == 7 then data = data:gsub("[%d.]+", TOKENS[rand(#TOKENS)], 1 + rand(3))
    elseif op == 8 then data = data:gsub("\n", "\r\n")
    else data = data:sub(i) .. data:sub(1, i - 1) end                        -- rotate
  end
  return data
end

local function generated_seeds(dir)
  local files = {}
  local tr = dm.trajectory{t = {0, 0.5, 1}, coords = {"x", "y"}, q = {x = {2.385, 1, 0}, y = {0, -1, 1e-300}},
    p = {x = {1, 2, 3}, y = {4, 5, 6}}, columns = {energy = {1, 1, 1}}, meta = {system = "s", h = 0.5}}
  tr:save(dir .. "/gen1.csv")
  write_file(dir .. "/gen2.csv", "t,a,b\n0,1,2\n1,3,4\n")
  files[1], files[2] = dir .. "/gen1.csv", dir .. "/gen2.csv"
  return files
end

local function seeds_of(r, srcdir, gendir)
  if r.seeds == "gen:*.csv" then return generated_seeds(gendir) end
  local files = {}
  for pat in r.seeds:gmatch("%S+") do
    local p = io.popen("ls -1 " .. srcdir .. "/" .. pat .. " 2>/dev/null")
    for line in p:lines() do files[#files + 1] = line end
    p:close()
  end
  return files
end

local loaded = 0       -- files a reader accepted

-- Load one file with a reader; nil when fine, else what is wrong.
local function check_file(r, path, data)
  local function body()
    local obj, msg = r.load(path)
    if obj == nil then error(msg or "(nil and no message)", 0) end
    local _ = tostring(obj)
  end
  local ok, err
  if host then ok, err = host.call(LIMIT * 4, body) else ok, err = pcall(body) end
  loaded = loaded + (ok and 1 or 0)
  local why = judge(ok, err, {}, data)
  if not why and not ok and not tostring(err):find(path:match("[^/]*$"), 1, true)
     and not tostring(err):find("fuzz: time limit", 1, true) then
    why = "the message does not name the file"
  end
  return why, err
end

local function fuzz_files(nfiles, s)
  local srcdir = os.getenv("DMECH_SRCDIR") or "."
  local work = "files"
  os.execute("mkdir -p " .. work)
  for _, r in ipairs(READERS) do
    seed(s)
    loaded = 0
    local seeds, bad, t0 = seeds_of(r, srcdir, work), 0, os.clock()
    local datas = {}
    for k, f in ipairs(seeds) do datas[k] = {data = read_file(f), ext = f:match("%.%w+$") or ""} end
    for i = 1, (#datas > 0 and nfiles or 0) do
      local sd = datas[rand(#datas)]
      local path = ("%s/%s-%d%s"):format(work, r.name, i, sd.ext)
      local data = mutate(sd.data)
      write_file(path, data)
      set_last(("-- crash or hang reading %s with reader %s (seed %s, file %d)\n"):format(path, r.name, s, i))
      local why, err = check_file(r, path, data)
      if why then
        bad = bad + 1
        local keep = ("%s/%s-%s-%d%s"):format(OUT, r.name, s, i, sd.ext)
        write_file(keep, read_file(path))   -- (another file system, maybe)
        os.remove(path)
        diag(("%s: %s\n  %s\n  file: %s"):format(r.name, why, tostring(err):sub(1, 300), keep))
      else
        os.remove(path)
      end
    end
    clear_last()
    tap(bad == 0 and #seeds > 0, ("files: %d mutated %s files from %d seeds (seed %s), %d read "
        .. "without error, %d failures, %.1f s CPU"):format(nfiles, r.name, #seeds, s, loaded, bad,
        os.clock() - t0))
  end
end

-- }====

-- {==== replay ===============================================================

local function replay(dir)
  local p = io.popen("ls -1 '" .. dir .. "' 2>/dev/null")
  local names = {}
  for line in p:lines() do names[#names + 1] = line end
  p:close()
  local P, K = V.pool()
  local F = functions()
  local ncases = 0
  for _, name in ipairs(names) do
    local path = dir .. "/" .. name
    if name:find("%.lua$") then
      ncases = ncases + 1
      local case = assert(loadfile(path))()
      local ok, err
      local function body() return case(P, H, F) end
      if host then ok, err = host.call(LIMIT * 4, body) else ok, err = pcall(body) end
      local why = judge(ok, err, {})
      tap(not why and probe(), ("replay %s%s"):format(name, why and (": " .. why .. ": " .. tostring(err)) or ""))
    else
      local rname = name:match("^(%w+)%-")
      for _, r in ipairs(READERS) do
        if r.name == rname then
          ncases = ncases + 1
          local why, err = check_file(r, path, read_file(path))
          tap(not why, ("replay %s%s"):format(name, why and (": " .. why .. ": " .. tostring(err)) or ""))
        end
      end
    end
  end
  if ncases == 0 then tap(false, "no cases found in " .. dir) end
end

-- }====

local mode = ...
local a2, a3 = select(2, ...)
local mem = tonumber(os.getenv("FUZZ_MEMORY_MB") or "") or 4096
if host and mem > 0 then host.limit_memory(mem) end
if mode == "api" then
  fuzz_api(tonumber(a2) or 1000, a3 or "1")
elseif mode == "files" then
  fuzz_files(tonumber(a2) or 100, a3 or "1")
elseif mode == "replay" then
  replay(a2 or "tests/data/fuzz")
else
  io.stderr:write("usage: dmech-fuzz fuzz.lua api <calls> [seed] | files <n> [seed] | replay <dir>\n")
  return 2
end
report("1.." .. n_tap .. "\n")
return n_fail == 0 and 0 or 1
