-- sine_gordon.lua -- a multisymplectic variational integrator (doc/beyond-fixed-steps.md
-- §5): the sine-Gordon equation u_tt = u_xx - sin u on a space-time grid
-- (bilinear elements, one-point rule), a kink and an antikink colliding
-- (the exact Perring-Skyrme solution u = 4 atan(sinh(g v t)/(v cosh(g x)))).
--   sine_gordon.png   (a) u(x, t) at successive times (shifted upwards by 0.8 (t - t0)):
--                     the two pass through each other; (b) the error at the
--                     end against the exact solution, dx = 0.1 and 0.05 (order
--                     2); (c) the energy error over the run; the title gives the
--                     discrete multisymplectic conservation law checked node by
--                     node along the run
--   sine_gordon_adapt.png  moving nodes (dm.wave{..., adapt = {...}},
--                     doc/beyond-fixed-steps.md §7) on a kink v = 0.9:
--                     (a) the node paths X_i(t), crowding where the kink is;
--                     (b) u at the end with the nodes, adaptive against the
--                     still grid at the same number of nodes; (c) the error
--                     against the number of cells, both
--
--   src/dmech examples/sine_gordon.lua [output-directory]
local dm = dm or require "dmech"
local outdir = arg and arg[1] or "."
local v, t0, T, len = 0.5, -15, 30, 60
local g = 1 / math.sqrt(1 - v * v)

local function exact(x, t) return 4 * math.atan(math.sinh(g * v * t) / (v * math.cosh(g * x))) end
local function exact_t(x, t)
  local s = math.sinh(g * v * t) / (v * math.cosh(g * x))
  return 4 * g * math.cosh(g * v * t) / math.cosh(g * x) / (1 + s * s)
end
local start = {u = function(x) return exact(x, t0) end, v = function(x) return exact_t(x, t0) end}

local function solve(N, every)
  local dx = len / N
  local W = dm.wave{N = N, length = len, x0 = -len / 2, periodic = true, dt = dx / 2,
                    V = function(u) return 1 - dm.cos(u) end}
  local tr, U = W:run(start, {t = T, every = every})
  return W, tr, U
end

