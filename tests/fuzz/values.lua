-- values.lua -- what the fuzzer feeds dmech: a table of hostile values
-- (wrong types, NaN/Inf, huge/negative/zero sizes, malformed strings,
-- tables and functions that misbehave) and a pool of valid dmech objects of
-- every class, rebuilt identically for every replay.  Loaded by fuzz.lua
-- with dofile; returns {hostile = H, names = sorted names of H, pool = fn}.
local dm = require "dmech"

local H = {}
H.nil_ = nil
H["true"] = true
H["false"] = false
H.zero, H.negzero, H.one, H.minus1 = 0, -0.0, 1, -1
H.x2385, H.half, H.onehalf = 2.385, 0.5, 1.5
H.nan, H.inf, H.minf = 0 / 0, math.huge, -math.huge
H.big, H.tiny, H.denormal = 1e308, 1e-300, 5e-324
H.i31, H.m31, H.i53 = 2^31, -2^31, 2^53
H.maxint, H.minint = math.maxinteger, math.mininteger
H.size_big, H.size_huge = 100000000, 1e12
H.s_empty, H.s_x, H.s_t = "", "x", "t"
H.s_nan, H.s_num, H.s_big = "nan", "2.385", "1e999"
H.s_long = string.rep("a", 300)
H.s_utf8 = string.rep("\xc3\xa9", 200)
H.s_badutf8 = "\xff\xfe\xc3"
H.s_nul = "a\0b"
H.s_fmt = "%s%n%d%%"
H.s_nl = "x\ny"
H.s_quote = "'\"`@$(rm -rf)"
H.s_dots = "../x"
H.s_devnull, H.s_devfull = "/dev/null", "/dev/full"
H.s_nodir = "/nonexistent/dir/f.png"
H.s_png, H.s_csv, H.s_off = "f.png", "f.csv", "f.off"
H.s_method = "gauss"
H.s_colon = "gsl:"
H.t_empty = {}
H.t_nested = {{}}
H.t_nums = {1, 2, 3}
H.t_nan = {0 / 0, 1}
H.t_mixed = {1, "a", true}
H.t_map = {x = 1, y = 2.385}
H.t_holes = {1, nil, 3}
H.t_deep = {{{{{{{{{{1}}}}}}}}}}
H.t_big = (function() local t = {} for i = 1, 5000 do t[i] = i * 0.5 end return t end)()
H.t_state = {q = {1, 0}, v = {0, 1}}
H.t_badstate = {q = {0 / 0}, p = {"x"}}
H.t_opts = {method = "gauss", h = 0.1, steps = 3}
H.t_evil = setmetatable({}, {__index = function() error("evil __index") end,
  __len = function() error("evil __len") end, __tostring = function() error("evil __tostring") end,
  __pairs = function() error("evil __pairs") end})
H.t_selfref = (function() local t = {} t[1] = t t.x = t return t end)()
H.f_noop = function() end
H.f_error = function() error("boom from a callback") end
H.f_nan = function() return 0 / 0 end
H.f_echo = function(...) return ... end
H.f_table = function() return {1, 2} end
H.f_yield = function() return coroutine.yield(1) end
H.co = coroutine.create(function() end)
H.stdout = io.stdout

local names = {}
for k in pairs(H) do names[#names + 1] = k end
names[#names + 1] = "nil_"
table.sort(names)

-- Valid objects by class kind ("vec", "system", ...: the prefixes of the
-- documented names).  Each is built under pcall: an object that a later
-- change of the API breaks is reported and left out, not fatal.
local function pool()
  local P, K, failed = {}, {}, {}
  local function add(kind, name, f)
    local ok, v = pcall(f)
    if ok and v ~= nil then
      P[name] = v
      K[kind] = K[kind] or {}
      table.insert(K[kind], name)
    else
      failed[#failed + 1] = name .. ": " .. tostring(v)
    end
  end
  local ok_cfg = pcall(function() dm.config.native = "never" end)
  add("vec", "vec", function() return dm.vec{2.385, -1, 0.5} end)
  add("mat", "mat", function() return dm.mat{{2, 1}, {1, 3}} end)
  add("expr", "expr", function() local x = dm.sym "x" return dm.sin(x) * 2.385 + x^2 end)
  add("expr", "sym", function() return dm.sym "y" end)
  add("fn", "fn", function() local x = dm.sym "x" return dm.fn{inputs = {x}, outputs = {dm.exp(x) * x}} end)
  add("system", "kepler", function() return dm.systems.kepler() end)
  add("system", "osc", function()
    return dm.system{name = "osc", coords = {"x"}, params = {k = 2.385},
      L = function(q, v, p) return 0.5 * v.x^2 - 0.5 * p.k * q.x^2 end}
  end)
  add("system", "pendulum3", function() return dm.systems.spherical_pendulum_r3() end)
  add("system", "damped", function() return dm.systems.damped() end)
  add("integrator", "gauss", function() return dm.integrator(P.kepler, {method = "gauss", h = 0.1}) end)
  add("integrator", "verlet", function() return dm.integrator(P.kepler, {method = "trapezoid", h = 0.1}) end)
  add("integrator", "rk4", function() return dm.integrator(P.osc, {method = "rk4", h = 0.1}) end)
  add("integrator", "rattle", function() return dm.integrator(P.pendulum3, {method = "trapezoid", h = 0.05}) end)
  add("trajectory", "traj", function() return P.gauss:run({q = {1, 0}, v = {0, 1.1}}, {steps = 10}) end)
  add("trajectory", "traj_data", function()
    return dm.trajectory{t = {0, 1}, coords = {"a"}, q = {a = {1, 2}}, columns = {e = {3, 4}}, meta = {note = "x"}}
  end)
  add("system", "polar", function() return dm.systems.kepler_polar() end)
  add("routh", "red", function() return dm.routh(P.polar, {cyclic = {"theta"}, mu = 1.1}) end)
  add("integrator", "rgauss", function() return dm.integrator(P.red, {method = "gauss", h = 0.1}) end)
  add("trajectory", "rtraj", function() return P.rgauss:run({q = {1.2}, v = {0.1}}, {steps = 5}) end)
  add("discrete", "discrete", function() return P.red:discrete{method = "midpoint", h = 0.1} end)
  add("figure", "fig", function() return dm.figure{output = "fig.png"} end)
  add("mesh", "mesh", function() return dm.mesh.grid{n = 3} end)
  add("mesh", "disc", function() return dm.mesh.disc{n = 6} end)
  add("cochain", "cochain", function() return P.mesh:cochain(0, function(x, y) return x + 2.385 * y end) end)
  add("sparse", "sparse", function() return P.mesh:laplacian(0) end)
  add("G", "SO3", function() return dm.lie.SO3() end)
  add("G", "SE2", function() return dm.lie.SE2() end)
  add("g", "rot", function() return P.SO3:exp{0.1, 0.2, 2.385} end)
  add("S", "sphere", function() return dm.lie.sphere(2) end)
  if not ok_cfg then failed[#failed + 1] = "dm.config.native" end
  return P, K, failed
end

return {hostile = H, names = names, pool = pool}
