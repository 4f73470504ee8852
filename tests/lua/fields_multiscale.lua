-- fields_multiscale.lua -- multiscale methods from Lua: dm.msfem (exact at
-- the nodes; linear elements are not), dm.fast_frequency, the method
-- "multiscale" through dm.integrator with its options, the error texts.
local T = require "dmech.test"
local dm = require "dmech"

local eps = 0.025
local a = function(y) return 10 / (1 + 0.95 * math.sin(2 * math.pi * y)) end
local f = function(x) return x * x end
local x, U = dm.msfem{a = a, f = f, eps = eps, N = 4}
T.ok(#x == 5 and x[3] == 0.5 and U[1] == 0 and U[5] == 0, "nodes and boundary values")
T.ok(math.abs(U[3] + 0.0035985842096029269) < 1e-12, string.format("u(0.5) exact: %.17g", U[3]))
local _, Ul = dm.msfem{a = a, f = f, eps = eps, N = 4, method = "linear"}
T.ok(math.abs(Ul[3] + 0.0035985842096029269) > 2e-3, "linear elements miss it by 2.6e-3")
local _, Up = dm.msfem{a = a, f = f, eps = eps, N = 4,
  Phi = function(x) return (x + 0.95 * eps * (1 - math.cos(2 * math.pi * x / eps)) / (2 * math.pi)) / 10 end}
T.ok(math.abs(Up[3] - U[3]) < 1e-15, "with Phi in closed form: the same nodal values")

local sp = dm.system{name = "stiff", coords = {"a", "theta"}, params = {k = 1e6},
  L = function(q, v, p) return 0.5*(v.a^2 + (1 + q.a)^2*v.theta^2) + 9.81*(1 + q.a)*dm.cos(q.theta) - 0.5*p.k*q.a^2 end}
local s0 = {q = {9.81*math.cos(0.5)/1e6 + math.sqrt(0.1/1e6), 0.5}, p = {0, 0}}
local w, c = dm.fast_frequency(sp, s0)
T.ok(math.abs(w / 1000 - 1) < 1e-4 and c == "a", string.format("fast frequency %.6f on a", w))
local M = dm.integrator(sp, {method = "multiscale", h = 0.05, omega = 1000, fast = "a"})
T.ok(M.symplectic and M.method == "multiscale", "multiscale: a symplectic method")
local tr = M:run(s0, {t = 3})
T.ok(math.abs(tr:column("theta")[#tr] + 0.4924250571123753) < 1e-7 and tr:column("t")[#tr] == 3,
     "k = 1e6, h = 0.05: theta(3) to 1e-7 of the resolved reference")
local Me = dm.integrator(sp, {method = "multiscale", h = 0.05})      -- omega and fast estimated
local te = Me:run(s0, {t = 3})
T.ok(math.abs(te:column("theta")[#te] + 0.4924250571123753) < 2e-7, "the same with omega estimated")

local function err(pattern, name, fn) T.error_like(fn, pattern, name) end
err("dm.msfem: N must be an integer in 3..1e6", "N = 2", function() dm.msfem{a = a, f = f, eps = eps, N = 2} end)
err("dm.msfem: a %(a function of y = x/eps%) and f %(a function of x%) are required", "no f",
    function() dm.msfem{a = a, eps = eps, N = 4} end)
err("dm.msfem: eps must be finite and > 0", "no eps", function() dm.msfem{a = a, f = f, N = 4} end)
err("dm.msfem: f must return a number, got string", "f returning a string",
    function() dm.msfem{a = a, f = function() return "x" end, eps = eps, N = 4} end)
err("dm.msfem: .*boom", "an error inside a", function() dm.msfem{a = function() error("boom") end, f = f, eps = eps, N = 4} end)
err("dm.msfem: a <= 0 %(a must be positive%) at y = 5", "a <= 0", function() dm.msfem{a = function() return -1 end, f = f, eps = eps, N = 4} end)
err("dm.msfem: unknown field 'n'", "misspelt field", function() dm.msfem{n = 4} end)
err("dm.msfem: method must be multiscale or linear, got quadratic", "unknown method",
    function() dm.msfem{a = a, f = f, eps = eps, N = 4, method = "quadratic"} end)
err("fast_frequency: the state needs q and p", "no p", function() dm.fast_frequency(sp, {q = {0, 0}}) end)
err("multiscale: fast = 'b' names no coordinate of 'stiff'", "unknown fast coordinate",
    function() dm.integrator(sp, {method = "multiscale", h = 0.05, omega = 1000, fast = "b"}):run(s0, {steps = 1}) end)
err("option 'omega' does not apply to method 'gauss'", "omega for gauss",
    function() dm.integrator(sp, {method = "gauss", omega = 3}) end)
T.done()
