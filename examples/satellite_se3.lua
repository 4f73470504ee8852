-- satellite_se3.lua -- a rigid satellite in a central gravity field, on
-- SE(3) (doc/lie.md): orbit and attitude coupled through the gravity-gradient
-- potential, integrated with the Lie group variational integrator (lgvi).
--
--   src/dmech examples/satellite_se3.lua [output-directory]
--
-- The configuration is (R, p) in SE(3): attitude and position; the body
-- velocity (W, v) with p' = R v.  With G M = 1 and MacCullagh's second-order
-- potential of an extended body,
--   L = 1/2 W^T I W + 1/2 m |v|^2 + m/r + (tr I - 3 b^T I b)/(2 r^3),
--   r = |p|,  b = R^T p / r (the local vertical in the body frame),
-- whose derivative in R is the gravity-gradient torque 3/r^3 b x (I b) and
-- whose derivative in p adds a small non-central force: the attitude steers
-- the orbit and the orbit the attitude.  Only the total angular momentum
-- about the centre (the angular part of the spatial momentum, which dmech
-- records) and the energy are conserved; lgvi keeps the first to round-off.
--
-- The satellite is made absurdly large (I/(m r^2) ~ 1e-3; real ones are
-- ~1e-12) so that the coupling shows (much larger and the expansion breaks
-- down: the 1/r^3 term wins over the centrifugal barrier and the orbit
-- falls in): it starts on a circular orbit of radius 1, spinning with the
-- orbital rate, its long axis (body x, the smallest moment) pitched 0.5 rad
-- from the vertical; it librates about the vertical with the frequency
-- sqrt(3 (I2 - I1)/I3) = 1.34 times the orbital one.  Panels: the pitch
-- libration (the angle of the long axis from the local vertical in the
-- orbit plane); the orbital and the spin angular momentum, which trade what
-- the torque transfers while their sum stays constant; the orbit radius.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local SE3 = dm.lie.SE3()
local sat = dm.system{space = SE3, name = "satellite", params = {I1 = 0.001, I2 = 0.004, I3 = 0.005, m = 1},
  L = function(g, xi, p)
    local R, q = g.R, g.p
    local r2 = q[1]^2 + q[2]^2 + q[3]^2
    local r = dm.sqrt(r2)
    -- b = R^T q / r
    local b = {}
    for j = 1, 3 do b[j] = (R[1][j] * q[1] + R[2][j] * q[2] + R[3][j] * q[3]) / r end
    local bIb = p.I1 * b[1]^2 + p.I2 * b[2]^2 + p.I3 * b[3]^2
    local T = 0.5 * (p.I1 * xi[1]^2 + p.I2 * xi[2]^2 + p.I3 * xi[3]^2)
            + 0.5 * p.m * (xi[4]^2 + xi[5]^2 + xi[6]^2)
    return T + p.m / r + (p.I1 + p.I2 + p.I3 - 3 * bIb) / (2 * r^3)
  end}

local pitch0 = 0.5
local c, s = math.cos(pitch0), math.sin(pitch0)
local g0 = SE3.element{c, -s, 0, s, c, 0, 0, 0, 1, 1, 0, 0}   -- R = Rz(pitch0), p = (1, 0, 0)
-- body velocity: spin at the orbital rate 1 about z; v = R^T (0, 1, 0)
local I = dm.integrator(sat, {method = "lgvi", h = 0.005})
local T = 8 * 2 * math.pi
local tr = I:run({g = g0, xi = {0, 0, 1, s, c, 0}}, {t = T, every = 4})

-- derived columns: pitch, orbital and spin angular momentum (z), radius
local I1, I2, I3 = sat:param("I1"), sat:param("I2"), sat:param("I3")
tr:derive({"pitch", "Lorb", "Lspin", "r"}, function(x)
  local R = {{x.R11, x.R12, x.R13}, {x.R21, x.R22, x.R23}, {x.R31, x.R32, x.R33}}
  local px, py = x.p1, x.p2
  local r = math.sqrt(px^2 + py^2 + x.p3^2)
  -- velocity in space R v, orbital angular momentum m p x R v (z)
  local vx = R[1][1] * x.xi4 + R[1][2] * x.xi5 + R[1][3] * x.xi6
  local vy = R[2][1] * x.xi4 + R[2][2] * x.xi5 + R[2][3] * x.xi6
  local Lorb = px * vy - py * vx
  -- spin angular momentum R I W (z)
  local Lspin = R[3][1] * I1 * x.xi1 + R[3][2] * I2 * x.xi2 + R[3][3] * I3 * x.xi3
  -- the long axis R e1 against the local vertical p / r, in the orbit plane
  local a = math.atan(R[2][1], R[1][1]) - math.atan(py, px)
  a = (a + math.pi) % (2 * math.pi) - math.pi
  return a, Lorb, Lspin, r
end)

local Lo, Ls, J3 = tr:column("Lorb"), tr:column("Lspin"), tr:momentum("3")
local dJ, dE, dLo = 0, 0, 0
local E = tr:energy()
for k = 1, #tr do
  dJ = math.max(dJ, math.abs(J3[k] - J3[1]))
  dE = math.max(dE, math.abs(E[k] - E[1]))
  dLo = math.max(dLo, math.abs(Lo[k] - Lo[1]))
end
print(("orbital angular momentum varies by %.3g, spin by the same: the total (recorded "
       .. "momentum_3) to %.2g; max |E - E0| %.2g"):format(dLo, dJ, dE))
tr:derive({"dLorb", "dLspin", "dLtot", "orbits"}, function(x)
  return x.Lorb - Lo[1], x.Lspin - Ls[1], x.momentum_3 - J3[1], x.t / (2 * math.pi) end)

local file = outdir .. "/satellite_se3.png"
dm.plot{
  {{tr, "orbits", "pitch", with = "lines lw 1.5 lc rgb '#1f77b4'", title = "pitch"},
   title = "pitch libration: long axis from the local vertical", xlabel = "t / 2 pi (orbits)",
   ylabel = "rad", key = false},
  {{tr, "orbits", "dLorb", with = "lines lw 1.5 lc rgb '#d62728'", title = "orbit: m p x p' (z)"},
   {tr, "orbits", "dLspin", with = "lines lw 1.5 lc rgb '#2ca02c'", title = "spin: R I W (z)"},
   {tr, "orbits", "dLtot", with = "lines lw 2 lc rgb 'black'", title = "total: the spatial momentum (z)"},
   title = "angular momentum traded between orbit and attitude (change from t = 0)",
   xlabel = "t / 2 pi (orbits)", ylabel = "change", commands = {"set key below"}},
  {{tr, "orbits", "r", with = "lines lw 1.5 lc rgb '#9467bd'", title = "r"},
   title = "orbit radius |p| (1 for a point mass)", xlabel = "t / 2 pi (orbits)", ylabel = "r",
   key = false},
  layout = "1,3", size = {1700, 520}, output = file}
print("  wrote " .. file)
