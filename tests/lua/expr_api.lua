-- expr_api.lua -- symbolic expressions from Lua: symbols, arithmetic with
-- numbers, printing, derivatives, substitution, evaluation, symbolic
-- vectors, tracing, inspection.
local T = require "dmech.test"
local dm = require "dmech"

local r, theta, z = dm.syms "r theta z"
T.is(tostring(0.5*(r^2 + z^2)), "0.5*(r^2 + z^2)", "printing with minimal parentheses")
T.is(tostring(-1/dm.sqrt(r^2 + z^2)), "-1/sqrt(r^2 + z^2)", "negative quotient")
T.is(tostring(dm.sin(theta)^2), "sin(theta)^2", "power of a function")
T.is(tostring(2 - r), "2 - r", "number - expr")
T.is(tostring(2 / r), "2/r", "number / expr")
T.is(tostring(2 ^ r), "2^r", "number ^ expr")
T.is(tostring(-(r - z)), "z - r", "-(r - z) = z - r")
T.is(tostring(r * 2.385), "2.385*r", "constants first in products")
T.is(tostring(0.1 + r * 0 + 0.2), "0.30000000000000004", "constant folding, shortest round-trip")
T.ok((r * z):equals(z * r), "hash-consing: r*z and z*r are one node")
T.ok((r + 0):equals(r) and (1 * r):equals(r) and (r - r):equals(dm.expr(0)),
     "identities x+0, 1*x, x-x")
T.is("L = " .. (r^2 / 2), "L = 0.5*r^2", "concatenation prints the expression")

-- numbers in, numbers out
T.is(dm.sin(0.5), math.sin(0.5), "dm.sin of a number is math.sin")
T.is(dm.atan2(1, -1), math.atan(1, -1), "dm.atan2 of numbers")
T.is(dm.lt(1, 2), true, "dm.lt of numbers is a boolean")
T.is(dm.select(dm.lt(3, 2), 10, 20), 20, "dm.select with a boolean condition")
T.ok(dm.isexpr(dm.sin(r)) and not dm.isexpr(1.5), "dm.isexpr")

-- derivatives
local V = -1/dm.sqrt(r^2 + z^2)
T.is(tostring((0.5*(r^2 + z^2)):diff(r)), "r", "d/dr of 0.5*(r^2 + z^2)")
T.is(tostring((dm.sin(theta)^2):diff(theta)), "2*sin(theta)*cos(theta)", "d/dtheta sin^2")
T.is(tostring((r^3):diff("r", 2)), "6*r", "second derivative by name")
T.near(V:diff(r):eval{r = 1.2, z = 0.5}, 1.2 / (1.2^2 + 0.25)^1.5, 1e-15,
       "dV/dr = r/R^3 numerically")
