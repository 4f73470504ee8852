-- reduce_general.lua -- Routh reduction of a Lagrangian that is not quadratic
-- in the velocities: a relativistic particle in a central potential,
--   L = -sqrt(1 - rdot^2 - r^2 thetadot^2) + k/r,  theta cyclic.
-- By hand: J = r^2 thetadot / sqrt(1 - rdot^2 - r^2 thetadot^2) = mu gives
--   thetadot = mu sqrt(1 - rdot^2) / (r sqrt(r^2 + mu^2)),
-- and then 1 - rdot^2 - r^2 thetadot^2 = (1 - rdot^2) r^2 / (r^2 + mu^2), so
--   Rc = L - mu thetadot = -sqrt(1 - rdot^2) sqrt(1 + mu^2/r^2) + k/r.
-- The numerical reduction (J = mu solved by Newton) must reproduce these
-- values, its runs must equal the unreduced runs and the runs of the
-- hand-derived Routhian, and the reconstruction the unreduced theta.
local T = require "dmech.test"
local dm = require "dmech"

local k, mu = 0.3, 0.9
local sys = dm.system{name = "relativistic particle", coords = {"r", "theta"}, params = {k = k},
  L = function(q, v, p) return -dm.sqrt(1 - v.r^2 - q.r^2 * v.theta^2) + p.k / q.r end}
local red = dm.routh(sys, {cyclic = {"theta"}, mu = mu})
T.ok(tostring(red):find("numerical (L is not quadratic in the velocities)", 1, true), "tostring: " .. tostring(red))

local function Rc_hand(r, rd, m) return -math.sqrt(1 - rd^2) * math.sqrt(1 + m^2 / r^2) + k / r end
local function thd_hand(r, rd, m) return m * math.sqrt(1 - rd^2) / (r * math.sqrt(r^2 + m^2)) end

do
  local worst = 0
  for _, pt in ipairs{{1.7, 0.2}, {0.6, -0.55}, {2.385, 0.0}, {0.35, 0.8}} do
    local ev = red:eval{q = {pt[1]}, v = {pt[2]}}
    worst = math.max(worst, math.abs(ev.classical - Rc_hand(pt[1], pt[2], mu)) / math.abs(Rc_hand(pt[1], pt[2], mu)),
                     math.abs(ev.thetadot - thd_hand(pt[1], pt[2], mu)) / thd_hand(pt[1], pt[2], mu))
  end
  T.ok(worst <= 1e-14, ("classical Routhian and thetadot = the hand-derived formulas at 4 points (rel. %.2g)"):format(worst))
end

-- the hand-derived Routhian as a system of its own (mu a parameter)
local hand = dm.system{name = "hand Routhian", coords = {"r"}, params = {k = k, mu = mu},
  L = function(q, v, p) return -dm.sqrt(1 - v.r^2) * dm.sqrt(1 + p.mu^2 / q.r^2) + p.k / q.r end}
do   -- momentum and Hessian through the reduced system's conversions
  local x, xd = {1.3}, {0.45}
  local pr = red.system:momentum{q = x, v = xd}[1]
  local ph = hand:momentum{q = x, v = xd}[1]
  T.ok(math.abs(pr - ph) <= 1e-14 * math.abs(ph), ("dRc/drdot = hand (%.17g vs %.17g)"):format(pr, ph))
  local Eh, Er = hand:energy{q = x, v = xd}, red.system:energy{q = x, v = xd}
  T.ok(math.abs(Er - Eh) <= 1e-14 * math.abs(Eh), ("reduced energy = hand (%.17g vs %.17g)"):format(Er, Eh))
end

