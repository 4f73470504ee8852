-- rigid_body_phase.lua -- Montgomery's rigid-body phase formula checked on
-- a Lie group variational integrator run.  A free rigid body's body
-- angular momentum Pi(t) is periodic with period T; after one period the
-- body has turned about its (fixed) spatial angular momentum by
--   dtheta = -Lambda + 2 H T/|mu|,
-- Lambda the solid angle enclosed by the curve Pi/|Pi| on the sphere (its
-- geometric phase, the Levi-Civita holonomy of the frame bundle SO(3) ->
-- S^2 along the curve) and 2 H T/|mu| the dynamic phase.  For the
-- symmetric top I = diag(1, 1, 2), |mu| = 1, Pi(0) = (sin b, 0, cos b):
-- T = 4 pi/cos b, Lambda = 2 pi (1 - cos b).  The run is the lgvi of the
-- Lie group integrators; Lambda is computed from the discrete momentum
-- curve with dm.discrete_connection{bundle = dm.sphere_frames(), rule =
-- "levi-civita"}.  doc/bundles-connections-holonomy.md §8.  Writes
-- rigid_body_phase.png.
--
--   src/dmech examples/rigid_body_phase.lua
local dm = require "dmech"
local pi = math.pi
local SO3 = dm.lie.SO3()
dm.config.native = "never"

local top = dm.system{space = SO3, params = {J1 = 1, J2 = 1, J3 = 2}, name = "symmetric top",
  L = function(R, Om, p) return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) end}
local S = dm.sphere_frames()
local LC = dm.discrete_connection{bundle = S, rule = "levi-civita"}

-- the twist of R about the unit axis a (the rotation angle about a of the
-- swing-twist decomposition), in [0, 2 pi)
local function twist(R, a)
  local m = R:matrix()
  local w = math.sqrt(math.max(0, 1 + m[1][1] + m[2][2] + m[3][3])) / 2
  local v = {(m[3][2] - m[2][3]) / (4 * w), (m[1][3] - m[3][1]) / (4 * w), (m[2][1] - m[1][2]) / (4 * w)}
  return (2 * math.atan(v[1] * a[1] + v[2] * a[2] + v[3] * a[3], w)) % (2 * pi)
end

