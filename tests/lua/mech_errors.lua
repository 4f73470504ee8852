-- mech_errors.lua -- every misuse of dm.integrator, its methods,
-- integ:order_estimate and dm.tableau gives a clear error naming what was
-- wrong: unknown methods and options, options of the wrong type or range or
-- for another method, stages out of range, bad tableaus, wrong state sizes,
-- NaN states, a singular Hessian at the initial state, bad run options; and
-- numerical failures during a run keep the partial trajectory.
local T = require "dmech.test"
local dm = require "dmech"

local kep = dm.systems.kepler()
local k0 = {q = {0.4, 0}, p = {0, 2}}
local function err(pattern, name, f)
  T.error_like(f, pattern, name)
end
local function integ(o) return function() return dm.integrator(kep, o) end end

-- methods and options
err("bad argument #1 to '.-' %(system expected, got table%)", "not a system", function() dm.integrator({}, {}) end)
err("dm.integrator: unknown integration method 'gaus' %(known: midpoint, gauss, trapezoid, lobatto, prk, composition, rk4, gsl:<stepper>, adapt:<method>, sem, multiscale%)$",
    "unknown method lists the known ones", integ{method = "gaus"})
-- an error from dm.integrator is located at the caller's line (no Lua wrapper
-- between the user and the C function)
local function located(what, pattern, f, line)
  local ok, msg = pcall(f)
  T.ok(not ok and msg:find("^[^:]*mech_errors%.lua:" .. line .. ": " .. pattern),
       what .. " names the user's file and line: " .. tostring(msg))
end
located("an unknown method", "dm%.integrator: unknown integration method 'gaus'",
        function() return dm.integrator(kep, {method = "gaus"}) end, debug.getinfo(1, "l").currentline)
located("a bad option", "dm%.integrator: option 'stages' must be an integer",
        function() return dm.integrator(kep, {stages = "two"}) end, debug.getinfo(1, "l").currentline)
located("a bad argument", "bad argument #1 to '[%w.]*integrator' %(system expected, got number%)",
        function() return dm.integrator(42) end, debug.getinfo(1, "l").currentline)
err("dm.integrator: unknown option stags %(options: method, tableau, stages, h, tol, maxiter", "misspelt option", integ{stags = 2})
err("dm.integrator: option 'stages' does not apply to method 'rk4' %(its options: h%)", "option for another method",
    integ{method = "rk4", stages = 2})
err("dm.integrator: option 'order' does not apply to method 'gauss'", "composition option to gauss", integ{order = 4})
err("dm.integrator: option 'tableau' does not apply to method 'lobatto'", "tableau without prk",
    integ{method = "lobatto", tableau = dm.tableau("lobatto", 3)})
err("dm.integrator: option 'h' must be a number, got string", "h as a string", integ{h = "0.1"})
err("dm.integrator: option 'stages' must be an integer, got 2.5", "fractional stages", integ{stages = 2.5})
err("dm.integrator: option 'simplified' must be a boolean, got number", "boolean option", integ{simplified = 1})
err("dm.integrator: option 'scheme' must be a string, got number", "string option",
    integ{method = "composition", scheme = 4})
err("dm.integrator: option 'method' must be a string, got number", "method as a number", integ{method = 4})
err("dm.integrator: option 'h' must be a finite non%-zero number", "h = 0", integ{h = 0})
err("dm.integrator: option 'stages' = 21 out of range %(integer 1..20%)", "stages too large", integ{stages = 21})
err("dm.integrator: lobatto: stages = 1 out of range 2..20", "Lobatto with one stage", integ{method = "lobatto", stages = 1})
err("dm.integrator: option 'tol' = 0 out of range", "tol = 0", integ{tol = 0})
err("dm.integrator: option 'maxiter' = 0 out of range", "maxiter = 0", integ{maxiter = 0})
err("dm.integrator: composition: order = 5 not available", "composition order 5", integ{method = "composition", order = 5})
err("dm.integrator: composition: unknown scheme 'foo'", "unknown composition scheme", integ{method = "composition", scheme = "foo"})
err("dm.integrator: unknown GSL stepper 'nosuch'", "unknown GSL stepper", integ{method = "gsl:nosuch"})
err("dm.integrator: method 'prk' needs tableau = ", "prk without a tableau", integ{method = "prk"})
err("dm.integrator: tableau.a must be 3x3, got 2x2", "tableau of mismatched size",
    integ{method = "prk", tableau = {a = {{0, 0}, {0.5, 0.5}}, b = {1 / 6, 2 / 3, 1 / 6}}})
