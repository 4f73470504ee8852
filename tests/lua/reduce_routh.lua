-- reduce_routh.lua -- dm.routh from Lua: the derived formulas print, the double
-- spherical pendulum's I, A, beta, V_mu equal the closed forms of doc/reduce.md
-- §14, RSPRK / classical / discrete Routh agree through dm.integrator(red, ...),
-- project -> run -> reconstruct equals the unreduced run, the non-canonical
-- defect is at round-off, mu and parameters change without re-deriving, a
-- singular locked inertia stops a run keeping the trajectory, and every error
-- of dm.routh is clear.
local T = require "dmech.test"
local dm = require "dmech"

-- J2 satellite in cylindrical coordinates ---------------------------------
local sat = dm.systems.j2_cylindrical{J2 = 0.05}
local red = dm.routh(sat, {cyclic = {"theta"}, mu = 1.1})
T.ok(tostring(red):match("^<routh 'J2 satellite %(cylindrical%) reduced by theta': shape %(r, z%); mu_theta=1.1; beta = 0>$"),
     "tostring: " .. tostring(red))
T.is(tostring(red.A), "0", "J2: the connection A = 0")
T.is(tostring(red.beta), "0", "J2: beta = 0")
T.is(tostring(red.I), "r^2", "J2: locked inertia r^2")
T.ok(tostring(red.amended):find("0.5*mu_theta^2/r^2", 1, true), "the amended potential has the centrifugal term mu^2/(2 r^2): " .. tostring(red.amended))
T.ok(tostring(red.routhian):find("mu_theta^2/r^2", 1, true) and tostring(red.routhian):find("v_r^2", 1, true),
     "the Routhian R = (rdot^2 + zdot^2)/2 - V - mu^2/(2 r^2) prints")
T.is(table.concat(red.shape, ","), "r,z", "red.shape")
T.is(table.concat(red.cyclic, ","), "theta", "red.cyclic")
T.is(red.mu, 1.1, "red.mu")
T.ok(red.full == sat and red.system.n == 2, "red.full is the system, red.system the reduced one (n = 2)")
do
  local r, z, mu, J2 = 1.7385, 0.4127, 1.1, 0.05
  local R = math.sqrt(r^2 + z^2)
  local V = -1 / R + J2 / R^3 * (1.5 * z^2 / R^2 - 0.5)
  local ev = red:eval{q = {r, z}, v = {0.12, -0.31}}
  T.near(ev.routhian, 0.5 * (0.12^2 + 0.31^2) - V - mu^2 / (2 * r^2), 1e-14, "numeric Routhian with the centrifugal term")
  local ep = red:eval{q = {r, z}, p = {0.12, -0.31}}      -- Mtilde = Id here: s = xdot
  T.near(ep.routhian, ev.routhian, 1e-15, "eval of a reduced state given by (x, s)")
  T.error_like(function() red:eval({r, z}, {0.12, -0.31}) end,
    "eval: a reduced state {q = x%[, v = xdot | p = s%]} expected, got a list", "eval takes a state table")
end

-- double spherical pendulum: closed forms (doc/reduce.md §14) -------------
local P = {m1 = 1.3, m2 = 0.8, l1 = 1.1, l2 = 0.9, g = 9.81}
local dsp = dm.systems.double_spherical_pendulum{m1 = P.m1, m2 = P.m2, l1 = P.l1, l2 = P.l2, g = P.g, form = "shape"}
local mu = 0.537
local rd = dm.routh(dsp, {cyclic = {"theta"}, mu = mu})
T.ok(tostring(rd):find("magnetic term beta != 0", 1, true), "double pendulum: magnetic term present")
T.ok(tostring(rd.beta):find("dr1^dphi", 1, true) and tostring(rd.beta):find("dr2^dphi", 1, true)
     and not tostring(rd.beta):find("dr1^dr2", 1, true), "beta = (...) dr1^dphi + (...) dr2^dphi: " .. tostring(rd.beta):sub(1, 80))
