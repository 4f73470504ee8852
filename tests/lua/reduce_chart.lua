-- reduce_chart.lua -- the double spherical pendulum in R^3 x R^3 reduced by
-- the simultaneous rotation in the chart "bob 1 polar" (bob 1 in (r1, theta1,
-- z1), bob 2 from bob 1 in Cartesian (xi2, eta2, z2) of the frame rotated by
-- theta1), built as a traced dm.system and reduced by dm.routh: the derived
-- I and A equal their closed forms, the chart is singular only at r1 = 0,
-- positions (theta reconstructed) agree with the unreduced Cartesian
-- constrained system to order 4, and at a close approach r2 -> 0 its energy
-- error stays at the h^4 level where the cylindrical chart spikes
-- (doc/reduce.md §15; thesis §2.10.4).
local T = require "dmech.test"
local dm = require "dmech"

local P = {m1 = 1.3, m2 = 0.8, l1 = 1.1, l2 = 0.9, g = 9.81}
local function chart(params)
  return dm.system{name = "dsp bob 1 polar", params = params,
    coords = {"r1", "theta1", "z1", "xi2", "eta2", "z2"},
    L = function(q, v, p)
      local w = v.theta1
      local a, b, c = v.r1, q.r1 * w, v.z1                          -- bob 1 in the frame
      local A, B, C = a + v.xi2 - w * q.eta2, b + v.eta2 + w * q.xi2, c + v.z2  -- bob 2
      return 0.5 * p.m1 * (a^2 + b^2 + c^2) + 0.5 * p.m2 * (A^2 + B^2 + C^2)
        - p.m1 * p.g * q.z1 - p.m2 * p.g * (q.z1 + q.z2)
    end,
    constraints = function(q, p)
      return {q.r1^2 + q.z1^2 - p.l1^2, q.xi2^2 + q.eta2^2 + q.z2^2 - p.l2^2}
    end}
end

-- Cartesian (q1, q2 from bob 1) -> chart state
local function chart_state(qx, vx)
  local r = math.sqrt(qx[1]^2 + qx[2]^2)
  local c, s = qx[1] / r, qx[2] / r
  local w = (qx[1] * vx[2] - qx[2] * vx[1]) / r^2
  local xi, eta = c * qx[4] + s * qx[5], -s * qx[4] + c * qx[5]
  return {r, math.atan(qx[2], qx[1]), qx[3], xi, eta, qx[6]},
    {c * vx[1] + s * vx[2], w, vx[3], c * vx[4] + s * vx[5] + w * eta, -s * vx[4] + c * vx[5] - w * xi, vx[6]}
end

-- Cartesian state from cylindrical data (r1, theta1, r2, phi) and rates
local function cartesian(p, Q, V)
  local r1, th, r2, th2 = Q[1], Q[2], Q[3], Q[2] + Q[4]
  local rd1, thd, rd2, thd2 = V[1], V[2], V[3], V[2] + V[4]
  local s1, s2 = math.sqrt(p.l1^2 - r1^2), math.sqrt(p.l2^2 - r2^2)
  return {r1 * math.cos(th), r1 * math.sin(th), -s1, r2 * math.cos(th2), r2 * math.sin(th2), -s2},
    {rd1 * math.cos(th) - r1 * thd * math.sin(th), rd1 * math.sin(th) + r1 * thd * math.cos(th), r1 * rd1 / s1,
     rd2 * math.cos(th2) - r2 * thd2 * math.sin(th2), rd2 * math.sin(th2) + r2 * thd2 * math.cos(th2), r2 * rd2 / s2}
end

-- derivation --------------------------------------------------------------
local sys = chart(P)
T.ok(sys.traced, "the chart is a traced system")
T.error_like(function() return dm.routh(sys, {cyclic = {"r1"}}) end, "'r1' is not a cyclic coordinate",
             "r1 is not cyclic (L depends on it)")
