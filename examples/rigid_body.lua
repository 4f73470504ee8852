-- rigid_body.lua -- the free rigid body on SO(3) (doc/lie.md): body-momentum
-- curves on the momentum sphere, and the Lie group variational integrator
-- (lgvi, Moser-Veselov form) against RK4 on quaternions (GSL odeiv2) at
-- equal cost over 1e6 LGVI steps.
--
--   src/dmech examples/rigid_body.lua [output-directory]
--
-- J = diag(1, 2, 3), |Pi| = 1.  The body momentum Pi moves on the sphere
-- |Pi| = 1 along its intersections with the energy ellipsoids
-- Pi^T J^-1 Pi = 2E: closed curves about the axes of the smallest (energy
-- 1/2) and largest (1/6) moment of inertia; the curves through the middle
-- axis (E = 1/4) are the separatrices, and rotation about that axis is
-- unstable.  Figure 1 draws the curves of lgvi runs at h = 0.01.
--
-- Figure 2: lgvi with h = 0.01 for 1e6 steps (t = 1e4) and RK4 on the
-- quaternion ODE (gsl:rk4) with the step that makes it cost the same CPU
-- time per unit of simulated time (measured here, printed).  lgvi keeps
-- |Pi|, the spatial momentum R Pi and (for the free body) the energy to
-- round-off; RK4 drifts in all three.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local SO3 = dm.lie.SO3()
local body = dm.system{space = SO3, name = "free rigid body", params = {J1 = 1, J2 = 2, J3 = 3},
  L = function(R, Om, p) return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) end}

