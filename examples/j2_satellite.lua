-- j2_satellite.lua -- thesis figures 2.2-2.5: a satellite about an oblate
-- Earth, unreduced 3-D orbit beside the reduced (r, z) curve, for J2 = 0 and
-- J2 = 0.05, with the exact flow and with the midpoint rule at h = 0.3.
--
--   src/dmech examples/j2_satellite.lua [output-directory]
--
-- The reduction is derived by dmech itself: dm.routh(sys, {cyclic = {"theta"}})
-- finds the locked inertia r^2, the connection A = 0, beta = 0 and the
-- Routhian R = (rdot^2 + zdot^2)/2 - V(r, z) - mu^2/(2 r^2) (doc/reduce.md
-- §13, with the corrected sign of the Kepler term and the centrifugal term).  The
-- reduced system is integrated on (r, z) (RSPRK), and the 3-D orbit is
-- reconstructed from it (theta advanced by the reduced integrator's group
-- increments).
--
-- Initial condition (the thesis prints none): periapsis of an inclined,
-- slightly eccentric orbit on the ascending node,
--   a = 1.7, e = 0.06, i = 25 deg:  r = a (1 - e) = 1.598, theta = 0, z = 0,
--   v = sqrt((1 + e)/r) (0, cos i, sin i) in (radial, azimuthal, vertical),
-- followed for 40 orbital periods (2 pi a^1.5 each).  "Exact" is RSPRK with
-- the 3-stage Gauss method at h = 0.02 (order 6); "discrete" is the midpoint
-- rule (1-stage Gauss) at h = 0.3, as in the thesis.
--
-- What the figures show: for J2 = 0 the exact reduced curve is one closed
-- curve (nearly an arc of r^2 + z^2 = const); at h = 0.3 it stays a thin
-- closed band while the unreduced orbit precesses -- in the unreduced picture
-- much like the J2 = 0.05 orbit, whose reduced curve fills a region instead.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local a, e, inc = 1.7, 0.06, math.rad(25)
local rp = a * (1 - e)
local vp = math.sqrt((1 + e) / rp)
local q0 = {rp, 0, 0}
local v0 = {0, vp * math.cos(inc) / rp, vp * math.sin(inc)}
local period = 2 * math.pi * a^1.5
local T = 40 * period

local sat = dm.systems.j2_cylindrical{J2 = 0}
local red = dm.routh(sat, {cyclic = {"theta"}})
print(red)
print("  locked inertia I =", red.I)
print("  connection A =", red.A, "  magnetic term beta =", red.beta)
print("  Routhian R =", red.routhian)

-- osculating elements of the full state (GM = 1): node, argument of periapsis
local function elements(r, th, z, rd, thd, zd)
  local c, s = math.cos(th), math.sin(th)
  local P = {r * c, r * s, z}
  local V = {rd * c - r * thd * s, rd * s + r * thd * c, zd}
  local H = {P[2] * V[3] - P[3] * V[2], P[3] * V[1] - P[1] * V[3], P[1] * V[2] - P[2] * V[1]}
  local R = math.sqrt(P[1]^2 + P[2]^2 + P[3]^2)
  local Ev = {V[2] * H[3] - V[3] * H[2] - P[1] / R, V[3] * H[1] - V[1] * H[3] - P[2] / R,
              V[1] * H[2] - V[2] * H[1] - P[3] / R}
  local N = {-H[2], H[1]}
  local hn = math.sqrt(H[1]^2 + H[2]^2 + H[3]^2)
  local nn = math.sqrt(N[1]^2 + N[2]^2)
  local cr = ((N[2] * Ev[3]) * H[1] + (-N[1] * Ev[3]) * H[2] + (N[1] * Ev[2] - N[2] * Ev[1]) * H[3]) / (nn * hn)
  local dt = (N[1] * Ev[1] + N[2] * Ev[2]) / nn
  return math.atan(N[2], N[1]), math.atan(cr, dt)
end

local function unwrap(prev, x)
  while x - prev > math.pi do x = x - 2 * math.pi end
  while x - prev < -math.pi do x = x + 2 * math.pi end
  return x
end

