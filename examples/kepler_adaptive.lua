-- kepler_adaptive.lua -- adaptive steps that keep the structure
-- (doc/beyond-fixed-steps.md §3): a time transformation dt/ds = g(q) with fixed steps
-- in the fictitious time s, on the Kepler orbit of eccentricity 0.9.
--   kepler_adaptive.png   (a) every step of one orbit; (b) the physical
--                         step against the distance r (monitor r^1.5: slope
--                         1.5); (c) error after 100 periods against CPU
--                         time, beside GSL's adaptive rk8pd; (d) the energy
--                         error over the 100 periods: bounded against drift
--
--   src/dmech examples/kepler_adaptive.lua [output-directory]
local dm = dm or require "dmech"
local outdir = arg and arg[1] or "."
local e, periods = 0.9, 100
local T = 2 * math.pi * periods
local kep = dm.systems.kepler()
local start = {q = {1 - e, 0}, p = {0, math.sqrt((1 + e) / (1 - e))}}

-- the exact state at time t (Kepler's equation, a = 1, from the pericentre)
local function exact(t)
  local M = math.fmod(t, 2 * math.pi)
  local E = M + e * math.sin(M)
  for _ = 1, 60 do
    local d = (E - e * math.sin(E) - M) / (1 - e * math.cos(E))
    E = E - d
    if math.abs(d) < 1e-16 then break end
  end
  local w = 1 - e * math.cos(E)
  return math.cos(E) - e, math.sqrt(1 - e * e) * math.sin(E),
         -math.sin(E) / w, math.sqrt(1 - e * e) * math.cos(E) / w
end
local function error_at_end(tr)
  local n = #tr
  local x, y, px, py = exact(tr:column("t")[n])
  local dx, dy = tr:column("x")[n] - x, tr:column("y")[n] - y
  local dpx, dpy = tr:column("p_x")[n] - px, tr:column("p_y")[n] - py
  return math.sqrt(dx * dx + dy * dy + dpx * dpx + dpy * dpy)
end
-- CPU seconds per run, repeated until 0.1 s have passed (short runs are
-- below the clock's resolution)
local function timed(integ, opts)
  local c0, k, tr = os.clock(), 0, nil
  repeat
    tr = integ:run(start, opts)
    k = k + 1
  until os.clock() - c0 > 0.1
  return tr, (os.clock() - c0) / k
end

-- {== (a), (b): Gauss s = 2 with the Sundman-type monitor r^1.5
local G = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.02,
  adapt = {monitor = function(q) return dm.sqrt(q.x^2 + q.y^2)^1.5 end}})
local one = G:run(start, {t = 2 * math.pi})
-- h at sample k is the step that ended there; the last one was shortened
-- to end at t = 2 pi exactly and is left out
local r, hk = {}, {}
local xs, ys, hs = one:column("x"), one:column("y"), one:column("h")
for k = 1, #one - 1 do r[k], hk[k] = math.sqrt(xs[k]^2 + ys[k]^2), hs[k] end
print(string.format("one orbit, Gauss s=2, monitor r^1.5, h = 0.02: %d steps, physical steps "
  .. "%.3g ... %.3g", #one - 1, hs:min(), hs:max()))

-- {== (c): error after 100 periods against CPU time
local curves = {}
local function sweep(label, key, make, values, opts)
  local cx, cy = {}, {}
  for _, v in ipairs(values) do
    local tr, cpu = timed(make(v), opts)
    local err = error_at_end(tr)
    cx[#cx + 1], cy[#cy + 1] = cpu, err
    print(string.format("  %-34s %-10g error %.3e  cpu %.4f s", label, v, err, cpu))
  end
  curves[#curves + 1] = {cx, cy, title = key, with = "linespoints lw 2"}
end
print(string.format("error after %d periods (e = %g) against CPU time:", periods, e))
sweep("adapt, composition order 8, N", "adapt, composition order 8", function(N)
  return dm.integrator(kep, {method = "composition", order = 8, h = 2 * math.pi * (1 - e) / N,
                             adapt = true}) end, {8, 11, 16, 22, 32, 45}, {t = T, every = 1e9})
sweep("adapt, Gauss s=2, r^1.5, h", "adapt, Gauss s=2, r^1.5", function(h)
  return dm.integrator(kep, {method = "gauss", stages = 2, h = h,
    adapt = {monitor = function(q) return dm.sqrt(q.x^2 + q.y^2)^1.5 end}}) end,
  {0.04, 0.028, 0.02, 0.014, 0.01}, {t = T, every = 1e9})
sweep("GSL rk8pd (gsl:rk8pd), tol", "GSL rk8pd", function(tol)
  return dm.integrator(kep, {method = "gsl:rk8pd", adaptive = true, epsabs = tol, epsrel = tol,
                             h = 2 * math.pi}) end,
  {1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14}, {t = T, every = 1e9})
sweep("fixed steps, composition order 8, h", "fixed step, composition order 8", function(h)
  return dm.integrator(kep, {method = "composition", order = 8, h = h}) end,
  {0.02, 0.014, 0.01, 0.007}, {t = T, every = 1e9})

-- {== (d): the energy error, sampled once per period
local A = dm.integrator(kep, {method = "composition", order = 8, h = 2 * math.pi * (1 - e) / 16,
                              adapt = true})
local Rk = dm.integrator(kep, {method = "gsl:rk8pd", adaptive = true, epsabs = 1e-11, epsrel = 1e-11,
                               h = 2 * math.pi})
local function energy_error(tr)
  local E = tr:energy()
  local t, d = {}, {}
  for k = 2, #tr do               -- exact zeros have no place on a log scale
    local dk = math.abs(E[k] - E[1])
    if dk > 0 then t[#t + 1], d[#d + 1] = tr:column("t")[k], dk end
  end
  return t, d
end
local ta, da = energy_error(A:run(start, {t = T, every = 16}))   -- 16 steps = one period
local tg, dg = energy_error(Rk:run(start, {t = T}))

dm.plot{
  {{one, "x", "y", with = "points pt 7 ps 0.6", title = "every step"},
   {{0}, {0}, with = "points pt 3 ps 2", title = "focus"},
   title = "(a) one orbit, e = 0.9, Gauss s=2, monitor r^1.5", xlabel = "x", ylabel = "y",
   yrange = {-0.6, 0.9}, aspect = "equal", key = "top left"},
  {{r, hk, with = "points pt 7 ps 0.5", title = "physical steps"},
   {function(x) return x, 0.02 * x^1.5 end, range = {0.09, 2}, title = "0.02 r^1.5", with = "lines lw 2"},
   title = "(b) step against distance", xlabel = "r", ylabel = "physical step", logscale = "xy",
   xrange = {0.05, 3}, yrange = {3e-4, 0.1},
   grid = true, key = "top left"},
  {curves[1], curves[2], curves[3], curves[4],
   title = string.format("(c) error after %d periods", periods), xlabel = "CPU seconds",
   ylabel = "|(q, p) - exact|", logscale = "xy", grid = true, key = "bottom right",
   yrange = {1e-13, 10}},
  {{ta, da, with = "linespoints pt 7 ps 0.5", title = "adapt, composition order 8 (16 steps/period)"},
   {tg, dg, with = "lines lw 2", title = "GSL rk8pd, tol 1e-11"},
   title = "(d) energy error, once per period", xlabel = "t", ylabel = "|H - H0|", logscale = "y", grid = true,
   key = "bottom right"},
  layout = "2,2", title = "Kepler e = 0.9: time-transformed symplectic methods",
  output = outdir .. "/kepler_adaptive.png", size = {1300, 1000}}
print("wrote " .. outdir .. "/kepler_adaptive.png")
