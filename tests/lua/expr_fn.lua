-- expr_fn.lua -- dm.fn: compiled functions, parameters changed after
-- compiling, vector and matrix outputs, batch evaluation, native code.
local T = require "dmech.test"
local dm = require "dmech"

local x, y = dm.syms "x y"
local k = dm.param "k"
local e = k * dm.sin(x) * y^2 + dm.exp(-x*y)

dm.config.native = "never"
local f = dm.fn{inputs = {x, y}, outputs = e, params = {k = 2.385}}
local function ref(xv, yv, kv) return kv * math.sin(xv) * yv^2 + math.exp(-xv*yv) end
T.near(f(0.7, 1.3), ref(0.7, 1.3, 2.385), 1e-15, "scalar output, numbers in")
T.near(f{0.7, 1.3}, ref(0.7, 1.3, 2.385), 1e-15, "a table of inputs")
T.near(f(dm.vec{0.7, 1.3}), ref(0.7, 1.3, 2.385), 1e-15, "a vec of inputs")
f:set_param("k", -0.75)
T.near(f(0.7, 1.3), ref(0.7, 1.3, -0.75), 1e-15, "parameter changed after compiling")
T.is(f:param("k"), -0.75, "param reads back")
T.is(f:params().k, -0.75, "params() copies")
local st = f:stats()
T.ok(st.instructions > 0 and st.inputs == 2 and st.outputs == 1 and st.native == false,
     "stats: tape with native = never")
T.ok(tostring(f):match("^<fn 2 inputs %-> 1 outputs, %d+ instructions, tape>$"), "tostring")

-- vector and matrix outputs
local g = dm.fn{inputs = {"x", "y"}, outputs = e:grad{x, y}, params = {k = 2.385}}
local gv = g(0.7, 1.3)
T.is(#gv, 2, "list of outputs gives a vec")
local h = 1e-6
T.near(gv[1], (ref(0.7 + h, 1.3, 2.385) - ref(0.7 - h, 1.3, 2.385)) / (2*h), 1e-8, "gradient value")
local Hf = dm.fn{inputs = {x, y}, outputs = e:hessian{x, y}, params = {k = 2.385}}
local Hm = Hf(0.7, 1.3)
T.is(#Hm, 2, "a list of lists gives a mat")
T.is(Hm[1][2], Hm[2][1], "the Hessian matrix is symmetric")

-- batch evaluation agrees with single calls
local pts = {}
for i = 1, 100 do pts[i] = {0.01 * i, 1 - 0.005 * i} end
local B = g:batch(pts)
local worst = 0
for i = 1, 100 do
  local one = g(pts[i])
  worst = math.max(worst, math.abs(B[i][1] - one[1]), math.abs(B[i][2] - one[2]))
end
T.is(worst, 0, "batch of 100 points = single evaluations")

-- NaN propagation
local sq = dm.fn{inputs = {x}, outputs = dm.sqrt(x) + 1}
local nan = sq(-2.385)
T.ok(nan ~= nan, "sqrt of a negative gives NaN, not an error")

-- native code, when a C compiler works
local r1, th1, r2, th2 = dm.syms "r1 th1 r2 th2"
local vr1, vth1, vr2, vth2 = dm.syms "vr1 vth1 vr2 vth2"
local function vel(r, th, vr, vth, l)
  return vr*dm.cos(th) - r*dm.sin(th)*vth, vr*dm.sin(th) + r*dm.cos(th)*vth,
         r*vr/dm.sqrt(l^2 - r^2)
end
local a1, b1, c1 = vel(r1, th1, vr1, vth1, 1)
local a2, b2, c2 = vel(r2, th2, vr2, vth2, 1.2)
local L = 0.5*(a1^2 + b1^2 + c1^2) + 0.75*((a1 + a2)^2 + (b1 + b2)^2 + (c1 + c2)^2)
          + 9.81*dm.sqrt(1 - r1^2) + 1.5*9.81*(dm.sqrt(1 - r1^2) + dm.sqrt(1.44 - r2^2))
local vars = {r1, th1, r2, th2, vr1, vth1, vr2, vth2}
local outs = {L}
for _, gi in ipairs(L:grad(vars)) do outs[#outs + 1] = gi end
for _, row in ipairs(L:hessian(vars)) do for _, hij in ipairs(row) do outs[#outs + 1] = hij end end
local tape = dm.fn{inputs = vars, outputs = outs, native = "never"}
dm.config.native = "auto"
local ok, nat = pcall(dm.fn, {inputs = vars, outputs = outs, native = "always"})
if ok then
  T.ok(nat:stats().native, "native = always gives native code")
  local p = {0.6, 0.3, 0.5, 1.1, 0.2, -0.4, 0.3, 0.7}
  local a, b = tape(p), nat(p)
  local w = 0
  for i = 1, #a do w = math.max(w, math.abs(a[i] - b[i]) / math.max(1e-300, math.abs(a[i]))) end
  T.ok(w <= 1e-15, "double spherical pendulum L + gradient + Hessian: native = tape (" .. w .. ")")
  T.diag("tape: " .. tape:stats().instructions .. " instructions")
else
  T.skip("no C compiler: " .. tostring(nat))
  T.skip("no C compiler")
end
T.is(dm.fn{inputs = {x}, outputs = x + 1}:stats().native, false,
     "auto leaves small functions on the tape")
dm.config.native = "never"

T.done()
