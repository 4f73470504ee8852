-- traj_errors.lua -- every argument and data error of the trajectory API
-- gives a clear message.
local T = require "dmech.test"
local dm = require "dmech"

local tr = dm.trajectory{t = {0, 0.5, 1}, coords = {"r", "theta"},
  q = {r = {2.385, 2.4, 2.5}, theta = {0, 0.1, 0.2}}}
local function err(pattern, name, f, ...)
  local args = table.pack(...)
  T.error_like(function() return f(table.unpack(args, 1, args.n)) end, pattern, name)
end

-- unknown columns name the column and list the available ones
err("bad argument #1 to 'column' %(no column 'rho' %(available: t, r, theta%)%)",
    "column(\"rho\")", function() return tr:column("rho") end)
err("no coordinate 'x' %(coordinates: r, theta%)", "traj.q.x", function() return tr.q.x end)
err("no coordinate 3 %(coordinates: r, theta%)", "traj.q[3]", function() return tr.q[3] end)
err("this trajectory stores no momentum %(p%) columns %(available: t, r, theta%)", "traj.p without p",
    function() return tr.p end)
err("this trajectory stores no velocity %(v%) columns", "traj.v without v", function() return tr.v end)
err("traj:energy%(%): no column 'energy' %(available: t, r, theta%); the integrator records",
    "energy() without the diagnostic", function() return tr:energy() end)
err("traj:momentum%(%): no column 'momentum_theta' %(available: t, r, theta%)",
    "momentum(\"theta\") without the diagnostic", function() return tr:momentum("theta") end)
err("traj:momentum%(%): the trajectory has no momentum column", "momentum() without any",
    function() return tr:momentum() end)
local two = dm.trajectory{t = {1}, columns = {momentum_a = {1}, momentum_b = {2}}}
err("the trajectory has several momentum columns", "momentum() with several", function() return two:momentum() end)

-- argument types
err("bad argument #1 to 'column' %(string expected, got table%)", "column({})", function() return tr:column({}) end)
err("bad argument #1 to 'column' %(string expected, got no value%)", "column()", function() return tr:column() end)
err("trajectory expected, got table", "column on a table", tr.column, {}, "r")
err("trajectory expected, got vec", "column on a vec", tr.column, dm.vec{1}, "r")
err("bad argument #1 to 'slice' %(number expected, got string%)", "slice(\"a\")", function() return tr:slice("a") end)
err("bad argument #1 to 'slice' %(number has no integer representation%)", "slice(1.5)",
    function() return tr:slice(1.5) end)
err("bad argument #3 to 'slice' %(positive stride expected, got 0%)", "slice stride 0",
    function() return tr:slice(1, 2, 0) end)
err("bad argument #3 to 'slice' %(positive stride expected, got %-2%)", "slice stride -2",
    function() return tr:slice(1, 2, -2) end)
err("bad argument #1 to 'names' %(invalid option 'z'%)", "names(\"z\")", function() return tr:names("z") end)
err("bad argument #1 to 'meta' %(string expected, got table%)", "meta({})", function() return tr:meta({}, 1) end)
err("bad argument #2 to 'meta' %(string or number expected, got table%)", "meta(k, {})",
    function() return tr:meta("k", {}) end)
err("bad argument #1 to 'meta' %(invalid metadata key 'a=b'", "meta key with =", function() return tr:meta("a=b", 1) end)
err("bad argument #1 to 'save' %(string expected, got table%)", "save({})", function() return tr:save({}) end)
err("bad argument #1 to '[%w.]*load_trajectory' %(string expected, got no value%)", "load_trajectory()",
    function() return dm.load_trajectory() end)
local ok, msg = tr:save("")
T.ok(ok == nil and msg == "save: empty file name", "save(\"\") -> nil, message")

-- dm.trajectory{...}
err("bad argument #1 to '[%w.]*trajectory' %(table expected, got no value%)", "trajectory()",
    function() return dm.trajectory() end)
err("field 't' missing", "no t", dm.trajectory, {})
err("field 't': vec or non%-empty table of numbers expected, got empty table", "empty t", dm.trajectory, {t = {}})
err("field 't': vec or non%-empty table of numbers expected, got string", "t a string", dm.trajectory, {t = "0"})
err("field 't': number expected at index 2, got string", "t with a string", dm.trajectory, {t = {1, "x"}})
err("field 'q.r': 2 values expected %(as many as t%), got 1", "short q column",
    dm.trajectory, {t = {1, 2}, q = {r = {1}}})
err("field 'q' missing: 'coords' names 1 coordinates", "coords without q", dm.trajectory, {t = {1}, coords = {"r"}})
err("field 'q.z' missing: every coordinate needs a column", "coords not in q",
    dm.trajectory, {t = {1}, coords = {"z"}, q = {r = {1}}})
err("field 'q': 2 columns for 1 coordinates", "q with an extra column",
    dm.trajectory, {t = {1}, coords = {"r"}, q = {r = {1}, s = {2}}})
err("field 'p.r' missing", "p without the coordinate", dm.trajectory, {t = {1}, q = {r = {1}}, p = {x = {1}}})
err("field 'coords': name 2 is number, string expected", "non-string coordinate name",
    dm.trajectory, {t = {1}, coords = {"r", 5}, q = {r = {1}}})
err("field 'columns': keys must be column names, got a number key", "array columns",
    dm.trajectory, {t = {1}, columns = {{1}}})
err("field 'columns.E': number expected at index 1, got boolean", "bad column value",
    dm.trajectory, {t = {1}, columns = {E = {true}}})
err("column 't' is a t column and cannot be replaced", "a column called t",
    dm.trajectory, {t = {1}, columns = {t = {1}}})
err("invalid coordinate name 'a b'", "coordinate name with a space",
    dm.trajectory, {t = {1}, q = {["a b"] = {1}}})
err("field 'meta.h': string or number expected, got table", "bad metadata value",
    dm.trajectory, {t = {1}, meta = {h = {}}})
err("field 'meta': invalid metadata key 'a=b'", "bad metadata key", dm.trajectory, {t = {1}, meta = {["a=b"] = 1}})
err("field 'columns': table expected, got number", "columns not a table", dm.trajectory, {t = {1}, columns = 3})

-- an empty trajectory has no columns to give
local empty = tr:slice(3, 1)
err("column 't': the trajectory has no samples", "column of an empty trajectory", function() return empty.t end)
T.is(empty[1], nil, "no samples to index")
T.done()
