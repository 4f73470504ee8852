-- stiff_pendulum.lua -- a multiscale variational integrator (doc/beyond-fixed-steps.md
-- §4): the planar pendulum on a stiff spring, L = m(a'^2 + (l + a)^2 th'^2)/2
-- + m g (l + a) cos th - k a^2/2, with the fast energy fixed as the
-- stiffness k grows from 1e4 to 1e8, integrated to T = 3 with the same step
-- h = 0.05 (h w = 5 ... 500).
--   stiff_pendulum.png  (a) the error of the slow angle at T against k:
--                       the multiscale integrator's does not grow with k (it
--                       falls), Gauss s = 2's stays near 5e-7 (lower
--                       than the multiscale one only at k = 1e5, h w = 16,
--                       where it has already lost the fast phase); (b) the relative error
--                       of the fast stretch: the multiscale integrator keeps
--                       the fast phase (1e-3), Gauss s = 2 loses it (0.3 - 1);
--                       (c) theta(t) at k = 1e6 against a resolved run
--
--   src/dmech examples/stiff_pendulum.lua [output-directory]
local dm = dm or require "dmech"
local outdir = arg and arg[1] or "."
local h, T, th0, Ef = 0.05, 3, 0.5, 0.05
local sys = dm.system{name = "pendulum on a stiff spring", coords = {"a", "theta"},
  params = {k = 1e4, m = 1, g = 9.81, l = 1},
  L = function(q, v, p)
    return 0.5 * p.m * (v.a^2 + (p.l + q.a)^2 * v.theta^2) + p.m * p.g * (p.l + q.a) * dm.cos(q.theta)
      - 0.5 * p.k * q.a^2
  end}

local ks = {1e4, 1e5, 1e6, 1e7, 1e8}
local slow_ms, slow_g2, fast_ms, fast_g2 = {}, {}, {}, {}
local keep = {}
for i, k in ipairs(ks) do
  sys.params.k = k
  local A = math.sqrt(2 * Ef / k)
  local s0 = {q = {9.81 * math.cos(th0) / k + A, th0}, p = {0, 0}}
  local w = math.sqrt(k)
  -- the reference: Gauss s = 4, at least 40 steps per fast period, ending at T exactly
  local nref = math.ceil(T / (2 * math.pi / w / 40))
  local ref = dm.integrator(sys, {method = "gauss", stages = 4, h = T / nref})
                :run(s0, {steps = nref, every = nref})
  local ms = dm.integrator(sys, {method = "multiscale", h = h, omega = w, fast = "a"}):run(s0, {t = T})
  local g2 = dm.integrator(sys, {method = "gauss", stages = 2, h = h}):run(s0, {t = T})
  local function err(tr, c) return math.abs(tr:column(c)[#tr] - ref:column(c)[#ref]) end
  slow_ms[i], slow_g2[i] = err(ms, "theta"), err(g2, "theta")
  fast_ms[i], fast_g2[i] = err(ms, "a") / A, err(g2, "a") / A
  print(string.format("k = %.0e (h w = %5.0f): |d theta(T)| multiscale %.2e, Gauss s=2 %.2e; "
    .. "fast relative error %.2e, %.2e", k, h * w, slow_ms[i], slow_g2[i], fast_ms[i], fast_g2[i]))
  if k == 1e6 then keep = {ms = ms, g2 = g2, s0 = s0, w = w} end
end

-- (c) theta(t) at k = 1e6 against a resolved run sampled at the same times
sys.params.k = 1e6
local fine = dm.integrator(sys, {method = "gauss", stages = 4, h = h / 200})
                :run(keep.s0, {t = T, every = 200})
local t = keep.ms:column("t")
local function dev(tr)
  local d, th, thr = {}, tr:column("theta"), fine:column("theta")
  for k = 1, #tr do d[k] = math.max(math.abs(th[k] - thr[k]), 1e-16) end
  return d
end

dm.plot{
  {{ks, slow_ms, with = "linespoints lw 2 pt 7", title = "multiscale"},
   {ks, slow_g2, with = "linespoints lw 2 pt 5", title = "Gauss s=2"},
   title = string.format("(a) slow error |theta(T) - ref|, h = %g", h), xlabel = "stiffness k",
   ylabel = "error", logscale = "xy", grid = true, key = "bottom left"},
  {{ks, fast_ms, with = "linespoints lw 2 pt 7", title = "multiscale"},
   {ks, fast_g2, with = "linespoints lw 2 pt 5", title = "Gauss s=2"},
   title = "(b) fast error |a(T) - ref| / amplitude", xlabel = "stiffness k", ylabel = "relative error",
   logscale = "xy", grid = true, key = "bottom right"},
  {{t, dev(keep.ms), with = "lines lw 2", title = "multiscale"},
   {keep.g2:column("t"), dev(keep.g2), with = "lines lw 2", title = "Gauss s=2"},
   title = string.format("(c) |theta(t) - ref| at k = 1e6 (h w = %g)", h * keep.w), xlabel = "t",
   ylabel = "error", logscale = "y", grid = true, key = "bottom right", yrange = {1e-10, 1e-5}},
  layout = "1,3", size = {1500, 480}, output = outdir .. "/stiff_pendulum.png",
  title = "Pendulum on a stiff spring: the same step for every stiffness"}
print("wrote " .. outdir .. "/stiff_pendulum.png")
