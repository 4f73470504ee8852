-- dmech.test -- assertions for mechanics that print TAP.
--
-- The same module is dm.test for users (at the prompt and in *_test.lua files
-- that `dmech test` runs, each in a fresh process) and `require "dmech.test"`
-- for dmech's own test scripts (TAP read by automake's tap-driver).
--
--   local T = dm.test                     -- or require "dmech.test"
--   T.ok(cond, "name") ; T.is(got, want) ; T.like(text, "pattern")
--   T.near(got, want, tol)                -- numbers, vecs, mats, tables of either
--   T.conserved(traj, "energy" | f, tol)  -- over every sample
--   T.agree(traj1, traj2, {"r", "z"}, tol)
--   T.order(function(h) return err end, {0.2, 0.1, 0.05}, 4, 0.1)
--   T.symplectic(integ, state, tol)
--   T.error_like(f, "pattern") ; T.group(name, f) ; T.todo(reason, f)
--   T.skip(reason[, n]) ; T.skip_all(reason) ; T.plan(n) ; T.diag(text)
--   T.done()                              -- plan line, exit 0 iff all passed
--
-- Tolerances: a number tol accepts |got - want| <= tol * max(1, |want|); a
-- table {abs = a, rel = r} accepts |got - want| <= max(a, r |want|), entry by
-- entry for vectors and matrices.  A failure prints the file:line of the
-- assertion, the values (shortest round-trip form) and what was allowed.
-- There are deliberately no timing assertions: speed belongs to benchmarks.
local T = {}

local here = debug.getinfo(1, "S").source