local g = V:grad{r, z}
T.is(#g, 2, "gradient has one entry per variable")
T.near(g[2]:eval{r = 1.2, z = 0.5}, 0.5 / (1.2^2 + 0.25)^1.5, 1e-15, "dV/dz")
local H = V:hessian{r, z}
T.ok(H[1][2]:equals(H[2][1]), "Hessian is symmetric (one shared node)")
local h = 1e-5
local fd = (g[1]:eval{r = 1.2, z = 0.5 + h} - g[1]:eval{r = 1.2, z = 0.5 - h}) / (2*h)
T.near(H[1][2]:eval{r = 1.2, z = 0.5}, fd, 1e-9, "Hessian entry against central differences")
local J = dm.jacobian({r*z, dm.exp(r)}, {r, z})
T.is(tostring(J[1][1]) .. " " .. tostring(J[1][2]) .. " " .. tostring(J[2][1]) .. " " .. tostring(J[2][2]),
     "z r exp(r) 0", "dm.jacobian")

-- substitution and evaluation agree
local e = dm.exp(-r) * dm.cos(theta * z) + r^2 / (1 + z^2)
local s = e:subs{r = theta^2 + 1, [z] = 2.385}
T.near(s:eval{theta = 0.7}, e:eval{r = 0.7^2 + 1, theta = 0.7, z = 2.385}, 1e-15,
       "subs then eval = eval at the substituted values")
T.is(tostring((r*z + r):subs{r = 2}), "2*z + 2", "subs a number simplifies")
local J2 = dm.param "J2"
local P = J2 / r^3
T.near(P:eval{J2 = 0.05, r = 2}, 0.05 / 8, 1e-16, "eval binds parameters by name")
T.near(P:eval{[J2] = 0.05, [r] = 2}, 0.05 / 8, 1e-16, "eval binds by expression")
local ok, nan = pcall(function() return dm.sqrt(r):eval{r = -2.385} end)
T.ok(ok and math.type(nan) == "float" and nan ~= nan,
     "sqrt of a negative evaluates (no error) to NaN: " .. tostring(nan))
T.ok(dm.sqrt(r):eval{r = 2.385} == math.sqrt(2.385), "sqrt of a positive is the C sqrt")
local nan2 = (dm.log(r) + r^2):eval{r = -2.385}
T.ok(nan2 ~= nan2, "NaN propagates through the rest of the expression")

-- symbolic vectors
local q = dm.symvec("q", {"r", "theta", "z"})
T.ok(q[2]:equals(q.theta) and q.theta:equals(theta), "q[2], q.theta and dm.sym 'theta' are one symbol")
T.is(#q, 3, "#q")
local v = dm.symvec("v", {"r", "theta", "z"}, "%s_dot")
T.is(tostring(v.theta), "theta_dot", "fmt names the symbols")
local x = dm.symvec("x", 3)
T.is(tostring(x[1] + x[3]), "x1 + x3", "dm.symvec(label, n)")
local pv = dm.paramvec("p", {"m", "k"})
T.is(pv.k:op(), "param", "dm.paramvec makes parameters")

-- tracing a Lua function of vectors
local L, tq, tv = dm.trace(function(q, v)
  local R = dm.sqrt(q.r^2 + q.z^2)
  return 0.5*(v.r^2 + q.r^2*v.theta^2 + v.z^2) + 1/R
end, {{"r", "theta", "z"}, {"r", "theta", "z", fmt = "%s_dot", label = "v"}})
T.is(tostring(L), "0.5*(r_dot^2 + r^2*theta_dot^2 + z_dot^2) + 1/sqrt(r^2 + z^2)",
     "traced Lagrangian")
T.ok(tq.z:equals(z) and tv.r:equals(dm.sym "r_dot"), "trace returns its symbolic arguments")
local pair = dm.trace(function(a) return {a[1]^2, 3} end, {2})
T.is(tostring(pair[1]) .. ", " .. tostring(pair[2]), "x1^2, 3", "trace of a list result; numbers become constants")
local pr = dm.trace(function(p) return p.mu * 2 end, {{"mu", kind = "param"}})
T.is(pr:args()[2]:op(), "param", "trace with parameter arguments")

-- piecewise
local pw = dm.select(dm.lt(r, 0), -r, r)
T.is(tostring(pw), "select(r < 0, -r, r)", "select prints")
T.is(pw:eval{r = -2.5}, 2.5, "select: first branch")
T.is(pw:eval{r = 1.5}, 1.5, "select: second branch")
T.is(tostring(pw:diff(r)), "select(r < 0, -1, 1)", "derivative of select")
T.is(tostring(dm.apply("atan2", z, r)), "atan2(z, r)", "dm.apply by name")

-- inspection
local m = r * dm.sin(z)
T.is(m:op(), "mul", "op")
T.ok(m:args()[1]:equals(r) and m:args()[2]:equals(dm.sin(z)), "args")
T.is((r^3):args()[2], 3, "args of an integer power: base and exponent")
T.is(r:name(), "r", "name")
T.is(dm.expr(2.385):value(), 2.385, "value of a constant")
T.is(r:value(), nil, "value of a symbol is nil")
local fv = (J2 * r + z):free()
T.is(#fv, 3, "free variables")
T.ok(m:depends(z) and not m:depends(theta) and m:depends{theta, r}, "depends")

T.done()
