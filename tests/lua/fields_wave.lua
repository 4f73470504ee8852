-- fields_wave.lua -- dm.wave from Lua: the grid integrator (dispersion,
-- a kink's speed and energy, the multisymplectic form formula), the DEC
-- integrator on a mesh (the linear wave's energy), the error texts.
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
err_("form_check: the multisymplectic form formula is checked on grids", "form_check on a mesh",
     function() D:form_check({u = function() return 0 end}, {}) end)
T.done()
