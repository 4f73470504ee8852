-- usertest_asserts.lua -- dm.test's assertions: what they accept, and the
-- exact text of each failure (file:line, values, tolerance), captured from a
-- private reporter (T._capture) on purpose-built failures.
local T = require "dmech.test"
local dm = require "dmech"

T.ok(dm.test == T, "dm.test is the module of require \"dmech.test\"")

local SRC = debug.getinfo(1, "S").source:sub(2)

-- Run f under a private reporter; compare its TAP with want, where @AT
-- stands for "#   at <this file>:<the line f is written on>" followed by
-- the callers: this function's line and its caller's.
local function check(f, want, name)
  local out, c = T._capture(f); local line = debug.getinfo(1, "l").currentline
  local fl, cl = debug.getinfo(f, "S").linedefined, debug.getinfo(2, "l").currentline
  local at = ("#   at %s:%d (called from %s:%d, %s:%d)"):format(SRC, fl, SRC, line, SRC, cl)
  local at2 = ("#   at %s:%d (called from %s:%d, %s:%d, %s:%d)"):format(SRC, fl, SRC, fl, SRC, line, SRC, cl)
  want = want:gsub("@AT2", function() return at2 end):gsub("@AT", function() return at end)
  T.is(out, want, name)
  return c
end

-- {==== ok, is, like, error_like ===========================================
check(function() T.ok(2.385 > 3, "cond") end, "not ok 1 - cond\n@AT\n", "ok: failure")
check(function() T.ok(2.385) end, "ok 1 - ok\n", "ok: a number is true; default name")
check(function() T.is(0.1 + 0.2, 0.3, "sum") end, [[
not ok 1 - sum
@AT
#   got:  0.30000000000000004
#   want: 0.3
]], "is: numbers in round-trip form")
check(function() T.is("a\nb", "a", "text") end, [[
not ok 1 - text
@AT
#   got:  "a\nb"
#   want: "a"
]], "is: strings quoted on one line")
check(function() T.like(nil, "x", "like nil") end, [[
not ok 1 - like nil
@AT
#   got:     nil
#   pattern: x
]], "like: nil")
check(function() T.like(dm.vec{2.385}, "^vec{3", "like vec") end, [[
not ok 1 - like vec
@AT
#   got:     "vec{2.385}"
#   pattern: ^vec{3
]], "like: tostring of an object")
check(function() T.like(dm.expr(2.385), "2%.385") end, "ok 1 - like\n", "like: an expression")
check(function() T.error_like(function() end, "x", "e") end, "not ok 1 - e\n@AT\n#   no error raised\n",
  "error_like: no error")
check(function() T.error_like(function() error("density -2.385", 0) end, "positive", "e") end, [[
not ok 1 - e
@AT
#   error: density -2.385
#   wanted pattern: positive
]], "error_like: another message")
-- }====