local red = dm.routh(sys, {cyclic = {"theta1"}})
T.is(table.concat(red.shape, ","), "r1,z1,xi2,eta2,z2", "preshape coordinates")
T.is(#red.constraints, 2, "two constraints on the preshape space")
T.ok(tostring(red):find("magnetic term beta != 0", 1, true), "non-trivial magnetic term: " .. tostring(red))
do
  local x = {0.7385, -0.821, 0.3127, -0.4711, -0.6915}
  local ev = red:eval{q = x}
  local Ie = P.m1 * x[1]^2 + P.m2 * ((x[1] + x[3])^2 + x[4]^2)
  T.near(ev.I, Ie, 1e-14, "I = m1 r1^2 + m2 ((r1 + xi2)^2 + eta2^2)")
  local Ae = {-P.m2 * x[4] / Ie, 0, -P.m2 * x[4] / Ie, P.m2 * (x[1] + x[3]) / Ie, 0}
  local d = 0
  for i = 1, 5 do d = math.max(d, math.abs(ev.A[i] - Ae[i])) end
  T.ok(d <= 1e-15, ("A = m2/I (-eta2 dr1 - eta2 dxi2 + (r1 + xi2) deta2) (max diff %.1g)"):format(d))
  -- the singular set: at r1 -> 0 the locked inertia stays regular, Mtilde does not
  local x0 = {1e-4, -1.1, 0.3127, -0.4711, -0.6915}
  local e0 = red:eval{q = x0}
  T.ok(e0.I > 0.2, ("at r1 = 1e-4 the locked inertia is regular (I = %.3f): the action is free"):format(e0.I))
  local M = dm.mat(e0.Mtilde)
  local ev2 = M:eig()
  local lo, hi = math.huge, 0
  for i = 1, #ev2 do lo, hi = math.min(lo, math.abs(ev2[i])), math.max(hi, math.abs(ev2[i])) end
  T.ok(lo / hi < 1e-7, ("but Mtilde is singular there (eigenvalue ratio %.1g): the chart's singular set"):format(lo / hi))
end

-- positions against the unreduced Cartesian system, order by step halving ----
do
  local Q, V = {0.6, 0.3, 0.5, 0.3}, {0.1, 3.3, -0.1, 0.2}
  local qx, vx = cartesian(P, Q, V)
  local q, v = chart_state(qx, vx)
  local st, mu = red:project{q = q, v = v}
  red:set{mu = mu}
  local cart = dm.systems.double_spherical_pendulum_r3(P)
  local hs, err = {0.05, 0.025, 0.0125}, {}
  for j, h in ipairs(hs) do
    local n = math.floor(0.5 / h + 0.5)
    local opt = {method = "lobatto", stages = 3, h = h}
    local full = red:reconstruct(dm.integrator(red, opt):run(st, {steps = n, every = n}), {theta = q[2]})
    local ref = dm.integrator(cart, opt):run({q = qx, v = vx}, {steps = n, every = n})
    local k = #full:column("t")
    local s = {}
    for _, c in ipairs{"r1", "theta1", "z1", "xi2", "eta2", "z2"} do s[c] = full:column(c)[k] end
    local cs, sn = math.cos(s.theta1), math.sin(s.theta1)
    local P6 = {s.r1 * cs, s.r1 * sn, s.z1, s.xi2 * cs - s.eta2 * sn, s.xi2 * sn + s.eta2 * cs, s.z2}
    err[j] = 0
    for i, c in ipairs{"x1", "y1", "z1", "x2", "y2", "z2"} do
      err[j] = math.max(err[j], math.abs(P6[i] - ref:column(c)[k]))
    end
  end
  local sl = math.log(err[1] / err[3]) / math.log(4)
  T.ok(math.abs(sl - 4) <= 0.2, ("positions q1, q2 at t = 0.5 vs unreduced Cartesian R3xR3 (Lobatto 3): "
       .. "order %.2f (%.2g, %.2g, %.2g)"):format(sl, err[1], err[2], err[3]))
end

-- energy error at a close approach r2 -> 0 (the example's motion, t ~ 5.85) --
do
  local U = {m1 = 1, m2 = 1, l1 = 1, l2 = 1, g = 9.81}
  local cyl = dm.systems.double_spherical_pendulum{form = "shape"}
  local rc = dm.routh(cyl, {cyclic = {"theta"}})
  local q0, v0 = {0, 0.67, 0.36, 0.68}, {1.2, -0.22, 0.24, -0.61}
  local sc, mu = rc:project{q = q0, v = v0}
  rc:set{mu = mu}
  local rb = dm.routh(chart(U), {cyclic = {"theta1"}})
  local qx, vx = cartesian(U, {q0[2], q0[1], q0[3], q0[4]}, {v0[2], v0[1], v0[3], v0[4]})
  local q, v = chart_state(qx, vx)
  local sb, mub = rb:project{q = q, v = v}
  rb:set{mu = mub}
  T.near(mub, mu, 1e-14, "the same momentum in both charts")
  local opt = {method = "lobatto", stages = 3, h = 0.01}
  local a = dm.integrator(rc, opt):run(sc, {steps = 600})
  local b = dm.integrator(rb, opt):run(sb, {steps = 600})
  local function window(tr)
    local t, E, m = tr:column("t"), tr:energy(), 0
    for k = 1, #t do
      if t[k] >= 5.75 and t[k] <= 5.95 then m = math.max(m, math.abs(E[k] / E[1] - 1)) end
    end
    return m
  end
  local r2, rmin = a:column("r2"), 1
  for k = 576, 596 do rmin = math.min(rmin, r2[k]) end
  local ea, eb = window(a), window(b)
  T.ok(rmin < 0.04 and ea >= 1e-5 and eb <= 1e-7,
       ("r2 down to %.3f: max |dE/E| %.2g in the cylindrical chart (singular at r2 = 0), %.2g bob 1 polar"):format(
       rmin, ea, eb))
end

T.done()
