-- traj_basic.lua -- Trajectory objects: construction from Lua data, columns,
-- samples, #, names, metadata, slicing, diagnostics, tostring, close.
local T = require "dmech.test"
local dm = require "dmech"

-- a Kepler-like orbit in polar coordinates, 401 samples
local N, h = 401, 0.05
local t, r, th, pr, pth, vr, vth, E, J = {}, {}, {}, {}, {}, {}, {}, {}, {}
for k = 1, N do
  local s = (k - 1) * h
  t[k] = s
  r[k] = 2.385 + 0.3 * math.sin(s)
  th[k] = 0.6 * s
  vr[k] = 0.3 * math.cos(s)
  vth[k] = 0.6
  pr[k] = vr[k]
  pth[k] = r[k] ^ 2 * vth[k]
  E[k] = 0.5 * (vr[k] ^ 2 + r[k] ^ 2 * vth[k] ^ 2) - 1 / r[k]
  J[k] = pth[k]
end
local tr = dm.trajectory{
  t = t, coords = {"r", "theta"},
  q = {r = r, theta = th}, p = {r = pr, theta = pth}, v = {r = dm.vec(vr), theta = vth},
  columns = {energy = E, momentum_theta = J, extra = dm.vec(r)},
  meta = {system = "Kepler (polar)", method = "gauss", stages = 2, h = h},
}

T.is(#tr, N, "#traj is the number of samples")
T.is(tostring(tr), "<Trajectory 401 samples t=[0, 20] Kepler (polar) (gauss s=2 h=0.05)>",
     "tostring: samples, time span, system, method")
T.is(table.concat(tr:names(), ","),
     "t,r,theta,p_r,p_theta,v_r,v_theta,energy,extra,momentum_theta",
     "column names: t, q, p_<q>, v_<q>, then extra columns sorted by name")
T.is(table.concat(tr:names("q"), ","), "r,theta", "names(\"q\") are the coordinates")
T.is(table.concat(tr:names("diag"), ","), "energy,momentum_theta",
     "energy and momentum_* columns are diagnostics")
local kinds = tr:kinds()
T.ok(kinds.t == "t" and kinds.p_r == "p" and kinds.v_theta == "v" and kinds.extra == "data",
     "kinds()")

-- columns are vec copies
local col = tr:column("r")
T.ok(getmetatable(col) == getmetatable(dm.vec{1}) and #col == N, "column is a vec of #traj numbers")
T.is(col[200], r[200], "column values exact")
col[1] = 99
T.is(tr:column("r")[1], r[1], "a column is a copy")
T.is(tr.t[N], (N - 1) * h, "traj.t")
T.is(tr.q.theta[17], th[17], "traj.q.theta")
T.is(tr.p.theta[33], pth[33], "traj.p.theta is the column p_theta")
T.is(tr.v.r[5], vr[5], "traj.v.r is the column v_r")
T.is(tr.q[2][9], th[9], "traj.q[i] by coordinate number")
T.is(#tr.q, 2, "#traj.q is the number of coordinates")
T.ok(tr:column("p_theta") == tr.p.theta, "column(\"p_theta\") equals traj.p.theta")
T.ok(tr:energy() == dm.vec(E), "traj:energy()")
T.ok(tr:momentum("theta") == dm.vec(J), "traj:momentum(\"theta\")")
T.ok(tr:momentum() == dm.vec(J), "traj:momentum() with one momentum column")
T.is(tr.nosuchfield, nil, "unknown fields are nil")

-- samples
local s = tr[10]
T.ok(s.t == t[10] and s.q[1] == r[10] and s.q[2] == th[10] and s.p[2] == pth[10]
     and s.v[1] == vr[10], "traj[k] = {t=, q=vec, p=vec, v=vec}")
T.ok(s.r == r[10] and s.p_theta == pth[10] and s.energy == E[10], "samples also carry every column by name")
T.is(tr[-1].t, t[N], "traj[-1] is the last sample")
T.is(tr[-N].t, 0, "traj[-#traj] is the first")
T.ok(tr[0] == nil and tr[N + 1] == nil and tr[-N - 1] == nil, "out-of-range samples are nil")
local count, last = 0, nil
for k, smp in ipairs(tr) do count, last = k, smp.t end
T.ok(count == N and last == t[N], "ipairs walks every sample")

-- metadata
local m = tr:meta()
T.ok(m.system == "Kepler (polar)" and m.method == "gauss" and m.stages == 2 and m.h == 0.05
     and math.type(m.stages) == "integer" and math.type(m.h) == "float",
     "meta(): strings as strings, numbers as numbers")
T.is(tr:meta("h"), 0.05, "meta(key)")
T.ok(rawequal(tr:meta("note", 2.385), tr), "meta(key, value) sets and returns traj")
T.is(tr:meta("note"), 2.385, "number metadata keeps every digit")
tr:meta("note", 1 / 3)
T.is(tr:meta("note"), 1 / 3, "1/3 stored exactly")
tr:meta("label", "2.385")
T.is(tr:meta("label"), "2.385", "a string that looks like a number stays a string")
tr:meta("label", nil)
tr:meta("note", nil)
T.is(tr:meta("note"), nil, "meta(key, nil) removes")

-- slicing (string.sub rules)
local a = tr:slice(11, 30)
T.ok(#a == 20 and a.t[1] == t[11] and a.t[20] == t[30], "slice(11, 30)")
local b = tr:slice(1, -1, 100)
T.ok(#b == 5 and b.t[5] == t[401] and b[2].q[1] == r[101], "slice(1, -1, 100): stride")
local c = tr:slice(-3)
T.ok(#c == 3 and c.t[1] == t[N - 2], "slice(-3): the last three")
T.is(#tr:slice(50, 10), 0, "i > j gives an empty trajectory")
T.is(tostring(tr:slice(50, 10)), "<Trajectory 0 samples Kepler (polar) (gauss s=2 h=0.05)>",
     "tostring of an empty trajectory")
T.is(#tr:slice(-1000, 1000), N, "out-of-range bounds are clamped")
T.ok(b:meta().system == "Kepler (polar)" and b:energy()[2] == E[101], "slices keep metadata and diagnostics")

-- a plain data table: no coordinates
local d = dm.trajectory{t = {0.5, 1.5}, columns = {x = {2.385, 1e-300}}}
T.ok(#d == 2 and d:column("x")[2] == 1e-300 and #d.q == 0, "columns only, no coordinates")
T.is(tostring(d), "<Trajectory 2 samples t=[0.5, 1.5]>", "tostring without metadata")
T.is(tostring(dm.trajectory{t = {3}}), "<Trajectory 1 sample t=[3, 3]>", "one sample")

-- to-be-closed and collected trajectories
do
  local x <close> = dm.trajectory{t = {1, 2}}
  d = x
end
T.is(tostring(d), "<Trajectory (closed)>", "closed by <close>")
T.error_like(function() return #d end, "attempt to use a closed trajectory", "# of a closed trajectory")
T.error_like(function() return d:column("t") end, "trajectory is closed", "method on a closed trajectory")
-- many short-lived trajectories are freed by __gc (make check-valgrind checks)
for _ = 1, 50 do dm.trajectory{t = t, q = {x = r}} end
collectgarbage(); collectgarbage()
T.done()