-- {==== near ================================================================
check(function() T.near(0.1 + 0.2, 0.3, 1e-17, "sum") end, [[
not ok 1 - sum
@AT
#   got:     0.30000000000000004
#   want:    0.3
#   |diff|:  5.55e-17
#   allowed: 1e-17 = tol 1e-17 x max(1, |want|)
]], "near: a number")
check(function() T.near(1000.5, 1000, 1e-3, "mixed") end, "ok 1 - mixed\n",
  "near: a number tol is relative for |want| > 1")
check(function() T.near(1000.5, 1000, {abs = 1e-3}, "abs") end, [[
not ok 1 - abs
@AT
#   got:     1000.5
#   want:    1000
#   |diff|:  0.5
#   allowed: 0.001 = max(abs 0.001, rel 0 x |want|)
]], "near: {abs=}")
check(function() T.near(2.5, 2, {rel = 0.25}, "edge") end, "ok 1 - edge\n", "near: |diff| = allowed passes")
check(function() T.near(dm.vec{1, 2.385, 3.1}, {1, 2.3850001, 3}, {abs = 1e-12, rel = 1e-9}, "vec") end, [[
not ok 1 - vec
@AT
#   2 of 3 entries outside the tolerance; the worst, [3]:
#   got:     3.1
#   want:    3
#   |diff|:  0.1
#   allowed: 3e-09 = max(abs 1e-12, rel 1e-09 x |want|)
]], "near: the worst entry of a vector")
check(function() T.near(dm.mat{{1, 2}, {3, 4}}, {{1, 2}, dm.vec{3, 4.5}}, 1e-3, "mat") end, [[
not ok 1 - mat
@AT
#   1 of 4 entries outside the tolerance; the worst, [2, 2]:
#   got:     4
#   want:    4.5
#   |diff|:  0.5
#   allowed: 0.0045 = tol 0.001 x max(1, |want|)
]], "near: a matrix against rows (a table and a vec)")
check(function() T.near({1, 0 / 0}, {1, 2}, 1, "nan") end, [[
not ok 1 - nan
@AT
#   1 of 2 entries outside the tolerance; the worst, [2]:
#   got:     nan
#   want:    2
#   |diff|:  nan
#   allowed: 2 = tol 1 x max(1, |want|)
]], "near: NaN never passes")
check(function() T.near({1, 2}, dm.vec{1, 2, 3}, 1, "shape") end, [[
not ok 1 - shape
@AT
#   got a vector of length 2, want a vector of length 3
]], "near: lengths differ")
check(function() T.near(dm.mat(2, 3), dm.mat(3, 2), 1, "shape") end, [[
not ok 1 - shape
@AT
#   got a 2 x 3 matrix, want a 3 x 2 matrix
]], "near: matrix shapes differ")
check(function() T.near(2.385, {2.385}, 1, "num-vec") end, [[
not ok 1 - num-vec
@AT
#   got a number, want a vector of length 1
]], "near: a number is not a vector")
check(function() T.near({1, "2"}, {1, 2}, 1, "kind") end, [[
not ok 1 - kind
@AT
#   got a table whose entry 2 is a string, want a vector of length 2 (numbers, vecs, mats or tables of numbers)
]], "near: a table that is not numbers")
check(function() T.near({{1, 2}, {3}}, {{1, 2}, {3, 4}}, 1, "rows") end, [[
not ok 1 - rows
@AT
#   got a table whose row 2 has 1 entries, row 1 2, want a 2 x 2 matrix (numbers, vecs, mats or tables of numbers)
]], "near: ragged rows")
T.error_like(function() T.near(1, 1, "x") end,
  "bad argument #3 to 'near' %(tolerance expected: a number >= 0 or {abs=, rel=}, got string%)", "near: tolerance type")
T.error_like(function() T.near(1, 1, -1e-9) end,
  "bad argument #3 to 'near' %(tolerance must be >= 0, got %-1e%-09%)", "near: negative tolerance")
T.error_like(function() T.near(1, 1, {}) end,
  "bad argument #3 to 'near' %(tolerance table needs abs= or rel=%)", "near: empty tolerance table")
T.error_like(function() T.near(1, 1, {rel = "big"}) end,
  "bad argument #3 to 'near' %(tolerance rel must be a number >= 0, got string%)", "near: bad rel")
T.error_like(function() T.near(1, 1, 0, 7) end,
  "bad argument #4 to 'near' %(name expected to be a string, got number%)", "near: name type")
-- }====