local q0, v0 = {1.4, 0.3}, {0.05, 0.3}
local st, mu0, th0 = red:project{q = q0, v = v0}
T.ok(math.abs(mu0 - sys:momentum({q = q0, v = v0}, "theta")) == 0 and red.mu == mu0, "project: mu = p_theta, set on the reduction")
hand.params.mu = mu0
local h, N = 0.02, 1500
for _, m in ipairs{{"gauss", 2}, {"lobatto", 3}, {"midpoint"}} do
  local opts = {method = m[1], stages = m[2], h = h}
  local rt = dm.integrator(red, opts):run(st, {steps = N, every = 100})
  local ht = dm.integrator(hand, opts):run({q = st.q, p = st.p}, {steps = N, every = 100})
  local ut = dm.integrator(sys, opts):run({q = q0, v = v0}, {steps = N, every = 100})
  local dh, du = 0, 0
  for i = 1, #rt do
    dh = math.max(dh, math.abs(rt:column("r")[i] - ht:column("r")[i]), math.abs(rt:column("p_r")[i] - ht:column("p_r")[i]))
    du = math.max(du, math.abs(rt:column("r")[i] - ut:column("r")[i]), math.abs(rt:column("p_r")[i] - ut:column("p_r")[i]))
  end
  T.ok(dh <= 1e-11, ("%s: reduced run = run of the hand-derived Routhian (%.2g)"):format(m[1], dh))
  T.ok(du <= 1e-11, ("%s: reduced run = unreduced run projected (%.2g)"):format(m[1], du))
  local full = red:reconstruct(rt, {theta = th0})
  local dth = 0
  for i = 1, #full do dth = math.max(dth, math.abs(full:column("theta")[i] - ut:column("theta")[i])) end
  T.ok(dth <= 1e-11, ("%s: reconstructed theta = unreduced theta (%.2g)"):format(m[1], dth))
end

do   -- discrete Routh equations with the Galerkin L_d of the full system
  local rt = dm.integrator(red, {method = "dr:gauss", stages = 2, h = h}):run(st, {steps = 100})
  local gt = dm.integrator(red, {method = "gauss", stages = 2, h = h}):run(st, {steps = 100})
  local d = math.abs(rt:column("r")[101] - gt:column("r")[101])
  T.ok(d <= 1e-12, ("dr:gauss = classical Gauss 2 (%.2g)"):format(d))
  local def = red:defect(st, {method = "gauss", stages = 2, h = 0.05})
  T.ok(def <= 1e-13, ("symplecticity defect of the reduced step in (r, p_r) (%.2g)"):format(def))
end

do   -- the Routh equations under rk4 = the unreduced rk4 run (p_theta stays mu)
  local rt = dm.integrator(red, {method = "rk4", h = h}):run(st, {steps = 300, every = 100})
  local ut = dm.integrator(sys, {method = "rk4", h = h}):run({q = q0, v = v0}, {steps = 300, every = 100})
  local full = red:reconstruct(rt, {theta = th0})
  local d = 0
  for i = 1, #rt do
    d = math.max(d, math.abs(rt:column("r")[i] - ut:column("r")[i]), math.abs(rt:column("p_r")[i] - ut:column("p_r")[i]),
                 math.abs(full:column("theta")[i] - ut:column("theta")[i]))
  end
  T.ok(d <= 1e-11, ("rk4 on the numerical Routhian = unreduced rk4, theta included (%.2g)"):format(d))
end

-- what a non-mechanical reduction does not have
T.error_like(function() return red.A end, "red.A: 'relativistic particle' is not mechanical", "no connection")
T.error_like(function() return red.amended end, "no locked inertia, connection or amended potential", "no amended potential")
T.error_like(function() red:phase(dm.trajectory{t = {0, 1}, coords = {"r"}, q = {r = {1, 1}}}) end,
  "no mechanical connection", "no phase split")
T.error_like(function()
  dm.routh(dm.system{coords = {"r", "theta"}, L = function(q, v) return -dm.sqrt(1 - v.r^2 - q.r^2 * v.theta^2) end,
    force = function(q, v) return {-0.1 * v.r, 0} end}, {cyclic = {"theta"}})
end, "numerical and does not take a force", "forces need a mechanical L")
do   -- a shape velocity |rdot| > 1: L, hence J = mu, is undefined
  local ok, err = pcall(function() return red:eval{q = {1.0}, v = {1.5}} end)
  T.ok(not ok and tostring(err):find("has no solution thetadot", 1, true), "eval outside the domain: " .. tostring(err))
end
T.done()