local function case(fig, J2, method, stages, h, every)
  red:set{J2 = J2}
  local st, mu = red:project{q = q0, v = v0}      -- the reduction takes the state's mu
  local I = dm.integrator(red, {method = method, stages = stages, h = h})
  local steps = math.floor(T / h + 0.5)
  local rt = I:run(st, {steps = steps, every = every})
  local full = red:reconstruct(rt, {theta = 0})
  full:derive({"x", "y", "zc"}, function(s)
    return s.r * math.cos(s.theta), s.r * math.sin(s.theta), s.z end)
  -- the numbers behind the figure
  local E = rt:energy()
  local dE = 0
  for k = 1, #E do dE = math.max(dE, math.abs(E[k] - E[1]) / math.abs(E[1])) end
  local r, th, z = full:column("r"), full:column("theta"), full:column("z")
  local vr, vth, vz = full:column("v_r"), full:column("v_theta"), full:column("v_z")
  local W0, w0 = elements(r[1], th[1], z[1], vr[1], vth[1], vz[1])
  local W, w = W0, w0
  for k = 2, #r do
    local Wk, wk = elements(r[k], th[k], z[k], vr[k], vth[k], vz[k])
    W, w = unwrap(W, Wk), unwrap(w, wk)
  end
  local pth = full:column("p_theta")
  local dJ = 0
  for k = 1, #pth do dJ = math.max(dJ, math.abs(pth[k] - mu)) end
  local rho_min, rho_max = math.huge, 0
  for k = 1, #r do
    local rho = math.sqrt(r[k]^2 + z[k]^2)
    rho_min, rho_max = math.min(rho_min, rho), math.max(rho_max, rho)
  end
  print(("Fig. %s  J2 = %-5g %-14s h = %-5g  %6d steps: rel. energy error %.2e, |J - mu| %.1e,"
         .. " node %+.4f rad, periapsis %+.4f rad over 40 orbits, |q| in [%.4f, %.4f]")
        :format(fig, J2, method .. (stages and (" s=" .. stages) or ""), h, steps, dE, dJ,
                W - W0, w - w0, rho_min, rho_max))
  local file = outdir .. "/j2_fig" .. fig:gsub("%.", "_") .. ".png"
  local label = ("J2 = %g, %s"):format(J2, h <= 0.05 and "exact flow" or ("midpoint h = " .. h))
  dm.plot{
    {{full, "x", "y", "zc", with = "lines", title = "orbit"},
     title = "unreduced (" .. label .. ")", xlabel = "x", ylabel = "y", zlabel = "z",
     aspect = "equal", view = {60, 30}, key = false,
     commands = {"set xtics 1", "set ytics 1", "set ztics 0.5"}},
    {{rt, "r", "z", with = "lines", title = "reduced"},
     title = "reduced (r, z) (" .. label .. ")", xlabel = "r", ylabel = "z", key = false,
     commands = {"set xtics autofreq", "set ytics autofreq"}},
    layout = "1,2", size = {1300, 560}, output = file}
  print("  wrote " .. file)
  return W - W0, w - w0
end

case("2.2", 0.0, "gauss", 3, 0.02, 5)
case("2.3", 0.05, "gauss", 3, 0.02, 5)
case("2.4", 0.0, "midpoint", nil, 0.3, 1)
case("2.5", 0.05, "midpoint", nil, 0.3, 1)

-- reduced = unreduced: the reconstructed orbit against the unreduced midpoint run
do
  red:set{J2 = 0.05}
  sat:set{J2 = 0.05}
  local st = red:project{q = q0, v = v0}
  local rt = dm.integrator(red, {method = "midpoint", h = 0.3}):run(st, {steps = 500})
  local full = red:reconstruct(rt, {theta = 0})
  local un = dm.integrator(sat, {method = "midpoint", h = 0.3}):run({q = q0, v = v0}, {steps = 500})
  local d = 0
  for _, c in ipairs{"r", "theta", "z", "p_r", "p_theta", "p_z"} do
    local x, y = full:column(c), un:column(c)
    for k = 1, #x do d = math.max(d, math.abs(x[k] - y[k])) end
  end
  print(("reduced + reconstruction vs unreduced midpoint, J2 = 0.05, 500 steps: max difference %.2e"):format(d))
end