-- {==== trajectories ========================================================
local tr = dm.trajectory{t = {0, 0.5, 1, 1.5}, coords = {"r", "z"},
  q = {r = {1, 1.25, 1.5, 1.75}, z = {0, 0.5, 0, -0.5}}, p = {r = {2, 2, 2, 2}, z = {1, 0, -1, 0}},
  columns = {energy = {-0.5, -0.5 + 2e-12, -0.5 - 3e-10, -0.5 + 1e-10}}}
check(function() T.conserved(tr, "energy", 1e-10) end, [[
not ok 1 - energy conserved
@AT
#   energy moves by 3e-10 from its initial value, allowed 1e-10 = tol 1e-10 x max(1, |initial|)
#   first beyond at sample 3 (t = 1): -0.5000000003
#   worst at sample 3 (t = 1): -0.5000000003
#   initial: -0.5
]], "conserved: a column")
local c = check(function() T.conserved(tr, "p_r", 0, "p_r exactly") end, "ok 1 - p_r exactly\n",
  "conserved: a constant column with tolerance 0")
T.is(c.failed, 0, "conserved: passing counts nothing failed")
check(function() T.conserved(tr, function(s) return s.r * s.p_r end, {rel = 0.1}, "r p_r") end, [[
not ok 1 - r p_r
@AT
#   the quantity moves by 1.5 from its initial value, allowed 0.2 = max(abs 0, rel 0.1 x |initial|)
#   first beyond at sample 2 (t = 0.5): 2.5
#   worst at sample 4 (t = 1.5): 3.5
#   initial: 2
]], "conserved: a function of the sample")
check(function() T.conserved(tr:column("z"), {abs = 0.6}, "values") end, "ok 1 - values\n",
  "conserved: a vec of values")
check(function() T.conserved({2.385, 2.385, 2.4}, 1e-3, "list") end, [[
not ok 1 - list
@AT
#   the value moves by 0.015 from its initial value, allowed 0.00238 = tol 0.001 x max(1, |initial|)
#   first beyond at sample 3: 2.4
#   worst at sample 3: 2.4
#   initial: 2.385
]], "conserved: a list of values")
check(function() T.conserved(tr, "energi", 1) end, [[
not ok 1 - energi conserved
@AT
#   the trajectory has no column 'energi' (columns: t, r, z, p_r, p_z, energy)
]], "conserved: a missing column")
T.error_like(function() T.conserved(tr, function() return "x" end, 1) end,
  "conserved: the function returned string for sample 1 %(number expected%)", "conserved: bad function result")
T.error_like(function() T.conserved(tr, 2, 1) end,
  "bad argument #2 to 'conserved' %(column name or function expected, got number%)", "conserved: what")
T.error_like(function() T.conserved("x", 1) end,
  "bad argument #1 to 'conserved' %(trajectory or list of values expected, got string%)", "conserved: first argument")

local tr2 = dm.trajectory{t = {0, 0.5, 1, 1.5}, coords = {"r", "z"},
  q = {r = {1, 1.25, 1.5 + 1e-9, 1.75 + 1e-6}, z = {0, 0.5, 0, -0.5}}, p = {r = {2, 2, 2, 2}, z = {1, 0, -1, 1e-3}}}
check(function() T.agree(tr, tr2, 1e-12) end, [[
not ok 1 - agree in r, z, p_r, p_z
@AT
#   the runs part at sample 3 (t = 1) in column 'r':
#   first:   1.5
#   second:  1.500000001
#   |diff|:  1e-09
#   allowed: 1.5e-12 = tol 1e-12 x max(1, |first|)
#   largest difference 0.001 at sample 4 (t = 1.5) in column 'p_z' (3 of 16 values beyond)
]], "agree: the first sample and column where the runs part, and the worst")
check(function() T.agree(tr, tr2, {"z", "p_r"}, 0, "z, p_r") end, "ok 1 - z, p_r\n", "agree: chosen columns")
check(function() T.agree(tr, tr2, "r", {abs = 1e-5}, "r") end, "ok 1 - r\n", "agree: one column by name")
local tr3 = dm.trajectory{t = {0, 0.5, 1.25, 1.5}, coords = {"r"}, q = {r = {1, 1.25, 1.5, 2}}}
check(function() T.agree(tr, tr3, "r", 1e-3, "times") end, [[
not ok 1 - times
@AT
#   the runs part at sample 4 (t = 1.5) in column 'r':
#   first:   1.75
#   second:  2
#   |diff|:  0.25
#   allowed: 0.00175 = tol 0.001 x max(1, |first|)
#   largest difference 0.25 at sample 4 (t = 1.5) in column 'r' (1 of 4 values beyond)
]], "agree: equal times are not required")
check(function() T.agree(tr, tr3, {"p_r"}, 1, "missing") end, [[
not ok 1 - missing
@AT
#   the second trajectory has no column 'p_r'
]], "agree: a column missing in the second")
check(function() T.agree(tr, tr:slice(1, 3), 1, "lengths") end, [[
not ok 1 - lengths
@AT
#   the trajectories have 4 and 3 samples
]], "agree: different lengths")
T.error_like(function() T.agree(tr, {}, 1) end,
  "bad argument #2 to 'agree' %(trajectory expected, got table%)", "agree: second argument")
T.error_like(function() T.agree(tr, tr2, {}, 1) end,
  "bad argument #3 to 'agree' %(column names expected, got table%)", "agree: empty column list")
-- }====