-- {==== the reporter ========================================================

-- One reporter per process; _capture swaps in a private one.
local function new_state(write, exit)
  return {n = 0, failed = 0, planned = nil, todo = nil, prefix = "",
          write = write, exit = exit}
end

-- exit closes the Lua state, so leak checkers see a failing __gc
local state = new_state(function(s) io.stdout:write(s); io.stdout:flush() end,
                        function(code) os.exit(code, true) end)

local function emit(s) state.write(s) end

-- The file:line of the innermost caller outside this module, then of up to
-- three of its callers (a helper function's call sites), up to the chunk.
local function where()
  local at = {}
  for level = 3, 200 do
    local info = debug.getinfo(level, "Sl")
    if info == nil or #at == 4 then break end
    if info.source ~= here and info.what ~= "C" and info.source:sub(1, 1) ~= "=" then
      local src = info.source:sub(1, 1) == "@" and info.source:sub(2) or info.short_src
      at[#at + 1] = src .. ":" .. (info.currentline or "?")
      if info.what == "main" then break end
    end
  end
  if #at == 0 then return nil end
  return at[1] .. (#at > 1 and (" (called from " .. table.concat(at, ", ", 2) .. ")") or "")
end

local function diag_lines(text, indent)
  for line in (tostring(text) .. "\n"):gmatch("(.-)\n") do emit("#" .. indent .. line .. "\n") end
end

-- One test line; on failure the location and detail() (a string, built only
-- when needed) as diagnostics.
local function report(pass, name, detail)
  local s = state
  s.n = s.n + 1
  if not pass and not s.todo then s.failed = s.failed + 1 end
  local label = (s.prefix .. (name or "")):gsub("\n", " ")
  local line = (pass and "ok " or "not ok ") .. s.n .. (label ~= "" and (" - " .. label) or "")
  if s.todo then line = line .. " # TODO " .. s.todo end
  emit(line .. "\n")
  if not pass then
    local at = where()
    if at then emit("#   at " .. at .. "\n") end
    if detail then
      local text = type(detail) == "function" and detail() or detail
      if text and text ~= "" then diag_lines(text, "   ") end
    end
  end
  return pass
end

local function argerror(n, fname, msg)
  error(("bad argument #%d to '%s' (%s)"):format(n, fname, msg), 3)
end

local function checkname(name, n, fname)
  if name ~= nil and type(name) ~= "string" then
    argerror(n, fname, "name expected to be a string, got " .. type(name))
  end
end

-- }====

-- {==== numbers and shapes ==================================================

-- Shortest decimal that reads back as the same double.
local function num(x)
  if math.type(x) == "integer" then return tostring(x) end
  if x ~= x then return "nan" end
  if x == math.huge then return "inf" elseif x == -math.huge then return "-inf" end
  for p = 15, 16 do
    local s = ("%." .. p .. "g"):format(x)
    if tonumber(s) == x then return s end
  end
  return ("%.17g"):format(x)
end

local function short(x) return ("%.3g"):format(x) end

local function classof(x)
  local mt = getmetatable(x)
  return type(mt) == "table" and rawget(mt, "__name") or nil
end

local function describe(x)
  return classof(x) or type(x)
end

-- dmech's classes by their registered metatables (the same __name could
-- belong to anybody's class).
local function isa(x, cls)
  local mt = getmetatable(x)
  return mt ~= nil and mt == debug.getregistry()["dmech." .. cls]
end

-- The numbers of x as a flat list and its shape ({} a number, {n} a vector,
-- {r, c} a matrix); nil and a reason when x is none of these.
local function numbers(x)
  if type(x) == "number" then return {x}, {} end
  if isa(x, "vec") then
    local t = x:totable()
    return t, {#t}
  elseif isa(x, "mat") then
    x = x:totable()
  elseif type(x) ~= "table" then
    return nil, "a " .. describe(x)
  end
  if type(x[1]) == "table" or isa(x[1], "vec") then
    local flat, cols = {}, nil
    for i = 1, #x do
      local row, shape = numbers(x[i])
      if row == nil or #shape ~= 1 then return nil, "a table whose row " .. i .. " is not a list of numbers" end
      if cols and #row ~= cols then
        return nil, ("a table whose row %d has %d entries, row 1 %d"):format(i, #row, cols)
      end
      cols = #row
      table.move(row, 1, #row, #flat + 1, flat)
    end
    return flat, {#x, cols}
  end
  for i = 1, #x do
    if type(x[i]) ~= "number" then return nil, ("a table whose entry %d is a %s"):format(i, describe(x[i])) end
  end
  return {table.unpack(x)}, {#x}
end

local function shape_text(shape)
  if #shape == 0 then return "a number" end
  if #shape == 1 then return "a vector of length " .. shape[1] end
  return ("a %d x %d matrix"):format(shape[1], shape[2])
end

local function index_text(shape, k)
  if #shape == 0 then return "" end
  if #shape == 1 then return "[" .. k .. "]" end
  return ("[%d, %d]"):format((k - 1) // shape[2] + 1, (k - 1) % shape[2] + 1)
end

-- A tolerance: a number tol (tol * max(1, |ref|)) or {abs=, rel=}
-- (max(abs, rel |ref|)).  ref names the reference value in messages.
local function tolerance(tol, n, fname, ref)
  local abs, rel, text
  if type(tol) == "number" then
    if not (tol >= 0) then argerror(n, fname, "tolerance must be >= 0, got " .. num(tol)) end
    abs, rel = tol, tol
    text = ("tol %s x max(1, |%s|)"):format(short(tol), ref)
  elseif type(tol) == "table" and classof(tol) == nil then
    abs, rel = tol.abs or 0, tol.rel or 0
    if tol.abs == nil and tol.rel == nil then argerror(n, fname, "tolerance table needs abs= or rel=") end
    for _, k in ipairs{"abs", "rel"} do
      local v = tol[k]
      if v ~= nil and (type(v) ~= "number" or not (v >= 0)) then
        argerror(n, fname, ("tolerance %s must be a number >= 0, got %s"):format(k,
          type(v) == "number" and num(v) or type(v)))
      end
    end
    text = ("max(abs %s, rel %s x |%s|)"):format(short(abs), short(rel), ref)
  else
    argerror(n, fname, "tolerance expected: a number >= 0 or {abs=, rel=}, got " .. describe(tol))
  end
  return {allowed = function(r) return math.max(abs, rel * math.abs(r)) end, text = text}
end

-- How far out of tolerance: <= 1 passes; NaN anywhere is worst.
local function excess(diff, allowed)
  if diff ~= diff then return math.huge end
  if diff <= allowed then return diff == 0 and 0 or diff / math.max(allowed, 1e-300) end
  return allowed > 0 and diff / allowed or math.huge
end

-- }====

-- {==== basic assertions ====================================================

function T.ok(cond, name)
  checkname(name, 2, "ok")
  return report(not not cond, name or "ok")
end

local function quote(s) return (("%q"):format(s):gsub("\\\n", "\\n")) end

local function show(x)
  return type(x) == "number" and num(x) or type(x) == "string" and quote(x) or tostring(x)
end

function T.is(got, want, name)
  checkname(name, 3, "is")
  return report(got == want, name or "is", function()
    return ("got:  %s\nwant: %s"):format(show(got), show(want))
  end)
end

function T.like(got, pattern, name)
  if type(pattern) ~= "string" then argerror(2, "like", "pattern expected, got " .. describe(pattern)) end
  checkname(name, 3, "like")
  local text = got ~= nil and tostring(got) or nil
  return report(text ~= nil and text:find(pattern) ~= nil, name or "like", function()
    return ("got:     %s\npattern: %s"):format(text and quote(text) or "nil", pattern)
  end)
end

function T.near(got, want, tol, name)
  local tl = tolerance(tol, 3, "near", "want")
  checkname(name, 4, "near")
  name = name or "near"
  local g, gshape = numbers(got)
  local w, wshape = numbers(want)
  if g == nil or w == nil then
    return report(false, name, ("got %s, want %s (numbers, vecs, mats or tables of numbers)")
      :format(g and shape_text(gshape) or gshape, w and shape_text(wshape) or wshape))
  end
  if #gshape ~= #wshape or gshape[1] ~= wshape[1] or gshape[2] ~= wshape[2] then
    return report(false, name, ("got %s, want %s"):format(shape_text(gshape), shape_text(wshape)))
  end
  local bad, worst, wk = 0, -1, 1
  for k = 1, #w do
    local e = excess(math.abs(g[k] - w[k]), tl.allowed(w[k]))
    if e > 1 then bad = bad + 1 end
    if e > worst then worst, wk = e, k end
  end
  return report(bad == 0, name, function()
    local head = #wshape == 0 and "" or
      ("%d of %d entries outside the tolerance; the worst, %s:\n"):format(bad, #w, index_text(wshape, wk))
    return head .. ("got:     %s\nwant:    %s\n|diff|:  %s\nallowed: %s = %s"):format(
      num(g[wk]), num(w[wk]), short(math.abs(g[wk] - w[wk])), short(tl.allowed(w[wk])), tl.text)
  end)
end

function T.error_like(f, pattern, name)
  if type(pattern) ~= "string" then argerror(2, "error_like", "pattern expected, got " .. describe(pattern)) end
  checkname(name, 3, "error_like")
  name = name or "error_like"
  local ok, err = pcall(f)
  if ok then return report(false, name, "no error raised") end
  err = tostring(err)
  return report(err:find(pattern) ~= nil, name,
    function() return ("error: %s\nwanted pattern: %s"):format(err, pattern) end)
end

-- }====

-- {==== mechanics ===========================================================

local function is_traj(x) return isa(x, "trajectory") end

local function has(list, x)
  for _, v in ipairs(list) do if v == x then return true end end
  return false
end

local function at_t(t, k) return t and ("sample %d (t = %.10g)"):format(k, t[k]) or ("sample " .. k) end

-- The values of a quantity along a trajectory: a column name or f(sample).
local function series(tr, what, fname)
  if type(what) == "string" then
    local names = tr:names()
    if not has(names, what) then
      return nil, ("the trajectory has no column '%s' (columns: %s)"):format(what, table.concat(names, ", "))
    end
    return tr:column(what):totable(), what
  end
  local v = {}
  for k = 1, #tr do
    local x = what(tr[k])
    if type(x) ~= "number" then
      error(("%s: the function returned %s for sample %d (number expected)"):format(fname, describe(x), k), 3)
    end
    v[k] = x
  end
  return v, "the quantity"
end

function T.conserved(tr, what, tol, name)
  local values, label, t
  if is_traj(tr) then
    if type(what) ~= "string" and type(what) ~= "function" then
      argerror(2, "conserved", "column name or function expected, got " .. describe(what))
    end
    checkname(name, 4, "conserved")
    local tl = tolerance(tol, 3, "conserved", "initial")
    values, label = series(tr, what, "conserved")
    if values == nil then return report(false, name or (type(what) == "string" and (what .. " conserved")
                                                       or "conserved"), label) end
    t = tr:column("t"):totable()
    tol = tl
  else
    local v, shape = numbers(tr)
    if v == nil or #shape ~= 1 then
      argerror(1, "conserved", "trajectory or list of values expected, got " .. describe(tr))
    end
    -- conserved(values, tol[, name])
    tol, name = tolerance(what, 2, "conserved", "initial"), tol
    checkname(name, 3, "conserved")
    values, label = v, "the value"
  end
  name = name or (type(what) == "string" and (what .. " conserved") or "conserved")
  if #values == 0 then return report(false, name, "no samples") end
  local v0, allowed = values[1], tol.allowed(values[1])
  local first, worst, wk = nil, -1, 1
  for k = 1, #values do
    local e = excess(math.abs(values[k] - v0), allowed)
    if e > 1 and not first then first = k end
    if e > worst then worst, wk = e, k end
  end
  return report(first == nil, name, function()
    return ("%s moves by %s from its initial value, allowed %s = %s\n"
      .. "first beyond at %s: %s\nworst at %s: %s\ninitial: %s"):format(
      label, short(math.abs(values[wk] - v0)), short(allowed), tol.text,
      at_t(t, first), num(values[first]), at_t(t, wk), num(values[wk]), num(v0))
  end), math.abs(values[wk] - v0)
end

function T.agree(a, b, columns, tol, name)
  if not is_traj(a) then argerror(1, "agree", "trajectory expected, got " .. describe(a)) end
  if not is_traj(b) then argerror(2, "agree", "trajectory expected, got " .. describe(b)) end
  if type(columns) == "number" or (type(columns) == "table" and columns[1] == nil
                                     and (columns.abs or columns.rel)) then
    columns, tol, name = nil, columns, tol      -- agree(a, b, tol[, name])
  end
  local tn = columns == nil and 3 or 4
  local tl = tolerance(tol, tn, "agree", "first")
  checkname(name, tn + 1, "agree")
  if type(columns) == "string" then columns = {columns} end
  if columns == nil then
    columns = a:names("q")
    for _, c in ipairs(a:names("p")) do columns[#columns + 1] = c end
  elseif type(columns) ~= "table" or #columns == 0 then
    argerror(3, "agree", "column names expected, got " .. describe(columns))
  end
  name = name or ("agree in " .. table.concat(columns, ", "))
  if #a ~= #b then
    return report(false, name, ("the trajectories have %d and %d samples"):format(#a, #b))
  end
  local na, nb = a:names(), b:names()
  for _, c in ipairs(columns) do
    if type(c) ~= "string" then argerror(3, "agree", "column names expected, got a " .. describe(c)) end
    if not has(na, c) then return report(false, name, "the first trajectory has no column '" .. c .. "'") end
    if not has(nb, c) then return report(false, name, "the second trajectory has no column '" .. c .. "'") end
  end
  local ta, tb = a:column("t"):totable(), b:column("t"):totable()
  local va, vb = {}, {}
  for j, c in ipairs(columns) do va[j], vb[j] = a:column(c):totable(), b:column(c):totable() end
  local fk, fj, beyond, worst, wk, wj = nil, nil, 0, -1, 1, 1
  for k = 1, #ta do
    for j = 1, #columns do
      local x, y = va[j][k], vb[j][k]
      local e = excess(math.abs(x - y), tl.allowed(x))
      if e > 1 then
        beyond = beyond + 1
        if not fk then fk, fj = k, j end
      end
      if e > worst then worst, wk, wj = e, k, j end
    end
  end
  local function when(k)
    return ta[k] == tb[k] and at_t(ta, k) or ("%s (second: t = %.10g)"):format(at_t(ta, k), tb[k])
  end
  return report(fk == nil, name, function()
    local x, y = va[fj][fk], vb[fj][fk]
    return ("the runs part at %s in column '%s':\nfirst:   %s\nsecond:  %s\n|diff|:  %s\n"
      .. "allowed: %s = %s\nlargest difference %s at %s in column '%s' (%d of %d values beyond)"):format(
      when(fk), columns[fj], num(x), num(y), short(math.abs(x - y)), short(tl.allowed(x)), tl.text,
      short(math.abs(va[wj][wk] - vb[wj][wk])), when(wk), columns[wj], beyond, #ta * #columns)
  end)
end

-- Least-squares slope of log(err) against log(h).
local function slope(hs, errs)
  local n, sx, sy = #hs, 0, 0
  for i = 1, n do sx, sy = sx + math.log(hs[i]), sy + math.log(errs[i]) end
  local mx, my, sxx, sxy = sx / n, sy / n, 0, 0
  for i = 1, n do
    local dx = math.log(hs[i]) - mx
    sxx, sxy = sxx + dx * dx, sxy + dx * (math.log(errs[i]) - my)
  end
  return sxy / sxx
end

function T.order(f, hs, p, tol, name)
  if type(f) ~= "function" and not (getmetatable(f) or {}).__call then
    argerror(1, "order", "function of h expected, got " .. describe(f))
  end
  if type(hs) ~= "table" or #hs < 2 then argerror(2, "order", "list of at least two step sizes expected") end
  for i, h in ipairs(hs) do
    if type(h) ~= "number" or not (h > 0) then argerror(2, "order", "step size " .. i .. " is not a positive number") end
    for j = 1, i - 1 do
      if hs[j] == h then argerror(2, "order", "step sizes " .. j .. " and " .. i .. " are equal") end
    end
  end
  if type(p) ~= "number" then argerror(3, "order", "expected order expected, got " .. describe(p)) end
  if type(tol) ~= "number" or not (tol > 0) then argerror(4, "order", "tolerance on the order expected (a number > 0)") end
  checkname(name, 5, "order")
  name = name or ("order " .. num(p))
  local errs, problem = {}, nil
  for i, h in ipairs(hs) do
    local e = f(h)
    local v = numbers(e)
    if v == nil then error(("order: f(%s) returned %s (an error: number or vector expected)"):format(num(h), describe(e)), 2) end
    local m = 0
    for _, x in ipairs(v) do m = (x ~= x or m ~= m) and 0 / 0 or math.max(m, math.abs(x)) end
    errs[i] = m
    if not problem and not (m > 0 and m < math.huge) then
      problem = ("the error at h = %s is %s: no logarithm (exact, below round-off, or diverged)"):format(num(h), num(m))
    end
  end
  local fitted = not problem and slope(hs, errs) or 0 / 0
  local pass = not problem and math.abs(fitted - p) <= tol
  report(pass, name, problem)
  local rows = {"h              error          order"}
  for i, h in ipairs(hs) do
    local local_p = i > 1 and errs[i] > 0 and errs[i - 1] > 0
      and ("%.3f"):format(math.log(errs[i - 1] / errs[i]) / math.log(hs[i - 1] / h)) or ""
    rows[#rows + 1] = ("%-14s %-14s %s"):format(short(h), ("%.4g"):format(errs[i]), local_p):gsub("%s+$", "")
  end
  rows[#rows + 1] = ("fitted slope %s, want %s +- %s%s"):format(
    fitted == fitted and ("%.4f"):format(fitted) or "nan", num(p), num(tol),
    pass and "" or " (outside)")
  diag_lines(table.concat(rows, "\n"), "   ")
  return pass, fitted, errs
end

function T.symplectic(integ, st, tol, name)
  local ok, m = pcall(function() return integ.symplecticity_defect end)
  if not ok or (type(m) ~= "function") then
    argerror(1, "symplectic", "integrator expected (with :symplecticity_defect), got " .. describe(integ))
  end
  if type(tol) ~= "number" or not (tol >= 0) then argerror(3, "symplectic", "tolerance expected (a number >= 0)") end
  checkname(name, 4, "symplectic")
  local d = integ:symplecticity_defect(st)
  -- on a Lie group the form is the canonical one of T*G at mu (doc/lie.md)
  local on_group = pcall(function() return integ.system:space() end)
  local form = on_group and "max|DPhi^T Omega(mu1) DPhi - Omega(mu0)|" or "max|DPhi^T J DPhi - J|"
  return report(d <= tol, name or "symplectic", function()
    return ("symplecticity defect %s = %s, allowed %s"):format(form, short(d), short(tol))
  end), d
end

-- }====

-- {==== structure: groups, todo, skip, plan, done ===========================

-- A failure for an error raised inside a group or todo block, with its
-- traceback cut where this module's frames begin.
local function errhandler(e)
  local msg = type(e) == "string" and e or ("(error object is a %s value)"):format(describe(e))
  local tb, out = debug.traceback(msg, 2), {}
  for line in (tb .. "\n"):gmatch("(.-)\n") do
    if line:find("in function 'xpcall'", 1, true) then break end
    if line ~= "\t[C]: in function 'error'" then out[#out + 1] = line end
  end
  return table.concat(out, "\n")
end

local function block(f)
  local ok, err = xpcall(f, errhandler)
  if not ok then report(false, "raised an error", err) end
  return ok
end

function T.group(name, f)
  if type(name) ~= "string" then argerror(1, "group", "name expected, got " .. describe(name)) end
  if type(f) ~= "function" then argerror(2, "group", "function expected, got " .. describe(f)) end
  local saved = state.prefix
  state.prefix = saved .. name .. ": "
  local failed = state.failed
  local ok = block(f)
  state.prefix = saved
  return ok and state.failed == failed
end

function T.todo(reason, f)
  if type(reason) ~= "string" then argerror(1, "todo", "reason expected, got " .. describe(reason)) end
  if type(f) ~= "function" then argerror(2, "todo", "function expected, got " .. describe(f)) end
  local saved = state.todo
  state.todo = reason
  block(f)
  state.todo = saved
end

function T.skip(reason, count)
  if reason ~= nil and type(reason) ~= "string" then argerror(1, "skip", "reason expected, got " .. describe(reason)) end
  if count ~= nil and math.type(count) ~= "integer" then argerror(2, "skip", "count expected (an integer)") end
  for _ = 1, count or 1 do
    state.n = state.n + 1
    emit("ok " .. state.n .. " # SKIP " .. (reason or "") .. "\n")
  end
end

function T.skip_all(reason)
  if state.n > 0 then error("skip_all must come before the first test", 2) end
  emit("1..0 # SKIP " .. (reason or "") .. "\n")
  state.exit(0)
end

function T.plan(k)
  if math.type(k) ~= "integer" or k < 1 then argerror(1, "plan", "number of tests expected (an integer >= 1)") end
  if state.n > 0 or state.planned then error("plan must come before the first test, once", 2) end
  state.planned = k
  emit("1.." .. k .. "\n")
end

function T.diag(msg)
  diag_lines(msg, " ")
end

function T.done()
  local s = state
  if s.planned == nil then emit("1.." .. s.n .. "\n") end
  if s.planned and s.planned ~= s.n then
    emit("# planned " .. s.planned .. " tests but ran " .. s.n .. "\n")
    s.failed = s.failed + 1
  end
  if s.failed > 0 then emit(("# %d of %d tests failed\n"):format(s.failed, s.n)) end
  s.exit(s.failed == 0 and 0 or 1)
end

-- A temporary directory under the build tree for this script's files.
function T.tmpdir(name)
  local base = os.getenv("DMECH_TESTTMP") or "."
  local dir = base .. "/" .. (name or "t")
  os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "'")
  return dir
end

-- For dmech's own tests of this module: run f with a private reporter and
-- return its TAP text and {n=, failed=, exit=}; done/skip_all end f there.
function T._capture(f)
  local buf, saved, exited = {}, state, {}
  state = new_state(function(s) buf[#buf + 1] = s end, function(code) error(exited(code)) end)
  setmetatable(exited, {__call = function(self, code) self.code = code; return self end})
  local ok, err = pcall(f)
  local counts = {n = state.n, failed = state.failed, exit = exited.code}
  state = saved
  if not ok and err ~= exited then error(err, 0) end
  return table.concat(buf), counts
end

-- The child of `dmech test`: run one file, then done(); an error outside
-- any group goes to stderr and exits with status 2 (no plan line).  The TAP
-- goes to descriptor fd when given (what the file prints stays apart).
function T._run_file(path, fd)
  local tap = fd and io.open("/dev/fd/" .. fd, "w")
  if tap then state.write = function(s) tap:write(s); tap:flush() end end
  local chunk, err = loadfile(path)
  if chunk == nil then
    io.stderr:write(err, "\n")
    os.exit(2)
  end
  arg = {[0] = path}
  local ok, msg = xpcall(chunk, errhandler)
  if not ok then
    io.stdout:flush()
    io.stderr:write(msg, "\n")
    io.stderr:flush()
    os.exit(2)
  end
  T.done()
end

-- }====

-- {==== help texts ==========================================================

local ok, core = pcall(require, "dmech.core")
if ok and type(core) == "table" and core.doc then
  local function doc(name, sig, text)
    core.doc("dm.test." .. name, sig, text, T[name])
  end
  core.doc("dm.test", "T = dm.test  (or require \"dmech.test\")",
    "Assertions for mechanics printing TAP; put them in *_test.lua files and run `dmech test` "
    .. "(a number tol accepts |got - want| <= tol max(1, |want|), {abs=, rel=} accepts "
    .. "max(abs, rel |want|); no timing assertions: speed belongs to benchmarks).", T)
  doc("ok", "T.ok(cond[, name]) -> pass", "Pass when cond is neither false nor nil.")
  doc("is", "T.is(got, want[, name]) -> pass", "Pass when got == want; a failure shows both (numbers in round-trip form).")
  doc("like", "T.like(got, pattern[, name]) -> pass",
    "Pass when tostring(got) matches the Lua pattern (printed formulas, messages).")
  doc("near", "T.near(got, want, tol | {abs=, rel=}[, name]) -> pass",
    "Compare numbers, vecs, mats or (nested) tables entry by entry; a failure shows the shapes or the worst entry, its values, |diff| and what was allowed.")
  doc("error_like", "T.error_like(f, pattern[, name]) -> pass",
    "Pass when f() raises an error whose message matches the Lua pattern.")
  doc("conserved", "T.conserved(traj, column | f(sample), tol | {abs=, rel=}[, name]) -> pass, drift",
    "Pass when the column (\"energy\", \"p_theta\", ...) or f(sample) stays within the tolerance of its initial value at every sample; a failure names the first and the worst sample with t (also T.conserved(values, tol)).")
  doc("agree", "T.agree(traj1, traj2[, columns], tol | {abs=, rel=}[, name]) -> pass",
    "Pass when two runs agree sample by sample in the columns (default: the q and p columns); a failure names the first sample and column where they part and the largest difference.")
  doc("order", "T.order(f, {h1, h2, ...}, p, tol[, name]) -> pass, slope, errors",
    "Fit the slope of log(error) against log(h) for the errors f(h) (numbers, or vectors by their max norm) and pass when |slope - p| <= tol; prints the table of h, error and observed order.")
  doc("symplectic", "T.symplectic(integ, state, tol[, name]) -> pass, defect",
    "Pass when integ:symplecticity_defect(state), the largest entry of |DPhi^T J DPhi - J| for one step (for a system on a Lie group |DPhi^T Omega(mu1) DPhi - Omega(mu0)|, Omega the canonical form of T*G), is at most tol.")
  doc("group", "T.group(name, f) -> pass",
    "Run f with \"name: \" before its test names; an error inside f is one failed test and the file goes on.")
  doc("todo", "T.todo(reason, f)",
    "Run f with its tests marked TODO: their failures (and errors) are reported but do not fail the run.")
  doc("skip", "T.skip([reason[, n]])", "Record n (default 1) skipped tests.")
  doc("skip_all", "T.skip_all(reason)", "Skip the whole file (before its first test) and exit successfully.")
  doc("plan", "T.plan(n)", "Declare the number of tests up front (optional: done() prints the count otherwise).")
  doc("diag", "T.diag(text)", "Print text as TAP diagnostic lines (# ...).")
  doc("done", "T.done()",
    "Print the plan and exit the script: status 0 when every test passed, else 1 (`dmech test` calls it after each file).")
  doc("tmpdir", "T.tmpdir([name]) -> path",
    "A directory for the test's files under $DMECH_TESTTMP (else the current directory), created if needed.")
end

-- }====

return T
