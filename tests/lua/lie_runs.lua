-- lie_runs.lua -- systems on Lie groups through the core run driver and
-- the ensembles: the trajectory's named momenta (mu1.., xi1..), pieces and
-- progress never changing a bit, streaming to a sink and a CSV file, the
-- runaway test, strict early ends, and dm.ensemble on rigid bodies (the
-- same table for 1 and 2 threads, members equal to lone runs, reduce
-- functions with traj:group, the errors for what groups do not have).
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"   -- the tape: no compiler runs in this test

local SO3 = dm.lie.SO3()
local body = dm.system{space = SO3, name = "rigid body", params = {J1 = 1.3, J2 = 2.1, J3 = 3.4},
  L = function(R, Om, p) return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) end}
-- a fresh integrator for every run compared bit for bit: lgvi starts its
-- Newton solve from the previous step's solution
local function lgvi() return dm.integrator(body, {method = "lgvi", h = 0.05}) end
local I = lgvi()
local s0 = {g = SO3.exp{0.3, -0.2, 0.9}, mu = {0.7, 1.9, -0.4}}

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

T.group("the trajectory of a run on SO(3)", function()
  local tr = I:run(s0, {steps = 200, every = 10})
  T.is(#tr, 21, "samples at 0, 10, ..., 200")
  T.is(table.concat(tr:names(), ","), "t,R11,R12,R13,R21,R22,R23,R31,R32,R33,mu1,mu2,mu3,"
       .. "xi1,xi2,xi3,energy,momentum_1,momentum_2,momentum_3", "columns")
  local k = tr:kinds()
  T.ok(k.R23 == "q" and k.mu2 == "p" and k.xi3 == "v" and k.energy == "diag"
       and k.momentum_1 == "diag", "kinds: g is q, mu is p, xi is v")
  T.is(#tr.q, 9, "#traj.q: the 9 stored numbers")
  T.is(#tr.p, 3, "#traj.p: 3 momenta")
  T.near(tr.p.mu2, tr:column("mu2"), 0, "traj.p.mu2")
  T.near(tr.v[3], tr:column("xi3"), 0, "traj.v[3]")
  T.error_like(function() return tr.p.p_R11 end,
    "no column 'p_R11' %(momenta: mu1, mu2, mu3%)", "traj.p names the momenta")
  local smp = tr[21]
  T.ok(#smp.q == 9 and #smp.p == 3 and #smp.v == 3 and smp.mu1 == tr:column("mu1")[21],
       "a sample: q (9), p and v (3)")
  local m = tr:meta()
  T.ok(m.space == "SO3" and m.method == "lgvi" and m.h == 0.05 and m.order == 2
       and m.steps == 200 and m.status == 0 and m["param.J2"] == 2.1, "metadata of the run")
  -- the body velocity is J^-1 mu and the spatial momentum R mu
  local R = tr:group(21)
  T.near(tr:column("xi2")[21], tr:column("mu2")[21] / 2.1, 1e-15, "xi = J^-1 mu")
  T.near(dm.vec{tr:column("momentum_1")[21], tr:column("momentum_2")[21],
                tr:column("momentum_3")[21]},
         R * {tr:column("mu1")[21], tr:column("mu2")[21], tr:column("mu3")[21]}, 1e-15,
         "momentum_k = (R mu)_k")
  local sl = tr:slice(3, 21, 9)
  T.ok(#sl == 3 and same(sl, tr:slice(3, 21, 9)) and sl.p.mu3[2] == tr:column("mu3")[12],
       "slices keep the named momenta")
  local nm = I:run(s0, {steps = 20, momentum = false})
  T.ok(not table.concat(nm:names(), ","):find("momentum"), "momentum = false: no momentum columns")
  T.error_like(function() I:run(s0, {steps = 20, momentum = {"R11"}}) end,
    "run: option 'momentum' must be a boolean for a system on a group", "momentum by name")
end)

T.group("pieces, sinks, files, runaway", function()
  local a = lgvi():run(s0, {steps = 300, every = 7})
  local b = lgvi():run(s0, {steps = 300, every = 7, chunk = 13})
  T.ok(same(a, b), "a run in pieces of 13 steps is the run in one, bit for bit")
  local got, calls = {}, 0
  local c = lgvi():run(s0, {steps = 300, every = 7, sink = function(tr)
    calls = calls + 1
    for k = 1, #tr do got[#got + 1] = tr:column("mu2")[k] end
  end, sink_every = 10})
  T.ok(calls == 5 and #got == #a and got[44] == a:column("mu2")[44] and #c == 1,
       "a sink gets every sample in blocks; the trajectory keeps the last")
  local f = T.tmpdir("lie_runs") .. "/lie_stream.csv"
  lgvi():run(s0, {steps = 300, every = 7, sink = f, sink_every = 8})
  local l = dm.load_trajectory(f)
  T.ok(same(l, a), "streamed to a CSV file and read back: the same trajectory")
  T.ok(l:group(#l):dist(a:group(#a)) == 0 and l:meta("space") == "SO3", "traj:group after loading")
  -- a heavy top (lgvi's energy error ~3e-4 by t = 0.4 with h = 0.05)
  local top = dm.system{space = SO3, name = "heavy top",
    params = {J1 = 1.3, J2 = 2.1, J3 = 3.4, mgl = 2.9},
    L = function(R, Om, p)
      return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) - p.mgl * R[3][3]
    end}
  local It = dm.integrator(top, {method = "lgvi", h = 0.05})
  local st = {g = SO3.exp{0.5, 0, 0}, mu = {0.5, 0.2, 1.0}}
  local ok, msg = pcall(It.run, It, st, {steps = 50, max_energy_error = 1e-4, strict = true})
  T.ok(not ok and tostring(msg):find("run: the energy error |E %- E0| = 0%.000298.- exceeds "
       .. "max_energy_error = 0%.0001 x max%(1, |E0|%) at step 8 of 50 %(t = 0%.4%): the run "
       .. "diverged; the trajectory up to there is kept", 1, false),
       "the runaway test: " .. tostring(msg))
  local tr, m2 = It:run(st, {steps = 50, max_energy_error = 1e-4, warn = false})
  T.ok(#tr == 9 and tr:meta("status") ~= 0 and m2:find("^run: the energy error"),
       "without strict: the samples so far and a message")
end)

T.group("ensembles of rigid bodies", function()
  local function start(k) return {g = SO3.exp{0.1 * k, 0.2, -0.05 * k}, mu = {0.7, 1.9 - 0.1 * k, -0.4}} end
  local e1 = dm.ensemble{integrator = I, members = 9, threads = 1, states = start,
    run = {t = 5}, reduce = {"final", "energy_error", "min_distance"}, progress = false}
  local e2 = dm.ensemble{integrator = I, members = 9, threads = 2, states = start,
    run = {t = 5}, reduce = {"final", "energy_error", "min_distance"}, progress = false}
  T.ok(same(e1, e2), "threads = 1 and 2: the same table bit for bit")
  T.is(table.concat(e1:names(), ","), "t,R11,R12,R13,R21,R22,R23,R31,R32,R33,mu1,mu2,mu3,"
       .. "energy_error,min_distance,status", "the final state's columns: g and mu")
  local lone = lgvi():run(start(6), {t = 5})
  local last = lone[#lone]
  T.ok(e1[6].R12 == last.R12 and e1[6].mu3 == last.mu3 and e1[6].t == 5 and e1[6].status == 0,
       "member 6 ends where a lone run ends, bit for bit")
  T.ok(e1[6].energy_error > 0 and e1[6].energy_error < 1e-3, "energy error bounded: "
       .. e1[6].energy_error)
  T.near(e1[6].min_distance, math.sqrt(3), 1e-12, "min_distance over the 9 entries of R: |R| = sqrt 3")
  local function casimir(tr)
    local d = 0
    local n0 = tr:column("mu1")[1]^2 + tr:column("mu2")[1]^2 + tr:column("mu3")[1]^2
    for k = 1, #tr do
      d = math.max(d, math.abs(tr:column("mu1")[k]^2 + tr:column("mu2")[k]^2
                                + tr:column("mu3")[k]^2 - n0))
    end
    return d, tr:group(#tr):dist(tr:group(1))
  end
  local u1 = dm.ensemble{integrator = I, members = 6, threads = 1, states = start,
    run = {t = 5, every = 5}, reduce = casimir, columns = {"dcasimir", "turned"}}
  local u2 = dm.ensemble{integrator = I, members = 6, threads = 2, states = start,
    run = {t = 5, every = 5}, reduce = casimir, columns = {"dcasimir", "turned"}}
  T.ok(same(u1, u2), "a reduce function of each member's trajectory: 1 and 2 threads agree")
  T.ok(u1[4].dcasimir < 1e-13 and u1[4].turned > 0.1, "|mu|^2 conserved to "
       .. u1[4].dcasimir .. " in each member; traj:group works on members' trajectories")
  T.error_like(function() dm.ensemble{integrator = I, members = 2, states = start,
    run = {t = 1}, reduce = {"megno"}} end,
    "dm.ensemble: megno, fli and lyapunov need the step Jacobian in coordinates, which a "
    .. "configuration stored in 9 numbers with 3 velocities %(a system on a group%) does not have",
    "chaos indicators: refused with the reason")
  T.error_like(function() dm.ensemble{integrator = I, members = 2, states = start,
    run = {t = 1}, params = {{J1 = 1}, {J1 = 2}}} end,
    "dm.ensemble: params are not supported for a system on a group", "params refused")
  T.error_like(function() dm.ensemble{integrator = I, members = 2, run = {t = 1},
    states = function(k) return {g = SO3.identity()} end} end,
    "dm.ensemble: state of member 1: the state needs mu %(body momentum%) or xi", "a bad state")
end)

T.done()