-- {==== order and symplecticity =============================================
local pass, p, errs, out
check(function() pass, p, errs = T.order(function(h) return 2.385 * h^4 end, {0.2, 0.1, 0.05}, 4, 0.01) end, [[
ok 1 - order 4
#   h              error          order
#   0.2            0.003816
#   0.1            0.0002385      4.000
#   0.05           1.491e-05      4.000
#   fitted slope 4.0000, want 4 +- 0.01
]], "order: the table of a passing fit")
T.ok(pass and math.abs(p - 4) < 1e-12 and #errs == 3, "order: returns pass, slope, errors")
check(function() T.order(function(h) return {h^2, -3 * h^2} end, {0.1, 0.05}, 4, 0.5, "second") end, [[
not ok 1 - second
@AT
#   h              error          order
#   0.1            0.03
#   0.05           0.0075         2.000
#   fitted slope 2.0000, want 4 +- 0.5 (outside)
]], "order: a vector error by its max norm, slope outside")
check(function() T.order(function(h) return h > 0.1 and h^2 or 0 end, {0.2, 0.1}, 2, 0.1, "zero") end, [[
not ok 1 - zero
@AT
#   the error at h = 0.1 is 0: no logarithm (exact, below round-off, or diverged)
#   h              error          order
#   0.2            0.04
#   0.1            0
#   fitted slope nan, want 2 +- 0.1 (outside)
]], "order: an error of zero")
T.error_like(function() T.order(function() return "x" end, {0.1, 0.05}, 2, 0.1) end,
  "order: f%(0.1%) returned string %(an error: number or vector expected%)", "order: bad result")
T.error_like(function() T.order(print, {0.1, 0.1}, 2, 0.1) end,
  "bad argument #2 to 'order' %(step sizes 1 and 2 are equal%)", "order: equal steps")
T.error_like(function() T.order(print, {0.1}, 2, 0.1) end,
  "bad argument #2 to 'order' %(list of at least two step sizes expected%)", "order: one step")
T.error_like(function() T.order(print, {0.1, 0.05}, 2, 0) end,
  "bad argument #4 to 'order' %(tolerance on the order expected %(a number > 0%)%)", "order: tolerance")

local fake = {symplecticity_defect = function(self, s) return s.d end}
check(function() T.symplectic(fake, {d = 2.385e-9}, 1e-12, "fake") end, [[
not ok 1 - fake
@AT
#   symplecticity defect max|DPhi^T J DPhi - J| = 2.38e-09, allowed 1e-12
]], "symplectic: the defect and the tolerance")
local ok_, d = nil, nil
check(function() ok_, d = T.symplectic(fake, {d = 1e-16}, 1e-15) end, "ok 1 - symplectic\n", "symplectic: passes")
T.is(d, 1e-16, "symplectic returns the defect")
T.error_like(function() T.symplectic({}, {}, 1) end,
  "bad argument #1 to 'symplectic' %(integrator expected %(with :symplecticity_defect%), got table%)",
  "symplectic: not an integrator")
-- }====

-- with real runs: a symplectic and a non-symplectic method, a measured order
local kep, k0 = dm.systems.kepler(), {q = {0.4, 0}, p = {0, 2}}
local gauss = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.05})
T.ok(T.symplectic(gauss, k0, 1e-14, "gauss is symplectic"), "symplectic passes for gauss")
local rk4 = dm.integrator(kep, {method = "rk4", h = 0.05})
out, c = T._capture(function() T.symplectic(rk4, k0, 1e-8, "rk4") end)
T.like(out, "^not ok 1 %- rk4\n.*defect max|DPhi^T J DPhi %- J| = %d%.%d%de%-0[5-7], allowed 1e%-08\n$",
  "symplectic fails for rk4 with its defect")
do -- on a Lie group the defect is that of the canonical form of T*SO(3)
  local SO3 = dm.lie.SO3()
  local top = dm.system{space = SO3, params = {J1 = 1.3, J2 = 2.1, J3 = 3.4, mgl = 2.943},
    L = function(R, Om, p)
      return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) - p.mgl * R[3][3]
    end}
  local t0 = {g = SO3.exp{0.5, -0.2, 0.3}, mu = {0.3, 2.385, -0.4}}
  T.ok(T.symplectic(dm.integrator(top, {method = "lgvi", h = 0.2}), t0, 1e-8, "lgvi on SO3"),
       "symplectic passes for lgvi on SO(3)")
  out = T._capture(function()
    T.symplectic(dm.integrator(top, {method = "gsl:rk4", h = 0.2}), t0, 1e-8, "rk4 on SO3")
  end)
  T.like(out, "^not ok 1 %- rk4 on SO3\n.*defect max|DPhi^T Omega%(mu1%) DPhi %- Omega%(mu0%)| = "
         .. "%d%.%d+e%-06, allowed 1e%-08\n$", "symplectic on a group names its form")
