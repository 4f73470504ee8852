-- fields_schrodinger.lua -- dm.schrodinger from Lua: the Galerkin
-- Hamiltonian's levels, states from functions, runs of the three methods
-- (trajectory columns, metadata, the final wave), the density, the error
-- texts.
local T = require "dmech.test"
local dm = require "dmech"

local w = 16
local S = dm.schrodinger{K = 32, V = function(x) return 0.5 * w^2 * (x - math.pi)^2 end}
T.ok(S.K == 32 and S.modes == 65 and S.hbar == 1 and S.m == 1, "fields K, modes, hbar, m")
T.ok(tostring(S):match("^<schrodinger K=32 %(65 modes%)"), "tostring")
local E = S:energies()
T.ok(#E == 65 and math.abs(E[1] - 8) < 1e-10 and math.abs(E[4] - 56) < 1e-10, "levels w (n + 1/2)")
local g, E0 = S:eigenstate(0)
local d = g:diagnostics()
T.ok(math.abs(E0 - 8) < 1e-10 and math.abs(d.norm - 1) < 1e-12 and math.abs(d.energy - 8) < 1e-10
     and math.abs(d.x - math.pi) < 1e-12 and math.abs(d.p) < 1e-12, "the ground state: norm 1, energy w/2, centred")
local psi = S:wave(function(x) return (w/math.pi)^0.25 * math.exp(-0.5*w*(x - math.pi - 0.25)^2) end)
local dt = 0.5 * math.sqrt(3) / E[#E]
for _, m in ipairs{"milne", "cn", "exact"} do
  local tr, wend = S:run(psi, {method = m, dt = dt, t = 2 * math.pi / w, every = 10})
  local x = tr:column("x")
  T.ok(math.abs(x[#tr] - math.pi - 0.25) < 1e-5 and tr:meta().method == m and tr:meta().h == dt,
       string.format("%s: after one period <x> returns to pi + 0.25 (%.8f)", m, x[#tr] - math.pi))
  T.ok(math.abs(wend:diagnostics().x - x[#tr]) < 1e-14, m .. ": the final wave is the last sample")
end
T.is(table.concat(S:run(psi, {dt = 0.01, steps = 2}):names(), ","), "t,norm,energy,x,p", "columns")
local xs, rho = psi:density(256)
local s = 0
for k = 1, #rho do s = s + rho[k] * 2 * math.pi / 256 end
T.ok(#xs == 256 and math.abs(s - 1) < 1e-12, "the density integrates to the norm")
local re, im = psi:coefficients()
T.ok(#re == 65 and #im == 65, "65 coefficients")
local free = dm.schrodinger{K = 4}
T.ok(math.abs(free:energies()[9] - 8) < 1e-15, "V = 0: the largest level is K^2/2")
T.ok(dm.schrodinger{K = 2, V = 3}:energies()[1] == 3, "a constant V shifts the levels")

local function err(pattern, name, f) T.error_like(f, pattern, name) end
err("dm.schrodinger: unknown field 'k' %(fields: K, hbar, m, V, samples%)", "misspelt field",
    function() dm.schrodinger{k = 3} end)
err("dm.schrodinger: K must be in 0..4096", "K < 0", function() dm.schrodinger{K = -1} end)
err("dm.schrodinger: hbar and m must be finite and > 0", "m = 0", function() dm.schrodinger{m = 0} end)
err("dm.schrodinger: V must be a function of x or a number, got string", "V a string",
    function() dm.schrodinger{V = "x^2"} end)
err("dm.schrodinger: samples must be more than 4K = 16", "too few samples",
    function() dm.schrodinger{K = 4, V = 1, samples = 16} end)
err("dm.schrodinger: V must return finite numbers, got nil", "V returning nil",
    function() dm.schrodinger{K = 2, V = function(x) end} end)
err("run: dt must be a finite non%-zero number", "no dt", function() S:run(psi, {t = 1}) end)
err("run: give exactly one of steps", "steps and t", function() S:run(psi, {dt = 0.1, t = 1, steps = 3}) end)
err("run: method must be milne, cn or exact, got 'rk4'", "unknown method",
    function() S:run(psi, {dt = 0.1, t = 1, method = "rk4"}) end)
err("run: unknown option 'tt'", "misspelt run option", function() S:run(psi, {dt = 0.1, tt = 1}) end)
err("bad argument #1 to 'run' %(a wave of this Schrodinger integrator expected%)", "another's wave",
    function() free:run(psi, {dt = 0.1, steps = 1}) end)
err("bad argument #1 to 'eigenstate' %(state number 0 .. modes %- 1 expected%)", "state 65",
    function() S:eigenstate(65) end)
T.done()
