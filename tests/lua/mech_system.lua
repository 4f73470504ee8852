-- mech_system.lua -- dm.system and the C catalogue entries: tracing, printing, conversions
-- (energy, momentum, velocity) against hand-computed values, parameters
-- changed after creation (also under existing integrators), built-in C
-- systems equal to traced ones, and every error of system construction.
local T = require "dmech.test"
local dm = require "dmech"

local function V_j2(R2, z, J2)
  local R = math.sqrt(R2)
  return -1 / R + J2 / R^3 * (1.5 * z^2 / R2 - 0.5)
end

local sat = dm.system{
  name = "J2 satellite (cylindrical)", coords = {"r", "theta", "z"}, params = {J2 = 0.05},
  L = function(q, v, p)
    local r, z = q.r, q.z
    local R = dm.sqrt(r^2 + z^2)
    local V = -1 / R + p.J2 / R^3 * (1.5 * z^2 / R^2 - 0.5)
    return 0.5 * (v.r^2 + r^2 * v.theta^2 + v.z^2) - V
  end}

-- object, fields, printing
T.ok(tostring(sat):match("^<system 'J2 satellite %(cylindrical%)': 3 coords %(r, theta, z%), J2=0.05; traced, %a+, mechanical>$"),
     "tostring is one line with coords, params and structure: " .. tostring(sat))
T.is(sat.n, 3, "sys.n")
T.is(table.concat(sat.coords, ","), "r,theta,z", "sys.coords")
T.is(table.concat(sat.cyclic, ","), "theta", "theta detected cyclic (L free of it)")
T.ok(sat.mechanical and not sat.separable and sat.traced and not sat.forced and sat.m == 0,
     "flags: mechanical, not separable (M depends on r), traced, unforced, unconstrained")
T.ok(tostring(sat.L):find("J2") and tostring(sat.L):find("v_theta"), "sys.L prints the traced formula")
T.is(tostring(sat.dLdv[2]), "r^2*v_theta", "sys.dLdv[2] = r^2 v_theta")
T.is(tostring(sat.dLdv), "{v_r, r^2*v_theta, v_z}", "sys.dLdv prints as a list")
T.is(tostring(sat.d2Ldv2), "{{1, 0, 0}, {0, r^2, 0}, {0, 0, 1}}", "sys.d2Ldv2 prints as a matrix")
T.is(tostring(sat.d2Ldv2[2][2]), "r^2", "sys.d2Ldv2[2][2] = r^2")
T.is(tostring(sat.dLdq[2]), "0", "sys.dLdq[2] = 0 (cyclic)")
T.ok(({["2*r*v_theta"] = 1, ["2*v_theta*r"] = 1})[tostring(sat.d2Ldvdq[2][1])], "sys.d2Ldvdq[2][1] = 2 r v_theta")
T.ok(sat.force == nil and sat.constraints == nil, "no force, no constraints")
T.is(tostring(sat.L:diff(sat.v.theta)), "r^2*v_theta", "sys.q, sys.v, sys.p are the traced symbols (dL/dv_theta)")
T.is(tostring(sat.p.J2), "J2", "sys.p.J2 is the parameter")

-- conversions against hand-computed values
local q, v = {2.385, 0.3, 0.7}, {0.1, 0.45, -0.2}
local r, z = q[1], q[3]
local Lexp = 0.5 * (v[1]^2 + r^2 * v[2]^2 + v[3]^2) - V_j2(r^2 + z^2, z, 0.05)
local Eexp = 0.5 * (v[1]^2 + r^2 * v[2]^2 + v[3]^2) + V_j2(r^2 + z^2, z, 0.05)
T.near(sat:lagrangian{q = q, v = v}, Lexp, 1e-15, "sys:lagrangian")
T.near(sat:energy{q = q, v = v}, Eexp, 1e-15, "sys:energy = p.v - L")
local p = sat:momentum{q = q, v = v}
T.ok(math.abs(p[1] - 0.1) < 1e-16 and math.abs(p[2] - r^2 * 0.45) < 1e-15 and math.abs(p[3] + 0.2) < 1e-16,
     "sys:momentum = (rdot, r^2 thetadot, zdot)")
