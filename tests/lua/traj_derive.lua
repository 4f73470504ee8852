-- traj_derive.lua -- derived columns computed by a Lua function (or any
-- callable) per sample: values, several columns at once, recomputation,
-- errors inside the function.
local T = require "dmech.test"
local dm = require "dmech"

local N = 10000
local t, r, th, z = {}, {}, {}, {}
for k = 1, N do
  local s = (k - 1) * 0.05
  t[k], r[k], th[k], z[k] = s, 2.385 + 0.1 * math.sin(s), 0.6 * s, 0.3 * math.cos(1.1 * s)
end
local tr = dm.trajectory{t = t, coords = {"r", "theta", "z"}, q = {r = r, theta = th, z = z}}

-- Cartesian positions from cylindrical coordinates
T.ok(rawequal(tr:derive("x", function(s) return s.r * math.cos(s.theta) end), tr),
     "derive returns the trajectory")
tr:derive({"y", "zz"}, function(s) return s.q[1] * math.sin(s.q[2]), s.q[3] end)
local x, y, zz = tr:column("x"), tr:column("y"), tr:column("zz")
local bad = 0
for k = 1, N, 7 do
  if x[k] ~= r[k] * math.cos(th[k]) or y[k] ~= r[k] * math.sin(th[k]) or zz[k] ~= z[k] then
    bad = bad + 1
  end
end
T.is(bad, 0, "derived x, y (two results) equal the formula bit for bit")
T.is(table.concat(tr:names("derived"), ","), "x,y,zz", "kind derived, in order")

-- a table or vec result for several names; a later column sees earlier ones
tr:derive({"rho", "rho2"}, function(s) return {math.sqrt(s.x ^ 2 + s.y ^ 2), s.r ^ 2} end)
T.near(tr:column("rho")[777], r[777], 1e-15, "rho = sqrt(x^2+y^2) = r (a table result; reads x, y)")
tr:derive({"a", "b"}, function(s) return dm.vec{s.t, -s.t} end)
T.ok(tr:column("b")[N] == -t[N], "a vec result")

-- recomputing replaces the column in place
tr:derive("x", function(s) return 2.385 end)
T.ok(tr:column("x")[5] == 2.385 and #tr:names() == 4 + 7, "derive again replaces the column")

-- any callable works (compiled dm.fn objects are callables)
local callable = setmetatable({}, {__call = function(self, s) return s.t * 2 end})
tr:derive("twice_t", callable)
T.is(tr:column("twice_t")[N], 2 * t[N], "a table with __call")

-- derived columns survive slicing and a save/load round trip
local dir = T.tmpdir("traj_derive")
local sl = tr:slice(100, 200, 10)
T.ok(sl:column("y")[3] == y[120], "slices keep derived columns")
assert(sl:save(dir .. "/d.csv"))
local back = assert(dm.load_trajectory(dir .. "/d.csv"))
T.ok(back:column("y") == sl:column("y") and back:kinds().y == "derived", "save/load keeps derived columns")
os.remove(dir .. "/d.csv")

-- errors inside f: the sample is named, nothing is added
local ncols = #tr:names()
T.error_like(function()
  tr:derive("w", function(s) if s.t > 1 then error("boom") end return 1 end)
end, "derive 'w': at sample 22 %(t = 1.05%): .*boom", "an error in f names the sample and time")
T.is(#tr:names(), ncols, "a failed derive adds nothing")
T.error_like(function() tr:derive("w", function(s) return "x" end) end,
  "derive 'w': at sample 1 %(t = 0%): result 1 is string %(number expected%)", "non-number result")
T.error_like(function() tr:derive({"u", "w"}, function(s) return 1 end) end,
  "the function returned 1 value %(2 numbers expected%)", "too few results")
T.error_like(function() tr:derive({"u", "w"}, function(s) return {1, "z"} end) end,
  "element 2 of the result is string %(number expected%)", "bad table result")
T.error_like(function() tr:derive("u", function(s) return nil end) end,
  "result 1 is nil %(number expected%)", "nil result")
T.error_like(function() tr:derive("w", function(s) error({code = 7}) end) end,
  "^table", "a non-string error value propagates unchanged")
T.error_like(function() tr:derive("r", function(s) return 1 end) end,
  "bad argument #1 to 'derive' %(column 'r' is a q column and cannot be replaced%)",
  "q columns cannot be replaced")
T.error_like(function() tr:derive("bad name", function(s) return 1 end) end,
  "derive: invalid column name 'bad name'", "invalid column name")
T.error_like(function() tr:derive({"u", "u"}, function(s) return 1, 2 end) end,
  "column name 'u' is used twice", "duplicate names")
T.error_like(function() tr:derive(5, print) end,
  "bad argument #1 to 'derive' %(column name or non%-empty table of names expected, got number%)",
  "name must be a string or table")
T.error_like(function() tr:derive({}, print) end,
  "bad argument #1 to 'derive' %(column name or non%-empty table of names expected, got empty table%)",
  "empty name table")
T.error_like(function() tr:derive({"u", 3}, print) end,
  "bad argument #1 to 'derive' %(name 2 is number %(string expected%)%)", "non-string name")
T.error_like(function() tr:derive("u", 5) end,
  "bad argument #2 to 'derive' %(function expected, got number%)", "f must be callable")
T.error_like(function() tr:derive("u", function(s) return tr:derive("w", print) end) end,
  "at sample 1 %(t = 0%): .*already deriving columns of this trajectory", "no derive from inside derive")
T.error_like(function() tr:derive("u", function(s) getmetatable(tr).__close(tr) end) end,
  "cannot close a trajectory while derive runs over it", "no close from inside derive")
T.ok(tr:column("x")[1] == 2.385 and tr:slice(1, 1)[1].r == r[1], "the trajectory is intact afterwards")
T.is(#tr:names(), ncols, "no failed derive added a column")
T.done()
