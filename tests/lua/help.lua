-- help.lua -- help's key scheme, fields, options and wrapping, and the hints
-- the prompt adds to error messages (did-you-mean and friends).
local T = require "dmech.test"
local dm = require "dmech"
local H = require "dmech.help"

local function capture(f, ...)
  local buf = {}
  local real = io.stdout
  io.stdout = {write = function(self, ...)
    for i = 1, select("#", ...) do buf[#buf + 1] = tostring((select(i, ...))) end
    return self
  end, flush = function() end}
  local ok, err = pcall(f, ...)
  io.stdout = real
  assert(ok, err)
  return table.concat(buf)
end

-- the terminal width is asked every time; pretend a narrow one
local real_width = dm._termwidth
local function at_width(w, f, ...)
  dm._termwidth = function() return w end
  local s = capture(f, ...)
  dm._termwidth = real_width
  return s
end

local function longest(s)
  local m = 0
  for line in s:gmatch("[^\n]+") do m = math.max(m, utf8.len(line)) end
  return m
end

-- {== wrapping
for _, w in ipairs{40, 63, 100} do
  local s = at_width(w, dm.help, "dm.integrator")
  T.ok(longest(s) <= w, string.format("help \"dm.integrator\" fits in %d columns (longest %d)", w, longest(s)))
  s = at_width(w, dm.help, "integrator")
  T.ok(longest(s) <= w, string.format("help \"integrator\" (a class) fits in %d columns (longest %d)", w, longest(s)))
end
T.is(H.wrap("aaa bbb ccc ddd", 8, "", 2), "aaa bbb\n  ccc\n  ddd", "wrap: hanging indent")
T.is(H.wrap("averyveryverylongword x", 8, "", 0), "averyveryverylongword\nx", "wrap: a long word stands alone")
T.is(H.wrap("θ = p / q", 5, "", 0), "θ = p\n/ q", "wrap counts characters, not bytes")

-- {== options, fields, the key scheme
local s = at_width(200, dm.help, "dm.integrator")
T.ok(s:find("Options: method, tableau, stages, h,", 1, true), "help lists the options of dm.integrator")
s = at_width(200, dm.help, "integrator:run")
T.ok(s:find("Options: steps, t, every,", 1, true), "help \"integrator:run\" lists the run options")
T.ok(at_width(200, dm.help, "integrator.run"):find("integ:run", 1, true), "'.' for ':' finds the method")
T.ok(at_width(200, dm.help, "I:run"):find("integ:run", 1, true), "any prefix finds the method by its name")
T.ok(at_width(200, dm.help, "traj:column"):find("A copy of the column", 1, true), "the prefix the signature uses")
T.ok(at_width(200, dm.help, "routh.routhian"):find("The Routhian", 1, true), "help \"routh.routhian\"")
T.ok(at_width(200, dm.help, "system.coords"):find("sys.coords -> {name, ...}", 1, true), "help \"system.coords\"")
T.ok(at_width(200, dm.help, "sys.coords"):find("The coordinate names", 1, true), "help \"sys.coords\"")
local sys = dm.systems.kepler()
s = at_width(200, dm.help, sys)
T.ok(s:find("system methods:", 1, true) and s:find("system fields:", 1, true)
     and s:find("sys.coords", 1, true) and s:find("sys:energy", 1, true), "help(obj) lists methods and fields")
local I = dm.integrator(sys, {h = 0.1})
s = at_width(200, dm.help, I)
T.ok(s:find("integ.system", 1, true) and s:find("integ:run", 1, true), "help(integrator) lists fields and methods")
local tr = I:run({q = {1, 0}, p = {0, 1}}, {steps = 2})
T.ok(at_width(200, dm.help, tr):find("traj.t", 1, true), "help(trajectory) lists its fields")
s = at_width(200, dm.help, "mat")
T.ok(s:find("dm.mat(rows", 1, true) and s:find("m:solve(b)", 1, true), "help \"mat\": the function and the class")
T.ok(at_width(200, dm.help, "dm.integrater"):find("did you mean \"dm.integrator\"?", 1, true),
     "help of a misspelt name suggests the right one")
T.ok(at_width(200, dm.help, "routhain"):find("did you mean", 1, true), "help of a misspelt member suggests")
T.ok(at_width(200, dm.help):find("dm.traceback()", 1, true), "the overview mentions dm.traceback()")
T.ok(not at_width(200, dm.help):find("_gp", 1, true), "the overview hides internal names")
T.ok(not at_width(200, dm.help, "dm"):find("_gp", 1, true), "help \"dm\" hides internal names")
T.ok(at_width(200, dm.help, "dm._gp"):find("dm._gp.send", 1, true), "help \"dm._gp\" shows them")
local docs = dm.docs()
T.ok(docs["dm.system"].opts and docs["dm.routh"].opts and docs["integrator:run"].opts,
     "options documented for dm.system, dm.routh, integrator:run")

-- every field an object's error message lists is documented (completion and
-- help(obj) read the documentation)
local function listed_fields(obj)
  local ok, err = pcall(function() return obj.zz_no_such_field end)
  return not ok and tostring(err):match("%(fields: ([^)]*)%)")
end
for what, obj in pairs{system = sys, integrator = I} do
  local list, missing = listed_fields(obj), {}
  T.ok(list, what .. ": the error for an unknown field lists the fields")
  for f in (list or ""):gmatch("[%w_]+") do
    if not docs[what .. "." .. f] then missing[#missing + 1] = f end
  end
  T.ok(#missing == 0, what .. ": every listed field is documented" ..
       (#missing > 0 and (" (missing: " .. table.concat(missing, ", ") .. ")") or ""))
end

-- {== hints
local function hint(msg, info) return H.hint(msg, info or {}) end
T.is(hint("x: dm.integrator: unknown option metod (options: method, tableau, stages, h)"),
     "\nhint: did you mean 'method'?", "unknown option from the listed options")
T.is(hint("dm.routh: unknown option cyclc"), "\nhint: did you mean 'cyclic'?", "unknown option from the documented options")
T.is(hint("unknown integration method 'lobbato' (known: midpoint, gauss, lobatto, gsl:<stepper>)"),
     "\nhint: did you mean \"lobatto\"?", "misspelt method name")
T.is(hint("bad argument #1 to 'column' (no column 'thta' (available: t, r, theta, p_r))"),
     "\nhint: did you mean \"theta\"?", "misspelt column")
T.is(hint("system has no field or method 'coord' (fields: name, n, coords)"),
     "\nhint: did you mean 'coords'?", "misspelt field")
T.is(hint("system has no field or method 'enrgy' (fields: name, n, coords)"),
     "\nhint: did you mean 'energy'?", "misspelt method through the field error")
T.is(hint("attempt to call a nil value (method 'nrom')"), "\nhint: did you mean :norm?", "misspelt method")
T.is(hint("bad argument #1 to 'sin' (number expected, got expr)"),
     "\nhint: math.sin takes numbers only; use dm.sin for a symbolic value (in L, force or constraints)",
     "math.sin on a symbolic value")
T.is(hint("bad argument #1 to 'run' (dmech.integrator expected, got table)",
          {namewhat = "field", source = "=stdin", line = 1, chunk = "tr = I2.run(s, {steps = 1})"}),
     "\nhint: call a method with ':', as in I2:run(...)", "I.run(...) suggests I:run")
T.is(hint("bad argument #1 to 'run' (dmech.integrator expected, got table)", {namewhat = "method"}), "",
     "no ':' hint when it was called with ':'")
T.is(hint("attempt to perform arithmetic on a nil value (global 'mass')",
          {traceback = "stack traceback:\n\t[C]: in function 'dmech.system'"}),
     "\nhint: 'mass' is not defined (a nil global); in L, a parameter is declared in params = {mass = ...} and read as p.mass",
     "an undefined global inside L is named with the params recipe")
T.is(hint("no element 'm' in p (elements: )"),
     "\nhint: parameters are declared in dm.system{params = {m = ...}} and read as p.m",
     "an undeclared parameter in L")
T.is(hint("no element 'thta' in q (elements: r, theta)"), "\nhint: did you mean 'theta'?",
     "a misspelt coordinate in L")
T.is(hint("no element 'thta' in v (elements: v_r, v_theta)"), "\nhint: did you mean 'theta'?",
     "a misspelt velocity in L")
T.is(hint("attempt to call a nil value (global 'prnt')"),
     "\nhint: 'prnt' is not defined (a nil global); did you mean 'print'?", "misspelt global")
T.is(hint("attempt to call a nil value (global 'linspace')"),
     "\nhint: 'linspace' is not a global; did you mean dm.linspace?", "a dm function without dm.")
T.is(hint("attempt to call a nil value (field 'integrater')"), "\nhint: did you mean 'integrator'?", "misspelt field of a module")
T.is(hint("attempt to index a nil value (field 'x')"), "", "no guess for one letter")
T.is(hint("something else entirely"), "", "no hint for other messages")
T.is(hint(nil), "", "no hint for a non-string message")
T.is(H.distance("nrom", "norm"), 1, "a transposition costs 1")
T.is(H.distance("Gauss", "gauss"), 0, "case does not count")

T.done()