-- one period of the top from Pi(0) = (sin b, 0, cos b), N steps
local function period(b, N)
  local Tp = 4 * pi / math.cos(b)
  local a = {math.sin(b), 0, math.cos(b)}
  local tr = dm.integrator(top, {method = "lgvi", h = Tp / N}):run({g = SO3.identity(), mu = a}, {steps = N})
  local H = 0.5 * (a[1]^2 + a[3]^2 / 2)
  -- Lambda: the holonomy of the (closed) momentum curve
  local pts = {}
  for k = 1, #tr do
    local p = dm.vec{tr:column("mu1")[k], tr:column("mu2")[k], tr:column("mu3")[k]}
    pts[#pts + 1] = p / p:norm()
  end
  pts[#pts + 1] = pts[1]
  local R0 = SO3.element(dm.mat{{a[3], 0, a[1]}, {0, 1, 0}, {-a[1], 0, a[3]}})   -- R0 e3 = Pi(0)
  -- the holonomy angle is the area mod 2 pi; caps smaller than a
  -- hemisphere (b < pi/2) enclose a solid angle in [0, 2 pi)
  local Lam = LC:holonomy(pts, S:point{R = R0}).angle % (2 * pi)
  local un = -Lam + 2 * H * Tp
  local me = twist(tr:group(#tr), a)
  return {tr = tr, T = Tp, H = H, Lam = Lam, measured = me, predicted = un % (2 * pi), a = a,
          unwrapped = un, measured_unwrapped = me + 2 * pi * math.floor((un - me) / (2 * pi) + 0.5)}
end

local b = 0.6
local r = period(b, 400)
print(top)
print(("beta = %.2f: T = %.7f, Lambda = %.9f (2 pi (1 - cos b) = %.9f), 2 H T = %.7f"):format(
  b, r.T, r.Lam, 2 * pi * (1 - math.cos(b)), 2 * r.H * r.T))
print(("phase after one period: measured %.9f, -Lambda + 2 H T = %.9f, exact %.9f"):format(
  r.measured, r.predicted, (r.T) % (2 * pi)))

-- the body momentum curve and the twist angle during the period
local tr = r.tr
local x, y, z, t, tw = {}, {}, {}, {}, {}
for k = 1, #tr do
  x[k], y[k], z[k] = tr:column("mu1")[k], tr:column("mu2")[k], tr:column("mu3")[k]
  t[k] = tr:column("t")[k]
  tw[k] = twist(tr:group(k), r.a)
end
for k = 2, #tw do tw[k] = tw[k] + 2 * pi * math.floor((tw[k - 1] - tw[k]) / (2 * pi) + 0.5) end
-- meridians and the equator of the unit sphere, for the picture
local sphere = {}
for m = 0, 5 do
  local X, Y, Z = {}, {}, {}
  for k = 0, 120 do
    local th = 2 * pi * k / 120
    X[#X + 1], Y[#Y + 1], Z[#Z + 1] = math.sin(th) * math.cos(pi * m / 6), math.sin(th) * math.sin(pi * m / 6), math.cos(th)
  end
  sphere[#sphere + 1] = {X, Y, Z, with = "lines lc rgb '#c8c8c8'"}
end
local X, Y, Z = {}, {}, {}
for k = 0, 120 do
  X[#X + 1], Y[#Y + 1], Z[#Z + 1] = math.cos(2 * pi * k / 120), math.sin(2 * pi * k / 120), 0
end
sphere[#sphere + 1] = {X, Y, Z, with = "lines lc rgb '#c8c8c8'"}
sphere[#sphere + 1] = {x, y, z, with = "lines lw 3 lc rgb '#b02020'", legend = "Pi(t)/|Pi|, one period"}
sphere.title = ("body momentum: a circle enclosing Lambda = %.4f"):format(r.Lam)
sphere.view = {60, 30}
sphere.xlabel, sphere.ylabel, sphere.zlabel = "Pi1", "Pi2", "Pi3"
sphere.key = "top left"
sphere.commands = {"set view equal xyz", "set xyplane at -1", "set xtics 0.5", "set ytics 0.5", "set ztics 0.5"}

-- the formula across cone angles, and the convergence in N
local bs, meas, pred = {}, {}, {}
for i = 1, 14 do
  local bb = 0.1 * i
  local q = period(bb, 400)
  bs[i], meas[i], pred[i] = bb, q.measured_unwrapped, q.unwrapped
end
local Ns, err = {}, {}
for i, N in ipairs{100, 200, 400, 800, 1600} do
  local q = period(b, N)
  Ns[i], err[i] = q.T / N, q.measured - q.T % (2 * pi)
  print(("N = %4d steps per period: phase error %+.4e"):format(N, err[i]))
end

dm.plot{
  sphere,
  {{t, tw, with = "lines lw 2", legend = "rotation about the spatial momentum"},
   {{r.T}, {r.predicted + 2 * pi * math.floor((tw[#tw] - r.predicted) / (2 * pi) + 0.5)},
    with = "points pt 7 ps 2", legend = "-Lambda + 2 H T (mod 2 pi)"},
   title = "the body's turn over one period (lgvi, 400 steps)", xlabel = "t",
   ylabel = "angle (rad)", key = "top left"},
  {{bs, pred, with = "lines lw 2", legend = "-Lambda + 2 H T, Lambda by holonomy"},
   {bs, meas, with = "points pt 6 ps 1.5", legend = "measured on the lgvi run (mod 2 pi, nearest branch)"},
   title = "Montgomery's formula across cone angles (400 steps per period)",
   xlabel = "cone angle b of Pi(0) (rad)", ylabel = "phase (rad)"},   -- the long key goes below
  dm.plot_convergence{h = Ns, errors = {{"phase error", err}}, orders = {2}, panel = true,
    xlabel = "step h", ylabel = "|phase error| (rad)",
    title = "lgvi: the phase converges at second order"},
  layout = "2,2", size = {1300, 1000}, output = "rigid_body_phase.png"}
