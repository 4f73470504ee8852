-- expr_compile.lua -- trace + differentiate + compile (tape) of the double
-- spherical pendulum through the Lua API, as a user pays for it: the
-- Lagrangian of doc/reduce.md §14 in cylindrical coordinates with the
-- bobs' Cartesian velocities written out, its gradient and full Hessian in
-- (q, v), compiled with dm.fn.  Every repetition uses fresh symbol names,
-- so nothing is reused from earlier ones.  Target: under 20 ms.
local dm = require "dmech"

local function L(q, v, p)
  local function vel(r, th, vr, vth, l)
    local c, s, w = dm.cos(th), dm.sin(th), dm.sqrt(l^2 - r^2)
    return vr*c - r*s*vth, vr*s + r*c*vth, r*vr/w, w
  end
  local a1, b1, c1, w1 = vel(q[1], q[2], v[1], v[2], p.l1)
  local a2, b2, c2, w2 = vel(q[3], q[4], v[3], v[4], p.l2)
  return 0.5*p.m1*(a1^2 + b1^2 + c1^2)
       + 0.5*p.m2*((a1 + a2)^2 + (b1 + b2)^2 + (c1 + c2)^2)
       + p.m1*p.g*w1 + p.m2*p.g*(w1 + w2)
end

local function once(k)
  local names = {"r1", "th1", "r2", "th2"}
  local t0 = os.clock()
  local Lx, q, v, p = dm.trace(L, {
    {names[1], names[2], names[3], names[4], fmt = "%s_" .. k, label = "q"},
    {names[1], names[2], names[3], names[4], fmt = "v%s_" .. k, label = "v"},
    {"m1", "m2", "l1", "l2", "g", fmt = "%s_" .. k, kind = "param", label = "p"}})
  local t1 = os.clock()
  local vars = {q[1], q[2], q[3], q[4], v[1], v[2], v[3], v[4]}
  local outs = {Lx}
  for _, g in ipairs(Lx:grad(vars)) do outs[#outs + 1] = g end
  for i, row in ipairs(Lx:hessian(vars)) do
    for j = i, #row do outs[#outs + 1] = row[j] end
  end
  local t2 = os.clock()
  local params = {}
  for _, n in ipairs{"m1", "m2", "l1", "l2", "g"} do params[n .. "_" .. k] = 1.0 end
  local f = dm.fn{inputs = vars, outputs = outs, params = params, native = "never"}
  local t3 = os.clock()
  return (t1 - t0) * 1e3, (t2 - t1) * 1e3, (t3 - t2) * 1e3, (t3 - t0) * 1e3, f:stats().instructions
end

local R = 21
local cols = {{}, {}, {}, {}}
local ninstr
for k = 1, R do
  local a, b, c, d, n = once(k)
  cols[1][k], cols[2][k], cols[3][k], cols[4][k], ninstr = a, b, c, d, n
end
local function median(t) table.sort(t) return t[(#t + 1) // 2] end
print(string.format("# double spherical pendulum through Lua (median of %d, CPU ms): " ..
  "trace %.3f, gradient + Hessian %.3f, compile %.3f, total %.3f ms (target < 20); " ..
  "%d instructions", R, median(cols[1]), median(cols[2]), median(cols[3]),
  median(cols[4]), ninstr))