T.near(sat:momentum({q = q, v = v}, "theta"), r^2 * 0.45, 1e-15, "sys:momentum({q = q, v = v}, 'theta') is the component")
T.near(sat:momentum{q = dm.vec(q), v = dm.vec(v)}[2], r^2 * 0.45, 1e-15, "sys:momentum with vecs")
local w = sat:velocity{q = q, p = p}
T.ok(math.abs(w[1] - 0.1) + math.abs(w[2] - 0.45) + math.abs(w[3] + 0.2) < 1e-15, "sys:velocity inverts the Legendre map")
T.near(sat:energy{q = {z = 0.7, r = 2.385, theta = 0.3}, v = v}, Eexp, 1e-15, "vectors keyed by coordinate names")

-- parameters
T.is(sat.params.J2, 0.05, "sys.params.J2")
T.is(#sat.params, 1, "#sys.params")
T.is(tostring(sat.params), "{J2 = 0.05}", "tostring(sys.params)")
local names = {}
for k, x in pairs(sat.params) do names[#names + 1] = k .. "=" .. x end
T.is(table.concat(names, " "), "J2=0.05", "pairs(sys.params)")
sat.params.J2 = 1.0826e-3
T.near(sat:energy{q = q, v = v}, 0.5 * (v[1]^2 + r^2 * v[2]^2 + v[3]^2) + V_j2(r^2 + z^2, z, 1.0826e-3), 1e-15,
       "sys.params.J2 = x changes the compiled system at once")
T.ok(sat:set{J2 = 0.05} == sat and sat.params.J2 == 0.05, "sys:set{...} returns the system")
T.error_like(function() sat:set{J2 = 1, J3 = 2} end, "no parameter 'J3' in system 'J2 satellite %(cylindrical%)' %(parameters: J2%)",
             "set with an unknown name raises")
T.is(sat.params.J2, 0.05, "... and changes nothing")
T.error_like(function() sat.params.J2 = "big" end, "parameter 'J2' needs a number, got string", "params need numbers")
T.error_like(function() return sat.params.J3 end, "no parameter 'J3'", "reading an unknown parameter raises")

-- parameter order: a map is sorted by name, a list of pairs keeps its order
local function lin(params)
  return dm.system{coords = {"x"}, params = params,
    L = function(q, v, p) return 0.5 * p.b * v.x^2 - 0.5 * p.a * q.x^2 end}
end
T.ok(tostring(lin{b = 2, a = 1}):find("a=1 b=2"), "params as a map: sorted by name")
T.ok(tostring(lin{{"b", 2}, {"a", 1}}):find("b=2 a=1"), "params as a list of pairs: in that order")

-- a parameter in the mass matrix: integrators built earlier see the change
local osc = lin{b = 2, a = 1.5}
T.ok(osc.separable, "L = b v^2/2 - a x^2/2 is separable")
local sv = dm.integrator(osc, {method = "trapezoid", h = 0.1})
local before = sv:step{q = {0.7}, p = {0.3}}
osc.params.b = 3.5
local after = sv:step{q = {0.7}, p = {0.3}}
local fresh = dm.integrator(lin{b = 3.5, a = 1.5}, {method = "trapezoid", h = 0.1}):step{q = {0.7}, p = {0.3}}
T.ok(after.q[1] == fresh.q[1] and after.p[1] == fresh.p[1] and after.q[1] ~= before.q[1],
     "changing the mass parameter rebuilds the integrator (same step as a fresh system)")

-- native and tape compile the same system
local function pend(native)
  return dm.system{name = "pendulum", coords = {"q"}, params = {k = 1}, native = native,
    L = function(q, v, p) return 0.5 * v.q^2 + p.k * dm.cos(q.q) end}
end
local pt = pend(false)
T.ok(not pt.native and tostring(pt):find("traced, tape"), "native = false runs the tape")
local pa = pend("auto")
T.ok(math.abs(pa:energy{q = {1.3}, v = {0.4}} - pt:energy{q = {1.3}, v = {0.4}}) < 1e-16, "auto (native when a compiler works) = tape")

-- built-in C systems: the same interface, equal values
local j2c = dm.systems.j2{J2 = 0.05, impl = "c"}
local j2t = dm.systems.j2{J2 = 0.05}
local qc, vc = {1.1, -0.4, 0.35}, {0.2, 0.9, 0.15}
T.near(j2c:energy{q = qc, v = vc}, j2t:energy{q = qc, v = vc}, 1e-15, "built-in J2 energy = traced J2 energy")
T.near(j2c:lagrangian{q = qc, v = vc}, j2t:lagrangian{q = qc, v = vc}, 1e-15, "built-in J2 Lagrangian = traced")
T.ok(not j2c.traced and tostring(j2c):find("built%-in C"), "built-ins say so")
T.error_like(function() return j2c.L end, "system.L: 'J2 satellite %(Cartesian%)' is a built%-in C system without expressions",
             "expressions of a built-in system: clear error (reduction needs a traced system)")
T.error_like(function() return j2c.dLdq end, "without expressions", "derivatives of a built-in system")
T.error_like(function() dm.routh(j2c, {cyclic = {"x"}, mu = 1}) end,
             "dm.routh needs a system defined by a Lagrangian %(dm.system{...}%); 'J2 satellite %(Cartesian%)' is a built%-in C system without expressions",
             "reduction refuses a built-in system")
T.is(table.concat(dm.systems.spherical_pendulum{impl = "c"}.cyclic, ","), "phi", "built-in spherical pendulum: phi cyclic")
T.error_like(function() dm.systems.kepler{dim = 4, impl = "c"} end, "dim must be 2 or 3", "builtin kepler dim")
T.error_like(function() dm.systems.spherical_pendulum_r3{form = "cube", impl = "c"} end, "form must be", "builtin r3 form")

-- the singular Hessian is named
local sing = dm.system{name = "degenerate", coords = {"x", "y"},
  L = function(q, v) return 0.5 * (v.x + v.y)^2 - 0.5 * (q.x^2 + q.y^2) end}
T.error_like(function() sing:velocity{q = {0.3, 0.1}, p = {1, 1}} end,
             "d2L/dv2 is singular at q = %(0.3, 0.1%).*the Lagrangian of 'degenerate' is not regular",
             "velocity of a degenerate Lagrangian: singular Hessian named")

-- construction errors
local function L0(q, v) return 0.5 * v[1]^2 end
local function err(pattern, name, spec)
  T.error_like(function() return dm.system(spec) end, pattern, name)
end
err("bad argument #1 to 'system' %(table expected, got nil%)", "no table", nil)
err("field 'coords' must be a non%-empty list", "empty coords", {coords = {}, L = L0})
err("coordinate 'x' is listed twice", "duplicate coords", {coords = {"x", "x"}, L = L0})
err("coordinate 1 must be a name", "bad coordinate name", {coords = {"1x"}, L = L0})
err("field 'L' must be a function L%(q, v, p%)", "no L", {coords = {"x"}})
err("L of system 'system' returned nothing", "L returns nil", {coords = {"x"}, L = function() end})
err("L of system 'system' must return one expression, got a list of 2", "L returns a list",
    {coords = {"x"}, L = function(q, v) return {v.x, q.x} end})
err("mech_system.lua:%d+: branch on a symbolic value %('<' on an expression%) in L of system 'bad'.*dm%.select",
    "branch in L names file:line", {name = "bad", coords = {"x"}, L = function(q, v)
      if q.x < 0 then return v.x^2 end
      return v.x^2 + q.x
    end})
err("L depends on symbol 'k', which is not a coordinate, velocity or parameter", "unknown symbol",
    {coords = {"x"}, L = function(q, v) return 0.5 * v.x^2 - dm.sym("k") * q.x^2 end})
err("no element 'thta' in q %(elements: r, theta%)", "misspelt coordinate",
    {coords = {"r", "theta"}, L = function(q, v) return v.r^2 + q.thta end})
err("no element 'mu' in p", "undeclared parameter", {coords = {"x"}, params = {k = 1},
    L = function(q, v, p) return v.x^2 - p.mu * q.x end})
err("params must map names to numbers", "non-numeric parameter", {coords = {"x"}, params = {k = "one"}, L = L0})
err("force of system 'system' must return a list of 2 expressions %(one per coordinate%), got 1 value",
    "force of the wrong size", {coords = {"x", "y"}, L = function(q, v) return v.x^2 + v.y^2 end,
    force = function(q, v) return {-v.x} end})
err("constraint 1 depends on the velocity 'v_x'", "velocity in a constraint",
    {coords = {"x"}, L = L0, constraints = function(q) return q.x - dm.sym("v_x") end})
err("native must be", "bad native mode", {coords = {"x"}, L = L0, native = "sometimes"})
err("constraints of system 'system' must return an expression or a flat list of them, got a nested list",
    "nested constraint list", {coords = {"x"}, L = L0, constraints = function(q) return {{q.x}, {q.x^2}} end})
T.error_like(function() return sat.nosuch end, "system has no field or method 'nosuch'", "unknown field")
T.error_like(function() sat:energy{q = {1, 2}, v = v} end, "energy: state.q: vector of length 3 expected, got length 2", "wrong size q")
T.error_like(function() sat:energy{q = {r = 1, theta = 2}, v = v} end, "energy: state.q: no value for coordinate 'z'", "missing named coordinate")
T.error_like(function() sat:energy{q = {r = 1, th = 2, z = 0}, v = v} end, "energy: state.q: unknown coordinate th", "unknown named coordinate")
T.error_like(function() sat:energy{q = q, v = "fast"} end, "energy: state.v: vec or table of 3 numbers expected, got string", "wrong type v")
-- one vocabulary: states are tables, and a state given by momenta works too
T.error_like(function() sat:energy(q, v) end,
  "energy: a state {q=, v=} or {q=, p=} expected, got a list %(sys:energy%(q, v%) is written sys:energy{q = q, v = v}%)",
  "the positional (q, v) form says how to write it now")
T.error_like(function() sat:momentum{v = v} end, "momentum: the state needs q", "state without q")
T.error_like(function() sat:lagrangian{q = q} end, "lagrangian: the state needs v or p", "state without v or p")
T.near(sat:energy{q = q, p = sat:momentum{q = q, v = v}}, Eexp, 1e-14, "energy of a state given by (q, p)")
T.error_like(function() return sat.legendre end, "system has no field or method .legendre.", "one momentum method: sys:legendre is gone (sys:momentum)")
T.error_like(function() sat:momentum({q = q, v = v}, "phi") end, "no coordinate 'phi' in system 'J2 satellite %(cylindrical%)' %(coordinates: r, theta, z%)",
             "momentum of an unknown coordinate")
-- systems get __close (to-be-closed variables): everything is released at
-- once, idempotently, and what was built on a closed system says so
do
  local kept
  do
    local sc <close> = dm.systems.pendulum{g = 2.385}
    kept = sc
    T.ok(sc:energy{q = {0.3}, v = {0.1}} < 0, "a <close> system works in its scope")
  end
  T.is(tostring(kept), "<system (closed)>", "closed at the end of the scope")
  local s2 = dm.systems.pendulum{}
  local I2 = dm.integrator(s2, {h = 0.1})
  local par = s2.params
  getmetatable(s2).__close(s2)
  getmetatable(s2).__close(s2)
  T.error_like(function() return s2.n end, "attempt to use a closed system", "fields of a closed system")
  T.error_like(function() s2:energy{q = {1}, v = {0}} end, "attempt to use a closed system", "methods of a closed system")
  T.error_like(function() return par.g end, "attempt to use the parameters of a closed system", "its params proxy")
  T.error_like(function() I2:step{q = {1}, v = {0}} end, "attempt to use an integrator whose system was closed",
    "an integrator of a closed system")
  T.error_like(function() dm.integrator(s2, {}) end, "attempt to use a closed system", "dm.integrator of a closed system")
  local sp = dm.systems.spherical_pendulum{}
  local red = dm.routh(sp, {cyclic = {"phi"}, mu = 0.3})
  local R = dm.integrator(red, {method = "gauss", h = 0.05})
  local D = red:discrete{h = 0.1}
  do local _ <close> = red end
  T.ok(tostring(red) == "<routh (closed)>" and tostring(D) == "<discrete Routh (closed)>", "a Routh reduction closes too")
  T.error_like(function() return red.mu end, "attempt to use a closed Routh reduction", "fields of a closed reduction")
  T.error_like(function() R:step{q = {1}, p = {0}} end, "attempt to use an integrator whose system was closed",
    "its integrators refuse to run")
  T.error_like(function() D:psi({1}, {1.1}) end, "attempt to use a closed Routh reduction", "its discrete Routh object")
  local red2 = dm.routh(sp, {cyclic = {"phi"}, mu = 0.3})
  getmetatable(sp).__close(sp)
  T.error_like(function() red2:project{q = {1, 0}, v = {0, 1}} end, "the reduction's full system was closed",
    "a reduction whose full system was closed cannot project full states")
  T.ok(dm.integrator(red2, {h = 0.1}):step{q = {1}, p = {0}}.q[1] < 1, "but it still integrates: it has its own compiled systems")
end
T.done()