T.ok(tostring(rd.A):find("*dphi", 1, true) and #rd.A == 3, "A is a 1-form in (dr1, dr2, dphi)")
do
  local r1, r2, ph = 0.7385, 0.4127, 1.234
  local I = P.m1 * r1^2 + P.m2 * (r1^2 + r2^2 + 2 * r1 * r2 * math.cos(ph))
  local A = {-P.m2 / I * r2 * math.sin(ph), P.m2 / I * r1 * math.sin(ph), P.m2 / I * (r2^2 + r1 * r2 * math.cos(ph))}
  local Vmu = -P.g * (P.m1 * math.sqrt(P.l1^2 - r1^2) + P.m2 * (math.sqrt(P.l1^2 - r1^2) + math.sqrt(P.l2^2 - r2^2)))
    + mu^2 / (2 * I)
  local ev = rd:eval{q = {r1, r2, ph}}
  T.near(ev.I, I, 1e-14, "I = m1 r1^2 + m2 (r1^2 + r2^2 + 2 r1 r2 cos phi)")
  local worst = 0
  for i = 1, 3 do worst = math.max(worst, math.abs(ev.A[i] - A[i]) / math.abs(A[i])) end
  T.ok(worst <= 1e-14, ("A = (m2/I)(-r2 sin phi, r1 sin phi, r2^2 + r1 r2 cos phi), rel. err %.2g"):format(worst))
  local B13, B23 = -2 * mu * P.m1 * P.m2 * r1 * r2^2 / I^2, 2 * mu * P.m1 * P.m2 * r1^2 * r2 / I^2
  T.ok(math.abs(ev.B[1][3] / B13 - 1) <= 1e-14 and math.abs(ev.B[2][3] / B23 - 1) <= 1e-14
       and math.abs(ev.B[1][2]) <= 1e-15 and ev.B[3][1] == -ev.B[1][3],
       ("B_r1phi = %.16g, B_r2phi = %.16g"):format(ev.B[1][3], ev.B[2][3]))
  T.near(ev.amended, Vmu, 1e-14, "V_mu = -g[m1 sqrt(l1^2 - r1^2) + m2 (...)] + mu^2/(2 I)")
end

-- a symmetry the formula hides: the same pendulum written through the
-- Cartesian velocities of both bobs (sin(theta), cos(theta) appear; dL/dtheta
-- cancels only through trigonometric identities).  Cyclicity is decided by
-- evaluation and the equivalent L with theta = 0 is reduced.
do
  local cart = dm.system{name = "double spherical pendulum (Cartesian velocities)",
    coords = {"theta", "r1", "r2", "phi"},
    params = {{"g", P.g}, {"l1", P.l1}, {"l2", P.l2}, {"m1", P.m1}, {"m2", P.m2}},
    L = function(q, v, p)
      local th1, th2, w1, w2 = q.theta, q.theta + q.phi, v.theta, v.theta + v.phi
      local s1, s2 = dm.sqrt(p.l1^2 - q.r1^2), dm.sqrt(p.l2^2 - q.r2^2)
      local x1d = v.r1 * dm.cos(th1) - q.r1 * dm.sin(th1) * w1
      local y1d = v.r1 * dm.sin(th1) + q.r1 * dm.cos(th1) * w1
      local x2d = v.r2 * dm.cos(th2) - q.r2 * dm.sin(th2) * w2
      local y2d = v.r2 * dm.sin(th2) + q.r2 * dm.cos(th2) * w2
      local z1d, z2d = q.r1 * v.r1 / s1, q.r2 * v.r2 / s2
      return 0.5 * p.m1 * (x1d^2 + y1d^2 + z1d^2)
        + 0.5 * p.m2 * ((x1d + x2d)^2 + (y1d + y2d)^2 + (z1d + z2d)^2)
        + p.m1 * p.g * s1 + p.m2 * p.g * (s1 + s2)
    end}
  T.ok(tostring(cart.dLdq[1]):find("sin(theta)", 1, true), "dL/dtheta of the Cartesian form is not 0 as a formula")
  local ok, rc = pcall(dm.routh, cart, {cyclic = {"theta"}, mu = mu})
  T.ok(ok, "dm.routh reduces it (cyclicity decided by evaluation): " .. tostring(rc))
  if ok then
    local x, xd = {0.7385, 0.4127, 2.385}, {0.1, -0.2, 0.3}
    local a, b = rc:eval{q = x, v = xd}, rd:eval{q = x, v = xd}
    local worst = 0
    for _, k in ipairs{"I", "amended", "routhian", "classical"} do worst = math.max(worst, math.abs(a[k] - b[k]) / math.abs(b[k])) end
    for i = 1, 3 do
      worst = math.max(worst, math.abs(a.A[i] - b.A[i]) / math.abs(b.A[i]))
      for j = 1, 3 do worst = math.max(worst, math.abs(a.B[i][j] - b.B[i][j]) / (1 + math.abs(b.B[i][j]))) end
    end
    T.ok(worst <= 1e-13, ("I, A, beta, V_mu, Routhians equal those of the shape-form Lagrangian (rel. %.2g)"):format(worst))
    local s0 = {q = {0.6, 0.5, 0.3}, v = {0.1, -0.1, 0.2}}
    local ta = dm.integrator(rc, {method = "gauss", h = 0.01}):run(s0, {steps = 100})
    local tb = dm.integrator(rd, {method = "gauss", h = 0.01}):run(s0, {steps = 100})
    local dx = math.abs(ta:column("phi")[101] - tb:column("phi")[101])
    T.ok(dx <= 1e-12, ("RSPRK on both reductions agrees over 100 steps (%.2g)"):format(dx))
  end
  local hidden = dm.system{name = "undecidable", coords = {"a", "b"},
    L = function(q, v) return 0.5 * (v.a^2 + v.b^2) + dm.log(q.b - 5) * dm.sin(q.a)^2 end}
  T.error_like(function() dm.routh(hidden, {cyclic = {"a"}}) end,
    "cannot decide whether L depends on 'a': dL/da is not finite at the sample points",
    "a derivative that cannot be evaluated is an error, not a guess")
  local weak = dm.system{name = "weakly asymmetric", coords = {"a", "b"},
    L = function(q, v) return 0.5 * (v.a^2 + v.b^2) - q.b^2 + 1e-9 * dm.sin(q.a) * q.b end}
  T.error_like(function() dm.routh(weak, {cyclic = {"a"}}) end, "'a' is not a cyclic coordinate: L depends on it",
    "a small but real dependence (1e-9 sin(a) b) is still refused: the test is relative to the terms")
end

-- reduced integrators through dm.integrator ---------------------------------
local q0, v0 = {0.3, 0.6, 0.5, 0.3}, {3.3, 0.1, -0.1, 0.2}       -- theta, r1, r2, phi
local st, mu0, th0 = rd:project{q = q0, v = v0}
T.near(mu0, dsp:momentum({q = q0, v = v0}, "theta"), 1e-15, "project: mu = p_theta")
T.is(th0, 0.3, "project: theta")
rd:set{mu = mu0}
T.is(rd.mu, mu0, "red:set{mu = ...}")
T.is(rd.params.mu_theta, mu0, "red.params holds mu_theta")
do   -- one parameter protocol: params and set, mu included, all checked first
  local r3 = dm.routh(dm.systems.j2_cylindrical{J2 = 0.05}, {cyclic = {"theta"}, mu = 1.1})
  local s0 = {q = {1.8, 0.2}, p = {0.0, 0.3}}
  local I3 = dm.integrator(r3, {method = "gauss", h = 0.05})
  local a = I3:run(s0, {steps = 20})
  r3.params.mu_theta = 1.2
  local b = I3:run(s0, {steps = 20})
  r3:set{mu = 1.1, J2 = 0.001}
  local c = I3:run(s0, {steps = 20})
  r3:set{J2 = 0.05}
  local d = I3:run(s0, {steps = 20})
  T.ok(r3.mu == 1.1 and r3.params.J2 == 0.05 and d:column("r")[21] == a:column("r")[21]
       and b:column("r")[21] ~= a:column("r")[21] and c:column("r")[21] ~= a:column("r")[21],
       "red.params.mu_theta = x and red:set{mu =, J2 =} reach an existing integrator; setting back restores the run bit for bit")
  T.error_like(function() r3:set{mu = 1.3, J3 = 1} end, "no parameter 'J3' in system", "set: unknown name")
  T.ok(r3.mu == 1.1, "set changes nothing when an entry is wrong")
  T.error_like(function() r3:set{mu = {1, 2}} end, "vector of length 1 expected", "set: mu of the wrong size")
  T.error_like(function() r3:set{J2 = "x"} end, "set: parameter 'J2' needs a finite number, got string", "set: a non-number")
  T.error_like(function() r3:set{[1] = 2} end, "set: parameter names are strings, got number", "set: a non-string key")
  T.error_like(function() return r3.set_mu end, "no field or method 'set_mu'", "one protocol: set_mu is gone")
end
T.is(rd.system.params.mu_theta, mu0, "mu is the parameter mu_theta of the reduced system")
local R = dm.integrator(rd, {method = "gauss", stages = 2, h = 0.01})
local C = dm.integrator(rd, {method = "classical", stages = 2, h = 0.01})
local D = dm.integrator(rd, {method = "dr:gauss", stages = 2, h = 0.01})
T.ok(R.method == "gauss" and R.family == "rsprk", "dm.integrator(red, {method = 'gauss'}) is RSPRK")
T.ok(C.family == "classical" and D.family == "dr" and D.method == "dr:gauss", "classical and dr:gauss are their families")
local tr = R:run(st, {steps = 200, every = 10})
local tc = C:run(st, {steps = 200, every = 10})
local td = D:run(st, {steps = 200, every = 10})
local function maxdiff(a, b, cols)
  local m = 0
  for _, c in ipairs(cols) do
    local x, y = a:column(c), b:column(c)
    for k = 1, #x do m = math.max(m, math.abs(x[k] - y[k])) end
  end
  return m
end
local cols = {"r1", "r2", "phi", "p_r1", "p_r2", "p_phi"}
T.ok(maxdiff(tr, tc, cols) <= 1e-12, ("RSPRK = classical Routhian SPRK under the momentum shift (%.2g)"):format(maxdiff(tr, tc, cols)))
T.ok(maxdiff(tr, td, cols) <= 1e-12, ("RSPRK = discrete Routh equations, Galerkin-Gauss 2 (%.2g)"):format(maxdiff(tr, td, cols)))
local E = tr:energy()
local dE = 0
for k = 1, #E do dE = math.max(dE, math.abs(E[k] - E[1])) end
T.ok(dE < 1e-8 * math.abs(E[1]), ("reduced energy column conserved (%.2g)"):format(dE))
local M = red:integrator{method = "midpoint", h = 0.1}
T.ok(M.method == "midpoint" and M.family == "rsprk", "red:integrator{...}")
-- the reduced system alone: its kind selects the same reduced families
local R2 = dm.integrator(rd.system, {method = "gauss", stages = 2, h = 0.01})
T.ok(R2.family == "rsprk" and maxdiff(R2:run(st, {steps = 200, every = 10}), tr, cols) == 0,
     "dm.integrator(red.system, {method = 'gauss'}) is the same RSPRK run, bit for bit")
local ms, mr = dm.methods(), dm.methods(rd)
T.ok(ms.gauss and ms.rk4 and not ms.routh and not ms.rsprk and not ms.dr and not ms.classical,
     "dm.methods() lists the Lagrangian methods only (no routh, rsprk, dr, classical)")
T.ok(mr.gauss and mr.gauss:find("RSPRK") and mr.dr and mr.classical and mr.rsprk and not mr.composition
     and mr.rk4 and mr.rk4:find("continuous Routh equations", 1, true)
     and dm.methods("routh").dr == mr.dr and dm.methods(rd.system).classical == mr.classical,
     "dm.methods(red | red.system | \"routh\") lists the reduced families")

-- reconstruction = the unreduced run ------------------------------------------
local full = rd:reconstruct(tr, {theta = 0.3})
local U = dm.integrator(dsp, {method = "gauss", stages = 2, h = 0.01})
local tu = U:run({q = q0, v = v0}, {steps = 200, every = 10})
local fcols = {"theta", "r1", "r2", "phi", "p_theta", "p_r1", "v_theta"}
T.ok(#full == #tu and maxdiff(full, tu, fcols) <= 1e-12,
     ("reconstructed full trajectory = unreduced Gauss 2 (max diff %.2g)"):format(maxdiff(full, tu, fcols)))
T.ok(tostring(full):find("double spherical pendulum", 1, true), "the reconstruction is labelled with the full system")
for _, pair in ipairs{{tc, "classical"}, {td, "dr:gauss"}} do
  local f = rd:reconstruct(pair[1], {theta = 0.3})
  T.ok(maxdiff(f, tu, fcols) <= 1e-12, ("reconstruction from the %s run (psi_mu, Lagrangian side) = unreduced (%.2g)")
       :format(pair[2], maxdiff(f, tu, fcols)))
end
do
  local s5 = tr[5]
  local lifted = rd:lift({q = s5.q, p = s5.p}, 0)
  local back = rd:project(lifted)
  T.ok(math.abs(back.p[3] - s5.p[3]) < 1e-13 and lifted.p[1] == mu0, "lift then project is the identity")
end

-- project takes the state's mu: a spherical-pendulum session made at another
-- mu reconstructs the unreduced motion (before, red kept mu = 0.3 and the
-- reconstructed phi was off by radians)
do
  local sp = dm.systems.spherical_pendulum{g = 9.81, l = 1.3, m = 0.7}
  local rsp = dm.routh(sp, {cyclic = {"phi"}, mu = 0.3})
  local q0s, v0s = {0.9, 2.385}, {0.2, 1.7}
  local mus = sp:momentum({q = q0s, v = v0s}, "phi")
  local rst, mu1, ph0 = rsp:project{q = q0s, v = v0s}
  T.ok(math.abs(mu1 - mus) <= 1e-15 * mus and rsp.mu == mu1 and rsp.system.params.mu_phi == mu1,
       ("project sets the reduction's mu to the state's (%.17g; was 0.3)"):format(rsp.mu))
  local h, N = 0.01, 400
  local rt = dm.integrator(rsp, {method = "gauss", stages = 2, h = h}):run(rst, {steps = N, every = 100})
  local fr = rsp:reconstruct(rt, {theta = ph0})
  local ut = dm.integrator(sp, {method = "gauss", stages = 2, h = h}):run({q = q0s, v = v0s}, {steps = N, every = 100})
  local dphi = math.abs(fr:column("phi")[#fr] - ut:column("phi")[#ut])
  T.ok(dphi <= 1e-11, ("reduced run from the projected state reconstructs the unreduced phi (diff %.2g)"):format(dphi))
end

-- the run records its method, stages and h: reconstruct uses them (a Gauss
-- s = 3 run was rebuilt with s = 2: theta off by 5e-5 at h = 0.02)
do
  local st3 = rd:project{q = q0, v = v0}
  local t3 = dm.integrator(rd, {method = "gauss", stages = 3, h = 0.02}):run(st3, {steps = 200, every = 20})
  T.ok(t3:meta("stages") == 3 and math.type(t3:meta("stages")) == "integer" and t3:meta("h") == 0.02,
       "reduced run metadata: stages and h as numbers")
  local f3 = rd:reconstruct(t3, {theta = 0.3})
  local u3 = dm.integrator(dsp, {method = "gauss", stages = 3, h = 0.02}):run({q = q0, v = v0}, {steps = 200, every = 20})
  local d3 = maxdiff(f3, u3, {"theta", "r1", "phi"})
  T.ok(d3 <= 1e-12, ("reconstruct of a Gauss s = 3 run with the run's stages = unreduced Gauss 3 (%.2g)"):format(d3))
  -- a user tableau: reduced prk and classical:prk
  local g3 = dm.tableau("gauss", 3)
  local tp = dm.integrator(rd, {method = "prk", tableau = g3, h = 0.02}):run(st3, {steps = 200, every = 20})
  local tc3 = dm.integrator(rd, {method = "classical:prk", tableau = g3, h = 0.02}):run(st3, {steps = 200, every = 20})
  T.ok(maxdiff(tp, t3, cols) <= 1e-12 and maxdiff(tc3, t3, cols) <= 1e-12,
       ("RSPRK and classical SPRK with the Gauss 3 tableau given by hand = RSPRK gauss s = 3 (%.2g, %.2g)")
       :format(maxdiff(tp, t3, cols), maxdiff(tc3, t3, cols)))
  local fp = rd:reconstruct(tp, {theta = 0.3, tableau = g3})
  T.ok(maxdiff(fp, u3, {"theta", "r1"}) <= 1e-12, "reconstruct of a prk run with its tableau")
  local o4 = dm.integrator(rd, {method = "prk", tableau = dm.tableau("gauss", 2)}):order_estimate{state = st3, t = 1,
    h = {0.04, 0.02, 0.01}}
  local o2 = dm.integrator(rd, {method = "dr"}):order_estimate{state = st3, t = 1, h = {0.04, 0.02, 0.01}}
  T.ok(math.abs(o4 - 4) <= 0.1 and math.abs(o2 - 2) <= 0.1,
       ("integ:order_estimate on reduced integrators (reference: RSPRK Gauss 6): prk with the Gauss 2 tableau %.3f, dr %.3f"):format(o4, o2))
  T.error_like(function() dm.integrator(rd, {method = "prk", h = 0.02}) end, "dm.integrator: method 'prk' needs a tableau",
    "reduced prk without a tableau")
  T.error_like(function() dm.integrator(rd, {method = "gauss", tableau = g3, h = 0.02}) end,
    "option 'tableau' is for method 'prk' %(got method 'gauss'%)", "a tableau with another method is an error, not ignored")
end

-- the continuous Routh equations as references: rk4 and gsl:<stepper> on the
-- reduced system (theta integrated along) --------------------------------------
do
  local st4, mu4, th4 = rd:project{q = q0, v = v0}
  local T4 = 2
  local ref = dm.integrator(dsp, {method = "gauss", stages = 6, h = 0.0025}):run({q = q0, v = v0}, {t = T4})
  local rr, rth = ref:column("r1")[#ref], ref:column("theta")[#ref]
  local hs, er, et = {0.02, 0.01, 0.005}, {}, {}
  for k, h in ipairs(hs) do
    local tr4 = dm.integrator(rd, {method = "rk4", h = h}):run(st4, {t = T4})
    local f4 = rd:reconstruct(tr4, {theta = th4})
    er[k] = math.abs(tr4:column("r1")[#tr4] - rr)
    et[k] = math.abs(f4:column("theta")[#f4] - rth)
  end
  local pr, pt = math.log(er[1] / er[3], 4), math.log(et[1] / et[3], 4)
  T.ok(math.abs(pr - 4) <= 0.15 and math.abs(pt - 4) <= 0.15,
       ("rk4 on the reduced system: order %.2f in r1, %.2f in the reconstructed theta"):format(pr, pt))
  local t8 = dm.integrator(rd, {method = "gsl:rk8pd", h = 0.02}):run(st4, {t = T4})
  local f8 = rd:reconstruct(t8, {theta = th4})
  local d8 = math.max(math.abs(t8:column("r1")[#t8] - rr), math.abs(f8:column("theta")[#f8] - rth))
  T.ok(d8 <= 1e-12, ("gsl:rk8pd on the Routh equations = unreduced Gauss 6 (%.2g)"):format(d8))
  T.ok(not dm.integrator(rd, {method = "rk4", h = 0.01}).symplectic, "rk4 on the reduced system is not symplectic")
  T.error_like(function() dm.integrator(rd, {method = "gsl:bsimp", h = 0.01}) end,
    "gsl:bsimp on a reduced system: implicit and multistep steppers need the Jacobian", "implicit GSL steppers refused with the reason")
  T.error_like(function() dm.integrator(rd, {method = "gsl:nosuch", h = 0.01}) end,
    "unknown GSL stepper 'nosuch' for a reduced system", "unknown stepper")
end

-- structure --------------------------------------------------------------------
T.ok(rd:defect(st, {method = "gauss", stages = 3, h = 0.05}) <= 1e-10, "non-canonical symplecticity defect of RSPRK Gauss 3")
T.ok(rd:defect(st, {method = "classical", stages = 2, h = 0.05}) <= 1e-10, "... and of the classical SPRK pulled back")
do
  local d = rd:defect(st, {method = "dr:gauss", stages = 2, h = 0.05})
  T.ok(d <= 1e-13, ("... and of the discrete Routh step, with its exact Jacobian (%.2g)"):format(d))
end
do
  local x0, x1 = {0.6, 0.5, 0.3}, {0.6031, 0.4962, 0.3118}
  local psi_m, D1m, D2m = rd:discrete{h = 0.05}:psi(x0, x1)
  local psi_g, D1g, D2g = rd:discrete{method = "gauss", stages = 1, h = 0.05}:psi(x0, x1)
  T.near(psi_m, psi_g, 1e-15, "psi_mu: midpoint closed form = Galerkin-Gauss 1")
  local dd = 0
  for i = 1, 3 do dd = math.max(dd, math.abs(D1m[i] - D1g[i]), math.abs(D2m[i] - D2g[i])) end
  T.ok(dd <= 1e-13, ("D1psi, D2psi: closed form = Galerkin-Gauss 1 (%.2g)"):format(dd))
  local dyn, geo, gap = rd:phase(tr)
  T.ok(dyn > 0 and math.abs(geo) > 0 and gap > 0, ("phase split: dynamic %.6f, geometric %.6f"):format(dyn, geo))
end

-- the discrete Routh equations in two-point form (red:discrete) -----------------
do
  local h = 0.02
  local D = rd:discrete{method = "gauss", stages = 2, h = h}
  T.ok(tostring(D):find("gauss s=2 h=0.02", 1, true), "tostring: " .. tostring(D))
  local F = dm.integrator(dsp, {method = "gauss", stages = 2, h = h})
  local function shape(q) return {q[2], q[3], q[4]} end
  local s1 = F:step({q = q0, v = v0})            -- (q0, q1) on J_d = mu
  local qa, qb = dm.vec(q0), s1.q
  local xa, xb = shape(qa), shape(qb)
  -- Lhat and the Legendre transforms against the full discrete Lagrangian
  local psi = D:psi(xa, xb)
  local p0, p1, Ld = F:dlegendre({0, xa[1], xa[2], xa[3]}, {psi, xb[1], xb[2], xb[3]})
  local Lh, forms = D:lhat(xa, xb)
  T.near(Lh, Ld, 1e-14, ("Lhat(x0, x1) = L_d((0, x0), (psi_mu, x1)) = %.10g"):format(Lh))
  T.near(p1[1], rd.mu, 1e-13, "J_d((0, x0), (psi_mu, x1)) = mu")
  local sm, sp = D:dlegendre(xa, xb)
  local proj = rd:project{q = qb, p = s1.p}
  local dl = 0
  for i = 1, 3 do dl = math.max(dl, math.abs(sp[i] - proj.p[i])) end
  T.ok(dl <= 1e-12, ("F+ Lhat(x0, x1) = projected momentum p_x - mu^T A at q1 (%.2g)"):format(dl))
  T.ok(#forms.D1 == 3 and #forms.A2 == 3, "lhat returns D1, D2, A1, A2")
  -- Theorem: the DEL trajectory projected solves the DR equations, and the
  -- DR recursion from the same (x0, x1) reproduces it
  local ya, yb = xa, xb
  local worst, rmax = 0, 0
  for k = 1, 100 do
    local qc = F:del_step(qa, qb)
    local yc = D:solve(ya, yb)
    local xc = shape(qc)
    for i = 1, 3 do worst = math.max(worst, math.abs(yc[i] - xc[i])) end
    local rdr, rdel = D:residual(shape(qa), shape(qb), xc)
    for i = 1, 3 do rmax = math.max(rmax, math.abs(rdr[i]), math.abs(rdel[i])) end
    qa, qb, ya, yb = qb, qc, yb, yc
  end
  T.ok(worst <= 1e-11, ("DR recursion = projected DEL trajectory over 100 steps (%.2g)"):format(worst))
  T.ok(rmax <= 1e-11, ("DR residual and shape part of DEL vanish along DEL (%.2g)"):format(rmax))
  -- reconstruction of tangent vectors: ((dth0, dx0), (dth1, dx1)) is tangent
  -- to J_d = mu (its derivative along the variation vanishes), dth1 = dth0 is not
  local dx0, dx1, dth0 = {0.31, -0.17, 0.42}, {-0.23, 0.29, 0.11}, 0.37
  local dth1 = D:dtheta(xa, xb, dth0, dx0, dx1)
  local th1 = D:psi(xa, xb)
  local function Jd(eps, d1)
    local a = {eps * dth0, xa[1] + eps * dx0[1], xa[2] + eps * dx0[2], xa[3] + eps * dx0[3]}
    local b = {th1 + eps * d1, xb[1] + eps * dx1[1], xb[2] + eps * dx1[2], xb[3] + eps * dx1[3]}
    return F:discrete_momentum(a, b, "theta")
  end
  local eps = 1e-6
  local dJ = (Jd(eps, dth1) - Jd(-eps, dth1)) / (2 * eps)
  local dJ0 = (Jd(eps, dth0) - Jd(-eps, dth0)) / (2 * eps)
  T.ok(math.abs(dJ) <= 1e-7 and math.abs(dJ0) > 1e-2,
       ("dtheta1 = dtheta0 + D1psi dx0 + D2psi dx1 keeps J_d = mu to first order (dJ_d %.2g; with dtheta1 = dtheta0: %.2g)"):format(dJ, dJ0))
  T.error_like(function() rd:discrete{method = "prk", h = 0.1} end, "method must be \"midpoint\", \"gauss\" or \"lobatto\"", "discrete: bad method")
  T.error_like(function() rd:discrete{method = "gauss"} end, "option 'h' %(a finite non%-zero step%) is required", "discrete: h required")
  T.error_like(function() rd:discrete{h = 0.1, tol = 1} end, "unknown option tol", "discrete: unknown option")
end

-- parameters: a change through the reduced system reaches every method -----------
do
  local sat2 = dm.systems.j2_cylindrical{J2 = 0.05}
  local r2 = dm.routh(sat2, {cyclic = {"theta"}, mu = 1.1})
  local s0 = {q = {1.8, 0.2}, p = {0.0, 0.3}}
  local a = dm.integrator(r2, {method = "gauss", h = 0.05}):run(s0, {steps = 50})
  r2.system.params.J2 = 0.001
  local b = dm.integrator(r2, {method = "gauss", h = 0.05}):run(s0, {steps = 50})
  local c = dm.integrator(r2, {method = "dr", h = 0.05}):run(s0, {steps = 50})
  local d = dm.integrator(r2, {method = "midpoint", h = 0.05}):run(s0, {steps = 50})
  T.ok(math.abs(a:column("z")[51] - b:column("z")[51]) > 1e-4 and math.abs(c:column("z")[51] - d:column("z")[51]) < 1e-12,
       "J2 changed through red.system.params: RSPRK sees it, dr (full system) = RSPRK midpoint")
end

-- singular locked inertia during a run ---------------------------------------------
do
  local free = dm.system{name = "free particle (polar)", coords = {"r", "th"},
    L = function(q, v) return 0.5 * (v.r^2 + q.r^2 * v.th^2) end}
  local rf = dm.routh(free, {cyclic = {"th"}, mu = 0})
  local traj, msg = dm.integrator(rf, {method = "midpoint", h = 0.1}):run({q = {0.3}, p = {-1}}, {steps = 10})
  T.ok(msg and msg:find("locked inertia") and #traj == 3 and math.abs(traj:column("r")[3] - 0.1) < 1e-15,
       "a run reaching I(x) -> 0 stops with the partial trajectory and says why: " .. tostring(msg))
end

-- errors ------------------------------------------------------------------------
T.error_like(function() dm.routh(sat, {cyclic = {"z"}}) end, "'z' is not a cyclic coordinate: L depends on it, dL/dz = ",
  "a coordinate L depends on is refused, showing dL/dz")
T.error_like(function() dm.routh(dm.systems.double_spherical_pendulum{}, {cyclic = {"theta1"}}) end,
  "dL/dtheta1 = .*sin", "theta1 alone is not cyclic in the two-angle chart")
T.error_like(function() dm.routh(sat, {cyclic = {"phi"}}) end, "no coordinate 'phi'", "unknown coordinate")
T.error_like(function() dm.routh(sat, {cyclic = "theta", mu = {1, 2}}) end, "length", "mu of the wrong size")
T.error_like(function() dm.routh(sat, {cyclic = {"theta"}, tol = 1}) end, "unknown option", "unknown option")
T.error_like(function() dm.routh(sat, {}) end, "cyclic", "cyclic coordinates required")
T.error_like(function() dm.routh(dm.systems.kepler{impl = "c"}, {cyclic = {"x"}}) end, "Lagrangian", "built-in C systems have no expressions")
do
  local line = debug.getinfo(1, "l").currentline + 1
  local ok, msg = pcall(function() return dm.integrator(red, {method = "composition"}) end)
  T.ok(not ok and msg:find("^[^:]*reduce_routh%.lua:" .. line .. ": dm%.integrator: method 'composition' does not apply to system '[^']*' %(a routh system%); it integrates lagrangian systems %(methods here: rsprk, gauss, midpoint, lobatto, trapezoid, prk, dr, classical, gsl:<stepper>, rk4%)$"),
       "non-reduced methods are refused on a reduction, at the user's line: " .. tostring(msg))
  ok, msg = pcall(function() return dm.integrator(red.system, {method = "composition"}) end)
  T.ok(not ok and msg:find("^[^:]*reduce_routh%.lua:" .. (line + 3) .. ": dm%.integrator: method 'composition' does not apply"),
       "and on its reduced system: " .. tostring(msg))
  ok, msg = pcall(function() return dm.integrator(sat, {method = "dr"}) end)
  T.ok(not ok and msg:find("dm.integrator: method 'dr' does not apply to system '[^']*' %(a lagrangian system%); it integrates routh systems"),
       "a reduced method on an unreduced system says what it integrates: " .. tostring(msg))
end
T.error_like(function() return red.nonsense end, "no field or method 'nonsense'", "unknown field")
T.ok(dm.docs()["dm.routh"] and dm.docs()["routh:reconstruct"] and dm.docs()["routh.beta"], "documented")

T.done()
