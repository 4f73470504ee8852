-- mech_adapt.lua -- variable steps from Lua: a time transformation of any
-- method (adapt = {monitor =} traced from a Lua function, {power =}, true)
-- and the symplectic-energy-momentum method "sem": runs to t = T that end
-- exactly there, the h column, the metadata, the fields, the error texts.
local T = require "dmech.test"
local dm = require "dmech"

-- {== a time transformation of Gauss s = 2 with a user monitor (Sundman type)
local kep = dm.systems.kepler()
local I = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.02,
  adapt = {monitor = function(q, p) return dm.sqrt(q.x^2 + q.y^2)^1.5 end}})
T.ok(I.method == "adapt:gauss" and I.stages == 2 and I.order == 4 and I.variable_steps
     and I.symplectic and I.symmetric, "adapt: method adapt:gauss, s = 2, order 4, variable steps")
local tr = I:run({q = {0.1, 0}, p = {0, math.sqrt(19)}}, {t = 20*math.pi})    -- e = 0.9, 10 periods
local t, h, E = tr:column("t"), tr:column("h"), tr:energy()
T.is(t[#tr], 20 * math.pi, "the run ends at t = 20 pi exactly")
T.ok(E:max() - E:min() < 1e-8, string.format("energy error over 10 periods at e = 0.9: %.3g",
     E:max() - E:min()))
T.ok(h:max() / h:min() > 100, string.format("steps from %.3g (pericentre) to %.3g (apocentre)",
     h:min(), h:max()))
local worst = 0
for k = 2, #tr do worst = math.max(worst, math.abs(h[k] - (t[k] - t[k - 1]))) end
T.ok(worst < 1e-13, "column h holds the physical steps")
local meta = tr:meta()
T.ok(meta.method == "adapt:gauss" and meta.stages == 2 and meta.h == 0.02 and meta.t_end == 20 * math.pi
     and meta.status == 0, "metadata: method, stages, nominal h, t_end")
T.ok(table.concat(tr:names(), ","):find(",energy,h$"), "columns end with energy, h")
-- the monitor may use the parameters; it is compiled, so the run equals the
-- same monitor written with the parameter's value
local I2 = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.02,
  adapt = {monitor = function(q, p, par) return (dm.sqrt(q.x^2 + q.y^2) / par.mu)^1.5 end}})