end
local kref = dm.integrator(kep, {method = "gauss", stages = 3, h = 0.0125}):run(k0, {steps = 160})
local pass4, p4 = nil, nil
out = T._capture(function()
  pass4, p4 = T.order(function(h)
    local tr = dm.integrator(kep, {method = "trapezoid", h = h}):run(k0, {steps = math.floor(2 / h + 0.5)})
    return tr[#tr].q - kref[#kref].q
  end, {0.1, 0.05, 0.025}, 2, 0.1)
end)
T.ok(pass4 and math.abs(p4 - 2) < 0.1, "order: Stormer-Verlet is second order on Kepler")
T.like(out, "\n#   0%.025 +[%d.e-]+ +2%.%d%d%d\n", "order: the table's last row")

-- {==== groups, todo, skip, plan, done ======================================
check(function()
  T.group("outer", function()
    T.ok(true, "a")
    T.group("inner", function() T.ok(true, "b") end)
  end)
  T.ok(true, "c")
end, "ok 1 - outer: a\nok 2 - outer: inner: b\nok 3 - c\n", "group: names nest and end")
out, c = T._capture(function()
  T.group("g", function() T.ok(true, "before"); error("broken at 2.385") end)
  T.ok(true, "after")
end)
T.like(out, "^ok 1 %- g: before\nnot ok 2 %- g: raised an error\n#   at [^\n]+\n#   [^\n]*: broken at 2%.385\n#   stack traceback:\n",
  "group: an error is one failure with its message and traceback")
T.like(out, "\nok 3 %- after\n$", "group: the file goes on after an error")
T.is(c.failed, 1, "group: the error counts as one failure")
T.ok(not out:find("in function 'error'", 1, true), "group: the traceback starts at the raising line")

c = check(function() T.todo("known bug", function() T.ok(false, "x"); T.ok(true, "y") end) end,
  "not ok 1 - x # TODO known bug\n@AT2\nok 2 - y # TODO known bug\n", "todo: marks every test")
T.is(c.failed, 0, "todo: failures do not count")
c = check(function() T.skip("no gnuplot", 2); T.skip() end,
  "ok 1 # SKIP no gnuplot\nok 2 # SKIP no gnuplot\nok 3 # SKIP \n", "skip: n tests")
c = check(function() T.plan(2); T.ok(true, "one"); T.done() end,
  "1..2\nok 1 - one\n# planned 2 tests but ran 1\n# 1 of 1 tests failed\n", "done: a plan not met")
T.is(c.exit, 1, "done: exit status 1")
c = check(function() T.ok(true, "one"); T.done() end, "ok 1 - one\n1..1\n", "done: prints the plan")
T.is(c.exit, 0, "done: exit status 0")
c = check(function() T.skip_all("needs MPI") end, "1..0 # SKIP needs MPI\n", "skip_all")
T.is(c.exit, 0, "skip_all exits 0")
T.error_like(function() T._capture(function() T.ok(true); T.skip_all("late") end) end,
  "skip_all must come before the first test", "skip_all after a test")
T.error_like(function() T._capture(function() T.ok(true); T.plan(3) end) end,
  "plan must come before the first test, once", "plan after a test")
T.error_like(function() T.group(1, print) end, "bad argument #1 to 'group' %(name expected, got number%)", "group: name")
T.error_like(function() T.todo("r") end, "bad argument #2 to 'todo' %(function expected, got nil%)", "todo: function")
T.error_like(function() T.skip("r", 1.5) end, "bad argument #2 to 'skip' %(count expected %(an integer%)%)", "skip: count")
-- }====

-- {==== help ================================================================
local function capture_help(x)
  local buf, real = {}, io.stdout
  io.stdout = setmetatable({}, {__index = {write = function(self, ...)
    for i = 1, select("#", ...) do buf[#buf + 1] = tostring((select(i, ...))) end
    return self
  end, flush = function() end}})
  local ok, err = pcall(dm.help, x)
  io.stdout = real
  assert(ok, err)
  return table.concat(buf)
end
local h = capture_help("test")
T.like(h, "^T = dm.test", "help \"test\" describes the module")
for _, fname in ipairs{"near", "conserved", "agree", "order", "symplectic", "todo", "skip", "error_like"} do
  T.ok(h:find("T." .. fname .. "(", 1, true), "help \"test\" lists T." .. fname)
end
T.is(capture_help(dm.test), h, "help(dm.test) by value")
T.like(capture_help("conserved"), "^T%.conserved%(traj, column", "help with a bare assertion name")
-- }====

T.done()