err("dm.integrator: tableau.a%[2%]%[1%] must be a number", "tableau with a string",
    integ{method = "prk", tableau = {a = {{0, 0}, {"x", 0.5}}, b = {0.5, 0.5}}})
err("dm.integrator: tableau.b must list 1..20 weights", "tableau without b", integ{method = "prk", tableau = {a = {{1}}}})
err("dm.integrator: holonomic constraints are not supported with the gauss tableau %(s = 2%)", "Gauss 2 with constraints",
    function() dm.integrator(dm.systems.spherical_pendulum_r3(), {method = "gauss", stages = 2}) end)
err("method 'rk4' does not support holonomic constraints", "rk4 with constraints",
    function() dm.integrator(dm.systems.spherical_pendulum_r3(), {method = "rk4"}) end)

-- states
local G = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.05})
err("step: state {q = ..., p = ...} or {q = ..., v = ...} expected, got number", "state not a table", function() G:step(3) end)
err("step: the state has no field 'q'", "no q", function() G:step{p = {0, 2}} end)
err("step: the state needs momenta p or velocities v besides q", "neither p nor v", function() G:step{q = {0.4, 0}} end)
err("step: state.q: vector of length 2 expected, got length 3", "wrong size q", function() G:step{q = {0.4, 0, 0}, p = {0, 2}} end)
err("step: state.p: vector of length 2 expected, got length 1", "wrong size p", function() G:step{q = {0.4, 0}, p = dm.vec{2}} end)
err("step: state.v: number expected at index 2, got string", "non-numeric v", function() G:step{q = {0.4, 0}, v = {0, "2"}} end)
err("step: state.q contains NaN or Inf %(component 2 = nan%)", "NaN in q", function() G:step{q = {0.4, 0 / 0}, p = {0, 2}} end)
err("run: state.p contains NaN or Inf %(component 1 = inf%)", "Inf in p", function() G:run({q = {0.4, 0}, p = {1 / 0, 2}}, {steps = 3}) end)
err("step: state.t must be a finite number", "bad t", function() G:step{q = {0.4, 0}, p = {0, 2}, t = "now"} end)
err("bad argument #2 to 'step' %(finite non%-zero step size expected%)", "h = 0 to step", function() G:step(k0, 0) end)
err("no step size: give h in dm.integrator", "no h anywhere", function() dm.integrator(kep, {}):step(k0) end)
err("integ.h must be a finite non%-zero number, got inf", "integ.h = inf", function() G.h = 1 / 0 end)
err("integrator field 'method' is read%-only", "read-only field", function() G.method = "rk4" end)
err("integrator has no field or method 'hh'", "unknown field", function() return G.hh end)
err("step: the initial position violates the constraints", "constraint violated at the start",
    function() dm.integrator(dm.systems.spherical_pendulum_r3{l = 1}, {method = "trapezoid", h = 0.1}):step{q = {0, 0, -2}, v = {0.1, 0, 0}} end)
err("symplecticity_defect: the step Jacobian in the containing space is not defined for constrained systems",
    "defect of a constrained system",
    function() dm.integrator(dm.systems.spherical_pendulum_r3{l = 1}, {method = "trapezoid", h = 0.1}):symplecticity_defect{q = {0, 0, -1}, v = {0.1, 0, 0}} end)
local closed
do
  local I <close> = dm.integrator(kep, {h = 0.1})
  closed = I
end
err("attempt to use a closed integrator", "a closed integrator", function() closed:step(k0) end)
T.ok(tostring(closed) == "<integrator (closed)>", "tostring of a closed integrator")

-- a Lagrangian whose Hessian d2L/dv2 is singular at the initial state
local deg = dm.system{name = "degenerate", coords = {"x", "y"},
  L = function(q, v) return 0.5 * (v.x + v.y)^2 - 0.5 * (q.x^2 + q.y^2) end}
