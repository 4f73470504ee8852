-- fields_wave.lua -- dm.wave from Lua: the grid integrator (dispersion,
-- a kink's speed and energy, the multisymplectic form formula), the DEC
-- integrator on a mesh (the linear wave's energy), moving nodes (adapt:
-- ordered, equidistributed, better than the still grid at the same N,
-- alpha = 0 is the still grid), the error texts.
local T = require "dmech.test"
local dm = require "dmech"

local W = dm.wave{N = 64, length = 10, c = 1.3, dt = 0.1}
T.ok(tostring(W):match("^<wave grid, 64 nodes, dt=0.1>$"), "tostring")
local k = 2 * math.pi * 5 / 10
T.ok(math.abs(math.tan(W:dispersion(k) * 0.05) / 0.1 - 1.3 * math.tan(k * 10 / 64 / 2) / (10 / 64)) < 1e-13,
     "dispersion: tan(w dt/2)/dt = c tan(k dx/2)/dx")
local x = W:x()
T.ok(#x == 64 and x[2] == 10 / 64, "node coordinates")

-- a sine-Gordon kink moves at its speed; its energy is 8 g
local v = 0.5
local g = 1 / math.sqrt(1 - v * v)
local SG = dm.wave{N = 800, length = 40, x0 = -20, periodic = false, dt = 0.025,
                   V = function(u) return 1 - dm.cos(u) end}
local tr, U = SG:run({u = function(x) return 4 * math.atan(math.exp(g * x)) end,
                      v = function(x) local e = math.exp(g * x) return -4 * g * v * e / (1 + e * e) end},
                     {t = 4, every = 40})
T.ok(#tr == 5 and U:rows() == 5 and U:cols() == 801, "samples: 5 rows of 801 nodes")
local xs, last, err = SG:x(), U:rows(), 0
for i = 1, #xs do err = math.max(err, math.abs(U[last][i] - 4 * math.atan(math.exp(g * (xs[i] - v * 4))))) end
T.ok(err < 5e-3, string.format("the kink at t = 4: max error %.2g", err))
local E = tr:energy()
T.ok(math.abs(E[1] - 8 * g) < 1e-2 and E:max() - E:min() < 1e-4,
     string.format("energy %.5f (8 g = %.5f), varies by %.2g", E[1], 8 * g, E:max() - E:min()))
local res = SG:form_check({u = function(x) return 4 * math.atan(math.exp(g * x)) end},
  {du = function(x) return math.exp(-x * x) end, dp = function(x) return 0 end,
   dv = function(x) return 0 end, dq = function(x) return math.exp(-(x - 1)^2) end, steps = 50})
T.ok(res.cell < 1e-14 and res.node < 1e-12 and res.level < 1e-12,
     string.format("multisymplectic form formula: cells %.2g, nodes %.2g, levels %.2g", res.cell, res.node, res.level))

-- DEC in space: the linear wave on a disc keeps its energy to round-off
local M = dm.mesh.disc{radius = 1, n = 5}
local D = dm.wave{mesh = M, dt = 0.02}
local trd = D:run({u = function(x, y) return math.exp(-10 * (x * x + y * y)) end}, {steps = 200, every = 20})
local Ed = trd:energy()
T.ok(Ed:max() - Ed:min() < 1e-13 * Ed[1], string.format("DEC disc: energy %.6f to %.2g", Ed[1], Ed:max() - Ed:min()))

local function err_(pattern, name, f) T.error_like(f, pattern, name) end
err_("dm.wave: dt must be a finite non%-zero number", "no dt", function() dm.wave{N = 10, length = 1} end)
err_("dm.wave: N %(the cells, >= 3%) and length, or mesh, are required", "no N", function() dm.wave{dt = 0.1} end)
err_("dm.wave: unknown field 'n'", "misspelt field", function() dm.wave{n = 3} end)
err_("dm.wave: give mesh or N and length, not both", "mesh and N", function() dm.wave{mesh = M, N = 4, dt = 0.1} end)
err_("dm.wave: V must be a function of u, got number", "V a number", function() dm.wave{N = 4, length = 1, dt = 0.1, V = 3} end)
err_("run: give exactly one of steps", "no t", function() W:run({u = function() return 0 end}, {}) end)
err_("run: the state needs u", "no u", function() W:run({}, {steps = 1}) end)
err_("form_check: the multisymplectic form formula is checked on still grids", "form_check on a mesh",
     function() D:form_check({u = function() return 0 end}, {}) end)
-- moving nodes: a kink v = 0.9 on 100 cells, arc-length equidistribution
local va = 0.9
local ga = 1 / math.sqrt(1 - va * va)
local kink = {u = function(x) return 4 * math.atan(math.exp(ga * (x + 6))) end,
              v = function(x) local e = math.exp(ga * (x + 6)) return -4 * ga * va * e / (1 + e * e) end}
local function adapt_wave(alpha, rule)
  return dm.wave{N = 100, length = 40, x0 = -20, periodic = false, dt = 0.1,
                 V = function(u) return 1 - dm.cos(u) end,
                 adapt = {monitor = "arclength", alpha = alpha, rule = rule}}
end
local A = adapt_wave(4)
T.ok(tostring(A) == "<wave grid r-adaptive alpha=4.0, 101 nodes, dt=0.1, V(u)>", tostring(A))
local tra, Ua, Xa = A:run(kink, {t = 12, every = 10})
T.ok(#tra == 13 and Ua:rows() == 13 and Xa:rows() == 13 and Xa:cols() == 101, "adapt: 13 samples of u and X")
local ordered, hmin = true, math.huge
for r = 1, Xa:rows() do
  for i = 1, 100 do
    ordered = ordered and Xa[r][i + 1] > Xa[r][i]
    hmin = math.min(hmin, Xa[r][i + 1] - Xa[r][i])
  end
end
T.ok(ordered and Xa[13][1] == -20 and Xa[13][101] == 20, string.format("adapt: nodes ordered, ends held (smallest cell %.3f)", hmin))
T.ok(tra:column("equidist"):max() < 1e-13, string.format("adapt: equidistribution residual %.2g", tra:column("equidist"):max()))
local function kink_err(X, U, t)
  local e = 0
  for i = 1, #X do e = math.max(e, math.abs(U[i] - 4 * math.atan(math.exp(ga * (X[i] + 6 - va * t))))) end
  return e
end
local ea = kink_err(Xa[13], Ua[13], 12)
local S = dm.wave{N = 100, length = 40, x0 = -20, periodic = false, dt = 0.1, V = function(u) return 1 - dm.cos(u) end}
local _, Us = S:run(kink, {t = 12, every = 120})
local es = kink_err(S:x(), Us[2], 12)
T.ok(es / ea > 10, string.format("adapt: nodal error %.3g against %.3g on the still grid (ratio %.1f)", ea, es, es / ea))
-- alpha = 0 with the centre rule is the still grid
local _, U0, X0 = adapt_wave(0, "centre"):run(kink, {t = 2.385, every = 24})
local d, dx = 0, 0
local _, Us0 = S:run(kink, {t = 2.385, every = 24})
for i = 1, 101 do
  d = math.max(d, math.abs(U0[U0:rows()][i] - Us0[Us0:rows()][i]))
  dx = math.max(dx, math.abs(X0[X0:rows()][i] - S:x()[i]))
end
T.ok(d < 1e-12 and dx < 1e-13, string.format("adapt alpha = 0, centre rule = still grid: u to %.2g, X to %.2g", d, dx))
err_("dm.wave: adapt.alpha is required", "no alpha", function() adapt_wave(nil) end)
err_("dm.wave: adapt.alpha must be a finite number >= 0, got %-2%.385", "negative alpha", function() adapt_wave(-2.385) end)
err_("dm.wave: adapt.rule must be \"edges\" or \"centre\", got middle", "bad rule", function() adapt_wave(1, "middle") end)
err_("dm.wave: adapt.monitor must be \"arclength\"", "bad monitor", function()
  dm.wave{N = 10, length = 1, periodic = false, dt = 0.1, adapt = {monitor = "gradient", alpha = 1}} end)
err_("dm.wave: unknown field 'beta' of adapt", "adapt key", function()
  dm.wave{N = 10, length = 1, periodic = false, dt = 0.1, adapt = {alpha = 1, beta = 2}} end)
err_("dm.wave: adapt must be a table", "adapt type", function()
  dm.wave{N = 10, length = 1, periodic = false, dt = 0.1, adapt = 2.385} end)
err_("dm.wave: adapt needs periodic = false", "periodic", function()
  dm.wave{N = 10, length = 1, periodic = true, dt = 0.1, adapt = {alpha = 1}} end)
err_("dm.wave: adapt moves the nodes of a grid", "mesh", function()
  dm.wave{mesh = M, dt = 0.1, adapt = {alpha = 1}} end)
err_("run: with adapt, state.u must be a function of x", "u values", function() A:run({u = dm.vec(101)}, {steps = 1}) end)
err_("run: with adapt, state.v must be a function of x", "v values", function()
  A:run({u = kink.u, v = dm.vec(101)}, {steps = 1}) end)
err_("run: state.u: r%-adaptive: the initial field fails at x = ", "u NaN", function()
  A:run({u = function(x) return x > 0 and 0 / 0 or 0 end}, {steps = 1}) end)
err_("x: adaptive nodes move", "x", function() A:x() end)
err_("dispersion: the relation is the still grid's", "dispersion", function() A:dispersion(1) end)
local trf, _, Xf, msg = dm.wave{N = 80, length = 40, x0 = -20, periodic = false, dt = 0.25,
  V = function(u) return 1 - dm.cos(u) end, adapt = {alpha = 4}}:run(
  {u = function(x) return 4 * math.atan(math.exp(3.2 * (x + 5))) end,
   v = function(x) local e = math.exp(3.2 * (x + 5)) return -4 * 3.2 * 0.95 * e / (1 + e * e) end}, {steps = 5})
T.ok(tostring(msg):find("^run: step 1 failed: r%-adaptive: ") and #trf == 1 and Xf:rows() == 1,
     "a failed step keeps the samples and says why: " .. tostring(msg))

T.done()