local tr2 = I2:run({q = {0.1, 0}, p = {0, math.sqrt(19)}}, {t = 2*math.pi})
local tr1 = I:run({q = {0.1, 0}, p = {0, math.sqrt(19)}}, {t = 2*math.pi})
T.ok(#tr1 == #tr2 and tr1:column("x")[#tr1] == tr2:column("x")[#tr2], "a monitor reading a parameter")
-- one step from Lua: the state's t advances by the physical step
local s1 = I2:step({q = {0.1, 0}, p = {0, math.sqrt(19)}, t = 1.5})
T.ok(math.abs(s1.t - 1.5 - 0.02 * 0.1^1.5) < 1e-6 and s1.t > 1.5, "integ:step returns the physical time")

-- {== the potential's monitor, the explicit path
local C = dm.integrator(kep, {method = "composition", order = 8, h = 0.01, adapt = true})
T.ok(C.method == "adapt:composition" and C.explicit and C.order == 8, "adapt = true: explicit order 8")
local tc = C:run({q = {0.1, 0}, p = {0, math.sqrt(19)}}, {t = 2*math.pi})
T.ok(math.abs(tc:column("x")[#tc] - 0.1) < 1e-9 and tc:column("t")[#tc] == 2*math.pi,
     string.format("one period at e = 0.9 returns to pericentre (x = %.12f)", tc:column("x")[#tc]))
local P = dm.integrator(kep, {method = "trapezoid", h = 0.01, adapt = {power = 1}})
T.ok(P:run({q = {0.4, 0}, p = {0, 2}}, {steps = 10}):column("t")[11] > 0, "adapt = {power = 1}")

-- {== symplectic-energy-momentum
local pend = dm.system{coords = {"q"}, L = function(q, v) return 0.5*v.q^2 + dm.cos(q.q) end}
local S = dm.integrator(pend, {method = "sem", h = 0.1})
T.ok(S.variable_steps and S.order == 2 and S.stages == 1, "sem: order 2, one stage by default")
local st = S:run({q = {1}, p = {0.5}}, {t = 10})
local hs, q = st:column("h"), st:column("q")
T.is(st:column("t")[#st], 10, "sem run ends at t = 10")
T.ok(hs:min() > 0.0074 and hs:max() < 0.1005, string.format("sem steps in [%.4g, %.4g]", hs:min(), hs:max()))
local Ed0, dEd = nil, 0
for k = 2, #st - 1 do            -- the last step is the fixed one that ends the run
  local v = (q[k] - q[k - 1]) / hs[k]
  local Ed = 0.5 * v * v - math.cos(0.5 * (q[k] + q[k - 1]))
  Ed0 = Ed0 or Ed
  dEd = math.max(dEd, math.abs(Ed - Ed0))
end
T.ok(dEd < 1e-13, string.format("sem: the discrete energy of the steps is constant to %.2g", dEd))
T.is(S.stats.flagged, 0, "sem: no step flagged")
T.ok(dm.integrator(pend, {method = "sem", stages = 2, h = 0.2}).order == 4, "sem s = 2: order 4")

-- {== errors
local function err(pattern, name, f) T.error_like(f, pattern, name) end
local function integ(sys, o) return function() return dm.integrator(sys, o) end end
err("dm.integrator: option 'adapt' must be true or a table {monitor = function%(q, p, par%) ... end | power = a}, got number",
    "adapt = 3", integ(kep, {adapt = 3}))
err("dm.integrator: unknown field 'monitr' in adapt %(fields: monitor, power%)", "misspelt adapt field",
    integ(kep, {adapt = {monitr = function(q) return 1 end}}))
err("dm.integrator: adapt.monitor must be a function%(q, p, par%) returning g%(q%) > 0, got number",
    "monitor not a function", integ(kep, {adapt = {monitor = 2}}))
err("dm.integrator: adapt.monitor of system 'Kepler %(Cartesian%)' must be a function of the coordinates q only %(it depends on p.y%)",
    "monitor depending on p", integ(kep, {adapt = {monitor = function(q, p) return 1 + p.y^2 end}}))
err("dm.integrator: adapt: give monitor or power, not both", "monitor and power",
    integ(kep, {adapt = {monitor = function(q) return 1 end, power = 2}}))
err("dm.integrator: adapt.power must be a number in %[0, 8%], got 9", "power out of range",
    integ(kep, {adapt = {power = 9}}))
err("dm.integrator: adapt.monitor of system 'Kepler %(Cartesian%)' must return one expression, got a list",
    "monitor returning a list", integ(kep, {adapt = {monitor = function(q) return {1, 2} end}}))
local damped = dm.system{coords = {"x"}, L = function(q, v) return 0.5*v.x^2 - 0.5*q.x^2 end,
                         force = function(q, v) return {-0.1*v.x} end}
err("dm.integrator: adapt: the time transformation keeps the energy level of the start, which a generalized force changes",
    "adapt on a forced system", integ(damped, {adapt = {monitor = function(q) return 1 end}}))
err("dm.integrator: sem: energy%-momentum steps need a conservative, unconstrained system", "sem with a force",
    integ(damped, {method = "sem"}))
err("run: adapt: the potential's monitor needs U = %-V = L%(q, 0%) > 0 %(an attractive potential%); not so at q = %(1%): give adapt.monitor",
    "potential's monitor of an oscillator", function()
      dm.integrator(dm.system{coords = {"x"}, L = function(q, v) return 0.5*v.x^2 - 0.5*q.x^2 end},
                    {h = 0.1, adapt = true}):run({q = {1}, p = {0}}, {t = 1})
    end)
err("dm.integrator: option 'order' does not apply to method 'gauss'", "options are the method's",
    integ(kep, {order = 4, adapt = true}))
T.done()
