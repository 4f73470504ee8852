-- spherical_pendulum.lua -- the spherical pendulum as a system on the
-- sphere S^2 (dm.system{space = dm.lie.sphere(2)}), stepped by the
-- variational integrator of Lee, Leok and McClamroch on the sphere itself
-- (method lgvi; doc/lie.md §10), against classical RK4 in spherical
-- coordinates.
--
--   src/dmech examples/spherical_pendulum.lua [output-directory]
--
-- L = (m/2)|v|^2 - m g z on the unit sphere, m = 1, g = 9.81; the bob starts
-- at theta = 2.385 from the upward vertical (43.4 degrees from the lowest
-- point), azimuth 0.3, with theta' = 0.2 and an azimuthal speed 1.1.
-- Panel 1: the bob seen from above (the precessing rosette), t = 0..30.
-- Panel 2, t = 0..2000: the energy error.  lgvi (h = 0.01, the potential's
-- gradient at both ends of a step: two evaluations) keeps it bounded (O(h^2),
-- oscillating, no drift); RK4 in (theta, phi) at h = 0.02 (four evaluations
-- a step: as many per unit time) starts far more accurate, but its error
-- grows steadily and passes lgvi's bound near t = 60.  Panel 3: what lgvi
-- keeps to round-off by construction, |x| = 1 (no projection) and the
-- vertical angular momentum (x p)_z; in (theta, phi) that momentum is
-- p_phi, a linear invariant every Runge-Kutta method conserves, so RK4
-- keeps it too -- the difference is the energy.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local m, g = 1, 9.81
local pend = dm.system{space = dm.lie.sphere(2), name = "spherical pendulum",
  coords = {"x", "y", "z"}, params = {m = m, g = g},
  L = function(x, v, p) return 0.5 * p.m * (v[1]^2 + v[2]^2 + v[3]^2) - p.m * p.g * x[3] end}
local polar = dm.system{coords = {"th", "ph"}, name = "spherical pendulum (theta, phi)",
  params = {m = m, g = g},
  L = function(q, v, p)
    return 0.5 * p.m * (v.th^2 + dm.sin(q.th)^2 * v.ph^2) - p.m * p.g * dm.cos(q.th)
  end}

local th, ph, dth, dph = 2.385, 0.3, 0.2, 1.1 / math.sin(2.385)
local st, ct, sp, cp = math.sin(th), math.cos(th), math.sin(ph), math.cos(ph)
local x0 = {st * cp, st * sp, ct}
local v0 = {ct * cp * dth - st * sp * dph, ct * sp * dth + st * cp * dph, -st * dth}

local short = dm.integrator(pend, {h = 0.01}):run({q = x0, v = v0}, {t = 30})
local T = 2000
local lg = dm.integrator(pend, {h = 0.01}):run({q = x0, v = v0}, {t = T, every = 100})
local rk = dm.integrator(polar, {method = "rk4", h = 0.02}):run({q = {th, ph}, v = {dth, dph}},
                                                               {t = T, every = 50})

-- errors against the start, as columns
local E0, Lz0 = lg:column("energy")[1], x0[1] * m * v0[2] - x0[2] * m * v0[1]
lg:derive("dE", function(s) return math.abs(s.energy - E0) end)
lg:derive("dLz", function(s) return math.abs(s.momentum_3 - Lz0) end)   -- (x ^ p)_z
lg:derive("dr", function(s) return math.abs(math.sqrt(s.x^2 + s.y^2 + s.z^2) - 1) end)
rk:derive("dE", function(s) return math.abs(s.energy - E0) end)
rk:derive("dLz", function(s) return math.abs(s.p_ph - Lz0) end)

local function worst(tr, c)
  local w = 0
  for _, x in ipairs(tr:column(c):totable()) do w = math.max(w, x) end
  return w
end
print(("lgvi, h = 0.01, %d steps:  max |E - E0| %.3g, max |(x p)_z drift| %.3g, max ||x| - 1| %.3g")
      :format(lg:meta().steps, worst(lg, "dE"), worst(lg, "dLz"), worst(lg, "dr")))
print(("rk4 in (theta, phi), h = 0.02, %d steps:  max |E - E0| %.3g, |E - E0| at t = %d: %.3g, "
       .. "max |p_phi drift| %.3g"):format(rk:meta().steps, worst(rk, "dE"), T,
       rk:column("dE")[#rk], worst(rk, "dLz")))

-- floor the round-off zeros for the log axes
for _, tr in ipairs{lg, rk} do
  tr:derive("dEp", function(s) return math.max(s.dE, 1e-17) end)
  tr:derive("dLzp", function(s) return math.max(s.dLz, 1e-17) end)
end
lg:derive("drp", function(s) return math.max(s.dr, 1e-17) end)

local file = outdir .. "/spherical_pendulum.png"
dm.plot{
  {{short, "x", "y", with = "lines lw 1.2 lc rgb '#1f77b4'", title = "bob (x, y)"},
   title = "the bob seen from above, t = 0..30 (lgvi, h = 0.01)", xlabel = "x", ylabel = "y",
   aspect = "equal", commands = {"set key below"}},
  {{lg, "t", "dEp", with = "lines lw 1.2 lc rgb '#1f77b4'", title = "lgvi on S^2, h = 0.01"},
   {rk, "t", "dEp", with = "lines lw 1.2 lc rgb '#d62728'",
    title = "rk4 in (theta, phi), h = 0.02"},
   title = "energy error, t = 0..2000", xlabel = "t",
   ylabel = "|E - E0|", logscale = "y",
   commands = {"set key below", "set format y '%.0e'", "set yrange [1e-7:1]"}},
  {{lg, "t", "dLzp", with = "lines lw 1.2 lc rgb '#1f77b4'", title = "lgvi: |(x p)_z - Lz0|"},
   {lg, "t", "drp", with = "lines lw 1.2 lc rgb '#2ca02c'", title = "lgvi: ||x| - 1|"},
   {rk, "t", "dLzp", with = "lines lw 1.2 lc rgb '#d62728'", title = "rk4: |p_phi - Lz0|"},
   title = "invariants kept to round-off", xlabel = "t", ylabel = "deviation",
   logscale = "y", commands = {"set key below", "set format y '%.0e'", "set yrange [1e-17:1e-11]"}},
  layout = "1,3", size = {1700, 560}, output = file}
print("  wrote " .. file)