-- figure 1: the curves on the momentum sphere, over a wire sphere
local series = {}
for k = 0, 5 do                                   -- meridians and parallels
  local x, y, z, u, v, w = {}, {}, {}, {}, {}, {}
  local phi, lat = k * math.pi / 6, (k - 2.5) * math.pi / 6
  for i = 0, 120 do
    local a = 2 * math.pi * i / 120
    x[#x + 1], y[#y + 1], z[#z + 1] = math.cos(a) * math.cos(phi), math.cos(a) * math.sin(phi), math.sin(a)
    u[#u + 1], v[#v + 1], w[#w + 1] = math.cos(lat) * math.cos(a), math.cos(lat) * math.sin(a), math.sin(lat)
  end
  series[#series + 1] = {x, y, z, with = "lines lc rgb '#dddddd'"}
  series[#series + 1] = {u, v, w, with = "lines lc rgb '#dddddd'"}
end
local nwire = #series
local function curve(pi0, T, title, style)
  local n = math.sqrt(pi0[1]^2 + pi0[2]^2 + pi0[3]^2)
  local p = {pi0[1] / n, pi0[2] / n, pi0[3] / n}
  local tr = dm.integrator(body, {method = "lgvi", h = 0.01}):run({g = SO3.identity(), mu = p},
                                                                   {t = T, every = 5})
  series[#series + 1] = {tr, "mu1", "mu2", "mu3", with = style, title = title}
  return tr
end
local E = function(p) return 0.5 * (p[1]^2 + p[2]^2 / 2 + p[3]^2 / 3) end
for _, a in ipairs{0.25, 0.45, 0.7} do            -- about the axis of J1 = 1 (both signs)
  curve({math.cos(a), 0, math.sin(a)}, 40, nil, "lines lc rgb '#1f77b4'")
  curve({-math.cos(a), 0, math.sin(a)}, 40, nil, "lines lc rgb '#1f77b4'")
end
for _, a in ipairs{0.25, 0.55, 0.85} do           -- about the axis of J3 = 3
  curve({0, math.sin(a), math.cos(a)}, 40, nil, "lines lc rgb '#2ca02c'")
  curve({0, math.sin(a), -math.cos(a)}, 40, nil, "lines lc rgb '#2ca02c'")
end
-- the separatrices (E = 1/4): from Pi = (+-1/2, 0, +-sqrt(3)/2) the flow
-- reaches the middle axis (0, +-1, 0) only asymptotically; each arc is drawn
-- with its mirror image Pi_2 -> -Pi_2 (the other half of the same curve)
for _, s in ipairs{{0.5, 0, math.sqrt(3) / 2}, {0.5, 0, -math.sqrt(3) / 2},
                   {-0.5, 0, math.sqrt(3) / 2}, {-0.5, 0, -math.sqrt(3) / 2}} do
  local tr = curve(s, 25, nil, "lines lw 2 lc rgb '#d62728'")
  tr:derive("mirror2", function(smp) return -smp.mu2 end)
  series[#series + 1] = {tr, "mu1", "mirror2", "mu3", with = "lines lw 2 lc rgb '#d62728'"}
end
series[nwire + 1].title = "about the axis of J1 = 1 (E > 1/4)"
series[nwire + 7].title = "about the axis of J3 = 3 (E < 1/4)"
series[nwire + 13].title = "separatrices through the middle axis (E = 1/4)"
print(("energies: %.4f .. %.4f about J1, %.4f .. %.4f about J3, separatrix %.4f"):format(
  E{math.cos(0.7), 0, math.sin(0.7)}, E{math.cos(0.25), 0, math.sin(0.25)},
  E{0, math.sin(0.85), math.cos(0.85)}, E{0, math.sin(0.25), math.cos(0.25)}, 0.25))
series.title = "body momentum on the sphere |Pi| = 1, J = diag(1, 2, 3) (lgvi, h = 0.01)\n\n\n\n"
series.xlabel, series.ylabel, series.zlabel = "Pi_1", "Pi_2", "Pi_3"
series.aspect = "equal"
series.view = {62, 28}
series.size = {900, 800}
series.output = outdir .. "/rigid_body_sphere.png"
series.commands = {"set key at screen 0.5, screen 0.93 center top box opaque",
                   "set xrange [-1.05:1.05]", "set yrange [-1.05:1.05]", "set zrange [-1.05:1.05]",
                   "set xtics 0.5", "set ytics 0.5", "set ztics 0.5", "set xyplane at -1.05"}
dm.plot(series)
print("  wrote " .. series.output)

-- figure 2: lgvi against RK4 on quaternions at equal cost
local s0 = {g = SO3.exp{0.3, -0.2, 0.1}, mu = {0.9, 0.35, -0.25}}
local lgvi = dm.integrator(body, {method = "lgvi", h = 0.01})
local rk4 = dm.integrator(body, {method = "gsl:rk4"})
local function cost(I, h, steps)
  local t0 = os.clock()
  I:run(s0, {steps = steps, every = steps, h = h})
  return (os.clock() - t0) / steps
end
local c_lgvi = cost(lgvi, 0.01, 100000)
local c_rk4 = cost(rk4, 0.01, 20000)
local h_rk4 = 0.01 * c_rk4 / c_lgvi
print(("cost per step: lgvi %.3g us, gsl:rk4 %.3g us (ratio %.2f): RK4 gets h = %.4g"):format(
  1e6 * c_lgvi, 1e6 * c_rk4, c_rk4 / c_lgvi, h_rk4))
local T = 1e4
local t1 = os.clock()
local a = lgvi:run(s0, {t = T, every = 1000})
local t2 = os.clock()
local b = rk4:run(s0, {t = T, h = h_rk4, every = math.max(1, math.floor(1000 * 0.01 / h_rk4))})
local t3 = os.clock()
print(("CPU: lgvi %.2f s for %d steps, gsl:rk4 %.2f s for %d steps"):format(t2 - t1,
  math.floor(T / 0.01 + 0.5), t3 - t2, math.floor(T / h_rk4 + 0.5)))

-- drifts: ||Pi| - |Pi0||, |R Pi - R0 Pi0|, |E - E0| (floored at 1e-17 for the log scale)
local function drifts(tr)
  local t, dn, dJ, dE = tr:column("t"), {}, {}, {}
  local m1, m2, m3 = tr:column("mu1"), tr:column("mu2"), tr:column("mu3")
  local J1, J2, J3 = tr:column("momentum_1"), tr:column("momentum_2"), tr:column("momentum_3")
  local En = tr:energy()
  local n0 = math.sqrt(m1[1]^2 + m2[1]^2 + m3[1]^2)
  local worst = {0, 0, 0}
  for k = 1, #tr do
    dn[k] = math.max(1e-17, math.abs(math.sqrt(m1[k]^2 + m2[k]^2 + m3[k]^2) - n0))
    dJ[k] = math.max(1e-17, math.sqrt((J1[k] - J1[1])^2 + (J2[k] - J2[1])^2 + (J3[k] - J3[1])^2))
    dE[k] = math.max(1e-17, math.abs(En[k] - En[1]))
    worst[1], worst[2], worst[3] = math.max(worst[1], dn[k]), math.max(worst[2], dJ[k]),
                                   math.max(worst[3], dE[k])
  end
  return t, dn, dJ, dE, worst
end
local ta, na, Ja, Ea, wa = drifts(a)
local tb, nb, Jb, Eb, wb = drifts(b)
print(("lgvi:    max ||Pi| - |Pi0|| %.2g, max |R Pi - R0 Pi0| %.2g, max |E - E0| %.2g"):format(
  wa[1], wa[2], wa[3]))
print(("gsl:rk4: max ||Pi| - |Pi0|| %.2g, max |R Pi - R0 Pi0| %.2g, max |E - E0| %.2g"):format(
  wb[1], wb[2], wb[3]))
local lg = "lines lw 2 lc rgb '#1f77b4'"
local rk = "lines lw 2 lc rgb '#d62728'"
local function panel(title, ya, yb)
  return {{ta, ya, with = lg, title = "lgvi, h = 0.01"},
          {tb, yb, with = rk, title = ("RK4 on quaternions, h = %.3g"):format(h_rk4)},
          title = title, xlabel = "t", ylabel = "error", logscale = "y",
          commands = {"set format y '1e%T'", "set yrange [1e-17:1]", "set xrange [0:1e4]",
                      "set key top left"}}
end
local file = outdir .. "/rigid_body_drift.png"
dm.plot{panel(("||Pi| - |Pi0||  (equal CPU: %d lgvi steps, %d RK4 steps)"):format(
                 math.floor(T / 0.01 + 0.5), math.floor(T / h_rk4 + 0.5)), na, nb),
        panel("|R Pi - R0 Pi0|  (spatial momentum)", Ja, Jb),
        panel("|E - E0|", Ea, Eb), layout = "1,3", size = {1600, 500}, output = file}
print("  wrote " .. file)