local D = dm.integrator(deg, {method = "gauss", stages = 2, h = 0.1})
err("run: d2L/dv2 is singular at q = %(0.3, 0.1%), v = %(0.2, 0%): the Lagrangian of 'degenerate' is not regular",
    "run: singular Hessian at the initial state", function() D:run({q = {0.3, 0.1}, v = {0.2, 0}}, {steps = 10}) end)
err("step: d2L/dv2 is singular", "step: singular Hessian", function() D:step{q = {0.3, 0.1}, p = {1, 1}} end)
local half = dm.system{name = "half", coords = {"x"},
  L = function(q, v) return v.x^4 / 12 - 0.5 * q.x^2 end}
err("run: d2L/dv2 is singular at q = %(0.5%), v = %(0%)", "singular only at v = 0: named there",
    function() dm.integrator(half, {method = "midpoint", h = 0.1}):run({q = {0.5}, v = {0}}, {steps = 3}) end)

-- run options
err("run: give exactly one of steps = .* or t = ", "neither steps nor t", function() G:run(k0, {}) end)
err("run: give exactly one of steps", "both steps and t", function() G:run(k0, {steps = 3, t = 1}) end)
err("run: unknown option stpes %(options: steps, t, every", "misspelt run option", function() G:run(k0, {stpes = 3}) end)
err("run: every must be >= 1, got 0", "every = 0", function() G:run(k0, {steps = 3, every = 0}) end)
err("run: steps must be >= 0, got %-2", "negative steps", function() G:run(k0, {steps = -2}) end)
err("run: the final time t = %-1 cannot be reached from t0 = 0 with h = 0.05", "t behind the start", function() G:run(k0, {t = -1}) end)
err("run: momentum%[1%] must name a coordinate of 'Kepler %(Cartesian%)', got theta", "momentum of an unknown coordinate",
    function() G:run(k0, {steps = 3, momentum = {"theta"}}) end)
err("run: option 'h' must be a finite non%-zero number", "run h = 0", function() G:run(k0, {steps = 3, h = 0}) end)

-- numerical failures during a run: the trajectory so far and a message
local well = dm.system{name = "sqrt well", coords = {"x"}, L = function(q, v) return 0.5 * v.x^2 - dm.sqrt(q.x) end}
for _, m in ipairs{"trapezoid", "gauss"} do
  local tr, msg = dm.integrator(well, {method = m, h = 0.1}):run({q = {1}, v = {-2}}, {steps = 20})
  T.ok(#tr == 5 and tr:column("t")[5] == 0.4 and msg:find("^run: step 5 of 20 from t = 0.4 failed: .*outside the domain"),
       ("%s: leaving the domain of sqrt at step 5 keeps 5 samples: %s"):format(m, msg))
end

-- integ:order_estimate and dm.tableau
local pend = dm.systems.pendulum{g = 1}
local G = dm.integrator(pend, {method = "gauss"})
err("order_estimate: field 'h' must list at least 2 step sizes", "one step size",
    function() G:order_estimate{state = {q = {1}, p = {0.5}}, t = 2, h = {0.1}} end)
err("order_estimate: h%[2%] must be a positive number", "negative step size",
    function() G:order_estimate{state = {q = {1}, p = {0.5}}, t = 2, h = {0.1, -0.05}} end)
err("order_estimate: field 't' %(the final time, != 0%) is required", "no t",
    function() G:order_estimate{state = {q = {1}, p = {0.5}}, h = {0.1, 0.05}} end)
err("order_estimate: field 'state' %(the initial state%) is required", "no state",
    function() G:order_estimate{t = 2, h = {0.1, 0.05}} end)
err("order_estimate: unknown option stages %(options: state, t, h, reference; the method and its options are the integrator's%)",
    "a method option given to order_estimate", function() G:order_estimate{stages = 2, state = {q = {1}, p = {0.5}}, t = 2, h = {0.1, 0.05}} end)
T.ok(dm.order_estimate == nil, "one way to estimate an order: the integrator's method")
err("dm.tableau: gauss needs 1 <= s <= 20 stages, got 0", "Gauss with 0 stages", function() dm.tableau("gauss", 0) end)
err("dm.tableau: lobatto needs 2 <= s <= 20 stages, got 1", "Lobatto with 1 stage", function() dm.tableau("lobatto", 1) end)
err("bad argument #1 to 'tableau' %(invalid option 'radau'%)", "unknown tableau family", function() dm.tableau("radau", 3) end)
T.done()
