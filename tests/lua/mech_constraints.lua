-- mech_constraints.lua -- constraints and forces through the Lua API on
-- TRACED systems: the spherical pendulum in R^3 keeps |q| = l to 1e-12
-- (RATTLE and Lobatto multipliers) and converges to the spherical-coordinate
-- solution at the method's order; the damped oscillator (Lagrange-
-- d'Alembert) converges to the exact solution at the method's order and its
-- energy decays at the rate c; traced systems equal the built-in C systems
-- on the same run to 1e-13.
local T = require "dmech.test"
local dm = require "dmech"

-- spherical pendulum: the same motion in angles and in R^3
local l, g = 1.3, 9.81
local th, ph, thd, phd = 1.2, 0.3, 0.5, 1.5
local function cart(a, b, ad, bd)
  local sa, ca, sb, cb = math.sin(a), math.cos(a), math.sin(b), math.cos(b)
  return {l * sa * cb, l * sa * sb, -l * ca},
         {l * (ca * cb * ad - sa * sb * bd), l * (ca * sb * ad + sa * cb * bd), l * sa * ad}
end
local q0, v0 = cart(th, ph, thd, phd)
local r3 = dm.systems.spherical_pendulum_r3{g = g, l = l}
local ang = dm.systems.spherical_pendulum{g = g, l = l}
T.ok(r3.m == 1 and r3.separable and #r3.constraints == 1, "R^3 pendulum: one constraint, separable L")
T.is(table.concat(ang.cyclic, ","), "phi", "angles: phi is cyclic")

for _, o in ipairs{{method = "trapezoid"}, {method = "lobatto", stages = 3}} do
  o.h = 0.01
  local I = dm.integrator(r3, o)
  local tr = I:run({q = q0, v = v0}, {steps = 2000})
  local x, y, z = tr:column("x"), tr:column("y"), tr:column("z")
  local vx, vy, vz = tr:column("v_x"), tr:column("v_y"), tr:column("v_z")
  local dg, dv = 0, 0
  for k = 1, #tr do
    dg = math.max(dg, math.abs(math.sqrt(x[k]^2 + y[k]^2 + z[k]^2) - l))
    dv = math.max(dv, math.abs(x[k] * vx[k] + y[k] * vy[k] + z[k] * vz[k]))
  end
  T.ok(dg <= 1e-12 and dv <= 1e-12, ("%s: | |q| - l | = %.2g and |q . v| = %.2g over 2000 steps"):format(
       tostring(I), dg, dv))
end

-- reference at T = 2 from the angles (Gauss 4, h = 0.002)
local ref = dm.integrator(ang, {method = "gauss", stages = 4, h = 0.002}):run({q = {th, ph}, v = {thd, phd}}, {t = 2})
local e = ref[#ref]
local qr, vr = cart(e.theta, e.phi, e.v_theta, e.v_phi)
for _, c in ipairs{{{method = "trapezoid"}, 2}, {{method = "lobatto", stages = 3}, 4},
                   {{method = "lobatto", stages = 4}, 6}, {{method = "composition", order = 4}, 4}} do
  local order, err = dm.integrator(r3, c[1]):order_estimate{state = {q = q0, v = v0}, t = 2,
    h = {0.04, 0.02, 0.01, 0.005}, reference = {q = qr, p = vr}}
  T.ok(math.abs(order - c[2]) <= 0.1, ("R^3 %s %s agrees with the angles at order %.3f (expected %d; errors %.2g .. %.2g)"):format(
       c[1].method, c[1].stages or c[1].order or "", order, c[2], err[1], err[4]))
end

-- damped oscillator x'' + c x' + omega^2 x = 0 against the exact solution
local omega, c = 2.385, 0.1
local damped = dm.systems.damped{omega = omega, c = c}
T.ok(damped.forced and #damped.force == 1, "the damped oscillator has a force")
local x0, u0 = 0.7, 0.2
local wd = math.sqrt(omega^2 - c^2 / 4)
local function exact(t)
  local A, B, e = x0, (u0 + c * x0 / 2) / wd, math.exp(-c * t / 2)
  local x = e * (A * math.cos(wd * t) + B * math.sin(wd * t))
  local u = -c / 2 * x + e * (-A * wd * math.sin(wd * t) + B * wd * math.cos(wd * t))
  return x, u
end
local xe, ue = exact(4)
for _, o in ipairs{{{method = "gauss", stages = 2}, 4}, {{method = "midpoint"}, 2}, {{method = "lobatto", stages = 3}, 4}} do
  local order = dm.integrator(damped, o[1]):order_estimate{state = {q = {x0}, v = {u0}}, t = 4,
    h = {0.2, 0.1, 0.05, 0.025}, reference = {q = {xe}, p = {ue}}}
  T.ok(math.abs(order - o[2]) <= 0.1, ("damped oscillator, %s: order %.3f against the exact solution"):format(
       o[1].method, order))
end
-- energy decay: the least-squares slope of log E over 50 time units is -c
local tr = dm.integrator(damped, {method = "gauss", stages = 2, h = 0.05}):run({q = {x0}, v = {u0}}, {t = 50})
local t, E = tr:column("t"), tr:energy()
local n, sx, sy, sxx, sxy = #tr, 0, 0, 0, 0
for k = 1, n do
  local y = math.log(E[k])
  sx, sy, sxx, sxy = sx + t[k], sy + y, sxx + t[k]^2, sxy + t[k] * y
end
local rate = -(n * sxy - sx * sy) / (n * sxx - sx * sx)
T.ok(math.abs(rate / c - 1) < 0.01, ("energy decays like exp(-c t): fitted rate %.5f, c = %g"):format(rate, c))
T.ok(E[n] < E[1] * math.exp(-c * 50) * 1.05 and E[n] > E[1] * math.exp(-c * 50) * 0.95,
     ("E(50)/E(0) = %.4g ~ exp(-5) = %.4g"):format(E[n] / E[1], math.exp(-5)))

-- traced = built-in C on the same run (final states, max-norm over q and p)
local function final(sys, o, s, steps)
  local tr = dm.integrator(sys, o):run(s, {steps = steps, every = steps})
  local q, p = {}, {}
  for i, name in ipairs(sys.coords) do
    q[i], p[i] = tr:column(name)[#tr], tr:column("p_" .. name)[#tr]
  end
  return {q = q, p = p}
end
local function diff(a, b)
  local d = 0
  for i = 1, #a.q do d = math.max(d, math.abs(a.q[i] - b.q[i]), math.abs(a.p[i] - b.p[i])) end
  return d
end
local function same(name, traced, builtin, o, s, steps)
  local d = diff(final(traced, o, s, steps), final(builtin, o, s, steps))
  T.ok(d <= 1e-13, ("%s, %d steps: traced (%s) = built-in C (%.2g)"):format(name, steps,
       traced.native and "native" or "tape", d))
end
local j2s = {q = {2, 0, 0.3}, p = {0, 0.6, 0.1}}
for _, native in ipairs{false, "auto"} do
  local sys = dm.system{name = "J2", coords = {"x", "y", "z"}, params = {J2 = 0.05}, native = native,
    L = function(q, v, p)
      local R = dm.sqrt(q.x^2 + q.y^2 + q.z^2)
      return 0.5 * (v.x^2 + v.y^2 + v.z^2) + 1 / R - p.J2 / R^3 * (1.5 * q.z^2 / R^2 - 0.5)
    end}
  same("J2, Gauss 2 h=0.05", sys, dm.systems.j2{J2 = 0.05, impl = "c"}, {method = "gauss", stages = 2, h = 0.05}, j2s, 200)
end
same("Kepler, explicit Stormer-Verlet h=0.01", dm.systems.kepler(), dm.systems.kepler{impl = "c"},
     {method = "trapezoid", h = 0.01}, {q = {0.4, 0}, p = {0, 2}}, 2000)
same("spherical pendulum in R^3, Lobatto 3 h=0.05", r3, dm.systems.spherical_pendulum_r3{g = g, l = l, impl = "c"},
     {method = "lobatto", stages = 3, h = 0.05}, {q = q0, v = v0}, 200)
same("spherical pendulum in angles, Gauss 2 h=0.05", ang, dm.systems.spherical_pendulum{g = g, l = l, impl = "c"},
     {method = "gauss", stages = 2, h = 0.05}, {q = {th, ph}, v = {thd, phd}}, 200)
same("damped oscillator, Gauss 2 h=0.1", damped, dm.systems.damped{omega = omega, c = c, impl = "c"},
     {method = "gauss", stages = 2, h = 0.1}, {q = {x0}, p = {u0}}, 500)
T.done()
