-- ensemble.lua -- dm.ensemble from Lua: the table it returns, the thread
-- count never changing a bit, members equal to lone runs, Lua reduce
-- functions, parameter sweeps (a parameter-dependent mass), per-member
-- random generators, chaos indicators telling a chaotic Henon-Heiles orbit
-- from a regular one, failures and error messages, HDF5 files read back by
-- dmech, h5dump and h5py, dm.mpi without mpirun.
local T = require "dmech.test"
local dm = require "dmech"

local kep = dm.systems.kepler()
local I = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.01})
local function start(k) return {q = {0.5 + 0.004 * k, 0}, p = {0, 1.3}} end

local function same(a, b, cols)
  for _, c in ipairs(cols or a:names()) do
    local x, y = a:column(c), b:column(c)
    if #x ~= #y then return false end
    for i = 1, #x do
      if not (x[i] == y[i] or (x[i] ~= x[i] and y[i] ~= y[i])) then return false end
    end
  end
  return true
end

-- {==== the table ==========================================================
local r1 = dm.ensemble{integrator = I, members = 30, threads = 1, run = {t = 3},
  states = start, reduce = {"final", "megno"}, progress = false}
local r2 = dm.ensemble{integrator = I, members = 30, threads = 2, run = {t = 3},
  states = start, reduce = {"final", "megno"}, progress = false}
T.is(tostring(r1), "<Ensemble table: 30 members (t, x, y, p_x, p_y, megno, status) Kepler (Cartesian) "
     .. "(gauss s=2 h=0.01)>", "tostring: members, columns, system and method")
T.ok(same(r1, r2), "threads = 1 and 2 give the same table bit for bit")
T.is(#r1, 30, "one row per member")
T.ok(r1[7].t == 3 and r1[7].status == 0 and r1[7].megno > 0, "a row: t reached, status, megno")
local m = r1:meta()
T.ok(m.members == 30 and m.method == "gauss" and m.stages == 2 and m.h == 0.01 and m.steps == 300
     and m.reduce == "final,megno" and m.failed == 0 and m.system == "Kepler (Cartesian)",
     "metadata: members, method, h, steps, reduce, failed")
local listed = {}
for k = 1, 7 do listed[k] = start(k) end
local r3 = dm.ensemble{integrator = I, states = listed, run = {steps = 300}, threads = 2}
T.ok(#r3 == 7 and table.concat(r3:names(), ",") == "t,x,y,p_x,p_y,status",
     "states as a list; reduce defaults to final")
do
  local tr = I:run(start(7), {t = 3})
  local last = tr[#tr]
  T.ok(last.x == r3[7].x and last.y == r3[7].y and last.p_x == r3[7].p_x and last.p_y == r3[7].p_y,
       "member 7's final state is integ:run's, bit for bit")
  T.ok(math.abs(last.x - r1[7].x) < 1e-12 and last.x ~= r1[7].x,
       "with megno the steps also take Jacobians: the same orbit to the Newton tolerance")
end
-- }==========================================================================

-- {==== Lua reduce functions ===============================================
local function emax(tr, k)
  local E = tr:energy()
  local d = 0
  for i = 2, #E do d = math.max(d, math.abs(E[i] - E[1])) end
  return d, #tr + k
end
local u1 = dm.ensemble{integrator = I, members = 12, threads = 1, run = {t = 1, every = 10},
  states = start, reduce = emax, columns = {"emax", "n"}}
local u2 = dm.ensemble{integrator = I, members = 12, threads = 2, run = {t = 1, every = 10},
  states = start, reduce = emax, columns = {"emax", "n"}}
T.ok(same(u1, u2) and u1[3].n == 11 + 3 and u1[3].emax > 0 and u1[3].emax < 1e-8,
     "a reduce function over each member's trajectory (11 samples), the same for 1 and 2 threads")
local kept = {}
local u3 = dm.ensemble{integrator = I, members = 3, run = {steps = 20, every = 5}, states = start,
  reduce = function(tr, k) kept[k] = tr return {value = tr[#tr].x} end}
T.ok(#kept[2] == 5 and kept[2][5].x == u3[2].value and kept[2]:meta().status == 0,
     "a table result; the member's trajectory can be kept")
T.error_like(function() dm.ensemble{integrator = I, members = 3, run = {steps = 2}, states = start,
  reduce = function() return 1, 2 end} end,
  "dm.ensemble: reduce of member 1 returned 2 values; columns names 1", "a count mismatch names the member")
T.error_like(function() dm.ensemble{integrator = I, members = 3, run = {steps = 2}, states = start,
  reduce = function(tr, k) if k == 2 then error("boom at " .. k) end return 0 end} end,
  "boom at 2", "an error in the reduce function comes through")
-- }==========================================================================

-- {==== parameter sweeps ===================================================
local osc = dm.system{name = "oscillator", coords = {"q"}, params = {m = 1, k = 1},
  L = function(q, v, p) return 0.5 * p.m * v.q^2 - 0.5 * p.k * q.q^2 end}
local V = dm.integrator(osc, {method = "trapezoid", h = 0.05})
local sw = dm.ensemble{integrator = V, members = 4, threads = 2, run = {steps = 200},
  states = function() return {q = {0.7}, v = {0.3}} end,
  params = function(k) return {m = 1 + 0.5 * k} end}
local ok = true
for k = 1, 4 do
  osc.params.m = 1 + 0.5 * k
  local tr = V:run({q = {0.7}, v = {0.3}}, {steps = 200})
  ok = ok and tr:column("q")[#tr] == sw:column("q")[k] and tr:column("p_q")[#tr] == sw:column("p_q")[k]
end
osc.params.m = 1
T.ok(ok, "params: each member runs with its own mass (p from v with it), as a lone run, bit for bit")
T.ok(osc.params.m == 1 and sw:meta()["param.m"] == 1, "the system's own parameters are untouched")
T.error_like(function() dm.ensemble{integrator = V, members = 2, run = {steps = 2},
  states = {{q = {1}, v = {0}}, {q = {1}, v = {0}}}, params = {{mass = 2}, {m = 1}}} end,
  "params of member 1: no parameter mass in system 'oscillator' %(parameters: k, m%)", "unknown parameter")
-- }==========================================================================

-- {==== random starts ======================================================
local function noisy(k, rng) return {q = {1 + rng:gaussian(0.01), 0}, p = {0, 1 + rng:gaussian(0.01)}} end
local g1 = dm.ensemble{integrator = I, members = 20, threads = 1, seed = 2385, run = {steps = 10},
  states = noisy}
local g2 = dm.ensemble{integrator = I, members = 40, threads = 2, seed = 2385, run = {steps = 10},
  states = noisy}
local g3 = dm.ensemble{integrator = I, members = 20, threads = 2, seed = 2386, run = {steps = 10},
  states = noisy}
T.ok(g1[17].x == g2[17].x and g1[17].p_y == g2[17].p_y,
     "a member's random start depends on (seed, k) only: not on threads or member count")
T.ok(g1[17].x ~= g3[17].x and g1[16].x ~= g1[17].x, "another seed, another member: other numbers")
local rng = dm.rng(7)
local u, z, i = rng:uniform(2, 3), rng:gaussian(), rng:integer(6)
T.ok(u >= 2 and u < 3 and z == z and i >= 1 and i <= 6 and math.type(i) == "integer", "dm.rng methods")
T.error_like(function() dm.rng(-1) end, "seed in 0 .. 2^32%-1 expected", "dm.rng seed range")
-- }==========================================================================

-- {==== chaos indicators ===================================================
-- Henon-Heiles at E = 1/8 from x = 0, p_y = 0: y0 = -0.23 is chaotic, 0.19 regular
local hh = dm.system{name = "Henon-Heiles", coords = {"x", "y"},
  L = function(q, v) return 0.5 * (v.x^2 + v.y^2) - 0.5 * (q.x^2 + q.y^2) - q.x^2 * q.y + q.y^3 / 3 end}
local H = dm.integrator(hh, {method = "gauss", stages = 2, h = 0.05})
local y0 = {-0.23, 0.19}
local ch = dm.ensemble{integrator = H, members = 2, run = {t = 500}, reduce = {"megno", "fli", "lyapunov"},
  states = function(k)
    local y = y0[k]
    return {q = {0, y}, p = {math.sqrt(2 * (0.125 - 0.5 * y^2 + y^3 / 3)), 0}}
  end}
local c, r = ch[1], ch[2]
T.ok(c.megno > 8 and math.abs(c.megno - c.lyapunov * 500 / 2) < 0.3 * c.megno,
     ("chaotic orbit: MEGNO %.1f ~ lambda t / 2 = %.1f"):format(c.megno, c.lyapunov * 250))
T.ok(r.megno > 1 and r.megno < 2.5 and r.fli < c.fli / 4,
     ("regular orbit: MEGNO %.2f near 2, FLI %.1f << %.1f"):format(r.megno, r.fli, c.fli))
-- }==========================================================================

-- {==== failures ============================================================
local res, msg = dm.ensemble{integrator = I, members = 6, threads = 2, run = {steps = 50},
  states = function(k) if k == 4 then return {q = {1e-3, 0}, p = {0, 0}} end return start(k) end}
T.like(msg, "^dm%.ensemble: 1 of 6 members failed %(the first: member 4: step %d+ of 50 from t = ",
       "the second value names the failing member")
T.ok(res[4].status == 3 and res[4].t < 0.5 and res[3].status == 0 and res[5].t == 0.5
     and res:meta().failed == 1
     and res:meta()["failure.4"]:match("^member 4: "), "its row: status and time reached; the others are kept")
local ur = dm.ensemble{integrator = I, members = 5, threads = 2, run = {steps = 50, every = 5},
  states = function(k) if k == 4 then return {q = {1e-3, 0}, p = {0, 0}} end return start(k) end,
  reduce = function(tr) return tr:meta().status, #tr end, columns = {"run_status", "samples"}}
T.ok(ur[4].run_status == 3 and ur[4].status == 3 and ur[4].samples >= 1 and ur[4].samples < 11
     and ur[3].run_status == 0 and ur[3].samples == 11,
     "a reduce function sees a failed member's partial trajectory and its status")
-- }==========================================================================

-- {==== errors ==============================================================
local function E(opts, pattern, name) T.error_like(function() dm.ensemble(opts) end, pattern, name) end
E({integrator = I, members = 2, states = start, run = {t = 1}, thread = 2},
  "dm.ensemble: unknown option thread %(known: integrator, members, ", "unknown option")
E({members = 2, states = start, run = {t = 1}}, "dm.ensemble: integrator = %(a dm.integrator%) is required",
  "no integrator")
E({integrator = kep, members = 2, states = start, run = {t = 1}},
  "dm.ensemble: integrator must be a dm.integrator, got system", "a system is not an integrator")
E({integrator = I, run = {t = 1}}, "states = %(a list of states, or a function", "no states")
E({integrator = I, states = start, run = {t = 1}}, "members = %(a count%) is required", "no members")
E({integrator = I, members = 3, states = {start(1)}, run = {t = 1}},
  "states lists 1 states for 3 members", "too few states")
E({integrator = I, members = 2, states = start}, "run = {t = %(final time%) | steps", "no run")
E({integrator = I, members = 2, states = start, run = {t = 1, steps = 3}}, "exactly one of t", "t and steps")
E({integrator = I, members = 2, states = start, run = {t = 1, every = 0}}, "run.every must be >= 1, got 0",
  "every")
E({integrator = I, members = 2, states = start, run = {t = 1}, reduce = {"final", "magno"}},
  "reduce%[2%]: unknown reducer magno %(built%-in: final, energy_error", "unknown reducer")
E({integrator = I, members = 2, states = start, run = {t = 1}, reduce = {"final", emax}},
  "reduce is either a list of built%-in reducers or one function", "mixed reduce")
E({integrator = I, members = 2, states = start, run = {t = 1}, columns = {"a"}},
  "columns names the values of a reduce function", "columns with built-ins")
E({integrator = I, members = 2, states = start, run = {t = 1}, distance = {"x"}},
  "distance applies to the min_distance reducer", "distance without min_distance")
E({integrator = I, members = 2, states = start, run = {t = 1}, reduce = {"min_distance"},
  distance = {"z"}}, "distance%[1%]: no coordinate z in system 'Kepler %(Cartesian%)' %(coordinates: x, y%)",
  "distance names coordinates")
E({integrator = I, members = 2, states = start, run = {t = 1}, threads = -1},
  "threads must be in 1 .. 4096", "threads")
E({integrator = I, members = 5, states = function(k) if k == 3 then error("no state " .. k) end
  return start(k) end, run = {t = 1}}, "no state 3", "an error in the states function comes through")
E({integrator = I, members = 2, states = function() return {q = {1, 0}} end, run = {t = 1}},
  "dm.ensemble: state of member 1: the state needs momenta p or velocities v besides q", "a bad state")
local cst = dm.integrator(dm.systems.spherical_pendulum_r3(), {method = "trapezoid", h = 0.01})
T.error_like(function() dm.ensemble{integrator = cst, members = 1, run = {steps = 2}, reduce = {"megno"},
  states = {{q = {1, 0, 0}, p = {0, 0, 0}}}} end, "megno, fli and lyapunov need the step Jacobian",
  "MEGNO of a constrained system")
-- }==========================================================================

-- {==== files ===============================================================
local dir = T.tmpdir("ensemble")
local f5 = dir .. "/r1.h5"
T.ok(r1:save(f5) == true, "save as HDF5")
local back, why = dm.load_trajectory(f5)
T.ok(back and same(r1, back) and back:meta().reduce == "final,megno" and tostring(back) == tostring(r1),
     "dm.load_trajectory reads it back bit for bit, metadata included" .. (why and ": " .. why or ""))
local csv = dir .. "/r1.csv"
r1:save(csv)
T.ok(same(dm.load_trajectory(csv), r1), "and from CSV")
local out = dir .. "/out.h5"
local r4 = dm.ensemble{integrator = I, members = 30, threads = 2, run = {t = 3}, states = start,
  reduce = {"final", "megno"}, output = out}
T.ok(same(dm.load_trajectory(out), r4), "output = file writes the table during the call")
local function found(prog) return os.execute("command -v " .. prog .. " >/dev/null 2>&1") end
if not found("h5dump") then
  T.skip("h5dump not installed (hdf5-tools)", 1)
else
  local p = io.popen("h5dump -d /megno -A 0 " .. f5 .. " 2>&1")
  local text = p:read("a")
  p:close()
  local first = text:match("%(0%): ([%d%.e%-]+)")
  T.ok(first and math.abs(tonumber(first) - r1[1].megno) < 1e-5 * r1[1].megno,
       "h5dump reads the megno dataset" .. (first and "" or ": " .. text))
end
local p, text
p = io.popen("/usr/bin/python3 -c 'import h5py, sys; f = h5py.File(sys.argv[1], \"r\"); "
  .. "print(repr(float(f[\"megno\"][4])), f.attrs[\"method\"].decode(), list(f.keys())[:2])' " .. f5 .. " 2>/dev/null")
text = p and p:read("a") or ""
if p then p:close() end
if text == "" then
  T.skip("python3 with h5py not installed", 1)
else
  T.is(text, ("%s gauss ['megno', 'p_x']\n"):format(string.format("%.17g", r1[5].megno):gsub("0+$", "")),
       "h5py reads datasets and attributes")
end
-- }==========================================================================

-- {==== dm.mpi without mpirun ===============================================
T.ok(dm.mpi.rank() == 0 and dm.mpi.size() == 1 and dm.mpi.barrier() == nil, "one process: rank 0 of 1")
local info = dm.mpi.info()
T.ok(type(info.built) == "boolean" and info.active == false and info.hdf5_version:match("^%d+%.%d+"),
     "dm.mpi.info: built, active, HDF5")
-- }==========================================================================

T.done()