local W, tr, U = solve(600, 30)
local x = W:x()
print(string.format("%d nodes, dt = %g, %d steps; kink energy 8 g = %.6f each", #x, 0.05, T / 0.05, 8 * g))

-- (a) snapshots every 3 time units, shifted by 0.8 (t - t0) (the run's clock
-- starts at 0)
local snaps = {}
for r = 1, U:rows(), 2 do
  local t = tr:column("t")[r]
  local y = {}
  for i = 1, #x do y[i] = U[r][i] + 0.8 * t end
  snaps[#snaps + 1] = {x, y, with = "lines lw 1.5 lc rgb '#3060a0'"}
end
snaps.title = "(a) u(x, t) + 0.8 (t - t0): kink and antikink collide"
snaps.xlabel = "x"
snaps.ylabel = "u + 0.8 (t - t0)"
snaps.key = false
snaps.xrange = {-20, 20}

-- (b) the error at the end, two resolutions
local function enderr(Wn, Un)
  local xs, d = Wn:x(), {}
  local last = Un:rows()
  for i = 1, #xs do d[i] = Un[last][i] - exact(xs[i], t0 + T) end
  return xs, d
end
local x1, d1 = enderr(W, U)
local W2, tr2, U2 = solve(1200, 60)
local x2, d2 = enderr(W2, U2)
local function maxabs(a) local m = 0 for i = 1, #a do m = math.max(m, math.abs(a[i])) end return m end
print(string.format("max error at t = %g: %.3g (dx = 0.1), %.3g (dx = 0.05): ratio %.2f",
  t0 + T, maxabs(d1), maxabs(d2), maxabs(d1) / maxabs(d2)))

-- (c) the energy error over the run, at every step
local trE = W:run(start, {t = T, every = 1})
local E = trE:energy()
local dE, tt = {}, trE:column("t")
for k = 1, #trE do dE[k] = E[k] - E[1] end
print(string.format("energy %.6f (exact 16 g = %.6f), variation %.2g", E[1], 16 * g, E:max() - E:min()))

-- the multisymplectic form formula along 100 steps of the collision
local res = W:form_check(start, {du = function(x) return math.exp(-(x - 3)^2) end,
                                 dp = function(x) return 0.1 * math.cos(x) end,
                                 dv = function(x) return 1 / math.cosh(x) end,
                                 dq = function(x) return math.exp(-(x + 4)^2) end, steps = 100})
print(string.format("multisymplectic form formula over 100 steps: cells %.2g, nodes %.2g, levels %.2g",
  res.cell, res.node, res.level))

dm.plot{
  snaps,
  {{x1, d1, with = "lines lw 2", title = "dx = 0.1"}, {x2, d2, with = "lines lw 2", title = "dx = 0.05"},
   title = string.format("(b) u - exact at t = %g", t0 + T), xlabel = "x", ylabel = "error",
   xrange = {-20, 20}, grid = true, key = "top center"},
  {{tt, dE, with = "lines lw 2", title = "E(t) - E(0)"},
   title = "(c) energy error (dx = 0.1)", xlabel = "t - t0", ylabel = "energy error", grid = true,
   key = "top right"},
  layout = "1,3", size = {1500, 500}, output = outdir .. "/sine_gordon.png",
  title = string.format("sine-Gordon kink-antikink, v = %g; multisymplectic law at every node to %.1g",
                        v, res.node)}
print("wrote " .. outdir .. "/sine_gordon.png")

-- moving nodes: a kink v = 0.9 (width 1/g = 0.44) travelling from x = -6
local va, Ta, lena = 0.9, 12, 40
local ga = 1 / math.sqrt(1 - va * va)
local kink = {u = function(x) return 4 * math.atan(math.exp(ga * (x + 6))) end,
              v = function(x) local e = math.exp(ga * (x + 6)) return -4 * ga * va * e / (1 + e * e) end}
local function kink_exact(x, t) return 4 * math.atan(math.exp(ga * (x + 6 - va * t))) end
local function kink_run(N, alpha)
  local opts = {N = N, length = lena, x0 = -lena / 2, periodic = false, dt = 10 / N,
                V = function(u) return 1 - dm.cos(u) end}
  if alpha then opts.adapt = {monitor = "arclength", alpha = alpha} end
  local Wk = dm.wave(opts)
  local trk, Uk, Xk = Wk:run(kink, {t = Ta, every = math.max(1, N // 50)})
  if not Xk then   -- the still grid: the same nodes at every sample
    local xs = Wk:x()
    Xk = dm.mat(Uk:rows(), #xs)
    for r = 1, Uk:rows() do for i = 1, #xs do Xk[r][i] = xs[i] end end
  end
  local last, e = Uk:rows(), 0
  for i = 1, Uk:cols() do e = math.max(e, math.abs(Uk[last][i] - kink_exact(Xk[last][i], Ta))) end
  return trk, Uk, Xk, e
end
local trA, UA, XA, eA = kink_run(100, 4)
local _, US, XS, eS = kink_run(100)
print(string.format("kink v = %g, 100 cells, t = %g: nodal error %.3g moving nodes, %.3g still grid (ratio %.1f); "
  .. "equidistribution residual <= %.2g", va, Ta, eA, eS, eS / eA, trA:column("equidist"):max()))
local paths, tA = {}, trA:column("t")
for i = 1, XA:cols(), 2 do
  local xi = {}
  for r = 1, XA:rows() do xi[r] = XA[r][i] end
  paths[#paths + 1] = {xi, tA, with = "lines lw 1 lc rgb '#3060a0'"}
end
paths[#paths + 1] = {{-6, -6 + va * Ta}, {0, Ta}, with = "lines lw 2 dt 2 lc rgb '#c03020'",
                     title = "kink centre x = -6 + v t"}
paths.title = "(a) node paths X_i(t) (every second node), alpha = 4"
paths.xlabel, paths.ylabel, paths.key = "x", "t", "top left opaque box"
local function row(M, r) local a = {} for i = 1, M:cols() do a[i] = M[r][i] end return a end
local xf, uf = {}, {}
for k = 0, 800 do xf[k + 1] = -20 + 40 * k / 800; uf[k + 1] = kink_exact(xf[k + 1], Ta) end
local Ns, errA, errS = {50, 100, 200, 400}, {}, {}
for j, N in ipairs(Ns) do
  errA[j] = select(4, kink_run(N, 4))
  errS[j] = select(4, kink_run(N))
  print(string.format("  %3d cells: error %.3g moving, %.3g still", N, errA[j], errS[j]))
end
dm.plot{
  paths,
  {{xf, uf, with = "lines lw 1 lc rgb 'black'", title = "exact"},
   {row(XA, XA:rows()), row(UA, UA:rows()), with = "linespoints pt 7 ps 0.6 lc rgb '#3060a0'",
    title = "moving nodes"},
   {row(XS, XS:rows()), row(US, US:rows()), with = "linespoints pt 6 ps 0.6 lc rgb '#c03020'",
    title = "still grid"},
   title = string.format("(b) u at t = %g, 100 cells: errors %.2g and %.2g", Ta, eA, eS),
   xlabel = "x", ylabel = "u", xrange = {0, 10}, grid = true, key = "bottom right"},
  {{Ns, errA, with = "linespoints lw 2 pt 7 lc rgb '#3060a0'", title = "moving nodes"},
   {Ns, errS, with = "linespoints lw 2 pt 6 lc rgb '#c03020'", title = "still grid"},
   title = "(c) nodal error at t = 12 (dt = 10/N)", xlabel = "cells N", ylabel = "max error",
   logscale = "xy", xrange = {40, 500}, grid = true, key = "top right"},
  layout = "1,3", size = {1500, 500}, output = outdir .. "/sine_gordon_adapt.png",
  title = string.format("sine-Gordon kink v = %g on moving nodes: arc-length equidistribution, alpha = 4", va)}
print("wrote " .. outdir .. "/sine_gordon_adapt.png")
