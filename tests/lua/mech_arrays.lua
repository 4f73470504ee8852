-- mech_arrays.lua -- arrays of coordinates: dm.coords(name, n) in
-- dm.system's coords (alone or mixed with names), q.x[i] and v.x[i] in L,
-- states given by the array's name, trajectories and plots addressing the
-- elements by name and index (traj.q.x[i], column "x[i]"), the errors.
local T = require "dmech.test"
local dm = require "dmech"

local N = 6
local function chain(coords)
  return dm.system{name = "chain", coords = coords, params = {k = 1.3},
    L = function(q, v, p)
      local T0, V = 0, 0
      for i = 1, N do T0 = T0 + 0.5 * v.x[i]^2 end
      for i = 2, N do V = V + 0.5 * p.k * (q.x[i] - q.x[i - 1])^2 end
      return T0 - V - 0.25 * q.x[1]^4
    end}
end

local a = chain(dm.coords("x", N))
T.is(a.n, N, "dm.coords alone: n coordinates")
T.is(a.coords[3], "x[3]", "named x[i]")
T.like(tostring(dm.coords("x", N)), "coords x%[1..6%]", "tostring of an array")

local seen = {}
local s2 = dm.system{name = "mixed", coords = {"theta", dm.coords("x", N), dm.coords("y", 2)},
  L = function(q, v, p)
    seen.len, seen.flat, seen.named = #q.x, q[2], q["x[1]"]
    seen.y2 = q.y[2]
    return 0.5 * (v.theta^2 + v.x[N]^2 + v.y[1]^2) - dm.cos(q.theta) * q.x[1] * q.y[2]
  end}
T.is(s2.n, 1 + N + 2, "mixed: names and two arrays")
T.ok(seen.len == N and tostring(seen.flat) == "x[1]" and tostring(seen.named) == "x[1]" and
     tostring(seen.y2) == "y[2]", "in L: #q.x, q[k] over all coordinates, q[\"x[1]\"], q.y[2]")
T.like(tostring(s2.L), "v_x%[6%]", "the symbols print as x[i], v_x[i]")
T.like(tostring(s2), "^<system 'mixed': 9 coords %(theta, x%[1%.%.6%], y%[1%.%.2%]%); ",
       "tostring names an array once, x[1..n], not its n elements")
local nb = dm.systems.nbody{n = 12}
T.like(tostring(nb), "24 coords %(x%[1%.%.12%], y%[1%.%.12%]%), G=1 soft=0 m1=1 .* m6=1 %.%.%. %(14 parameters%)",
       "many parameters: the first 8 and their count")

-- states by the array's name, and flat
local I = dm.integrator(a, {method = "gauss", h = 0.01})
local x0 = {0.1, 0.2, -0.1, 0.3, 0.0, -0.2}
local r1 = I:run({q = {x = x0}, v = {x = {0, 0, 0, 0, 0, 0}}}, {steps = 200, every = 20})
local r2 = I:run({q = x0, v = {0, 0, 0, 0, 0, 0}}, {steps = 200, every = 20})
T.agree(r1, r2, {"x[1]", "x[6]", "p_x[3]"}, 0, "a state by the array's name = the flat list")
T.is(#r1.q.x, N, "#traj.q.x")
T.near(r1.q.x[4], r1:column("x[4]"), 0, "traj.q.x[4] is the column x[4]")
T.near(r1.p.x[2], r1:column("p_x[2]"), 0, "traj.p.x[2]")
T.near(r1.q.x[1][1], 0.1, 0, "its first sample is the start")
T.error_like(function() return r1.q.x[7] end, "index 7 out of range 1..6 for the array x",
             "an index past the array")
T.error_like(function() return r1.q.z end, "no coordinate 'z'", "no such array")

-- plots take the element columns
local png = os.tmpname() .. ".png"
local okp = pcall(dm.plot, {{r1, "t", "x[3]"}, output = png})
if okp then
  local f = io.open(png, "rb")
  T.ok(f ~= nil and f:read(4) == "\137PNG", "dm.plot{{traj, \"t\", \"x[3]\"}} writes a PNG")
  if f then f:close() end
  os.remove(png)
else
  T.skip("no gnuplot")
end

-- errors
T.error_like(function() dm.coords("1x", 3) end, "a name", "an array name must be a name")
T.error_like(function() dm.coords("x", 0) end, "1 to 1000000", "at least one coordinate")
T.error_like(function() chain({"x", dm.coords("x", N)}) end, "'x' is listed twice",
             "an array and a coordinate of one name")
T.error_like(function() chain({dm.coords("x", N), dm.coords("x", 2)}) end,
             "is listed twice", "two arrays of one name")
T.error_like(function() I:run({q = {x = {1, 2}}, v = {0, 0, 0, 0, 0, 0}}, {steps = 1}) end,
             "x must be a list of 6 numbers", "an array given with the wrong length")
T.done()
