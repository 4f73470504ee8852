-- mech_run.lua -- integ:run and integ:step: sampling (every, t=, a start
-- time), exact sample times, columns and metadata of the trajectory, the
-- energy and momentum diagnostics, chunked runs equal to one-piece runs
-- bit for bit, a Newton failure that keeps the partial trajectory and says
-- where it stopped, and the state forms {q, p} / {q, v}.
local T = require "dmech.test"
local dm = require "dmech"

local pol = dm.systems.kepler_polar()
local G2 = dm.integrator(pol, {method = "gauss", stages = 2, h = 0.05})
T.ok(tostring(G2):match("^<integrator gauss s=2 order 4 h=0.05 on 'Kepler %(polar%)' %(implicit, symplectic, symmetric%)>$"),
     "tostring(integ) is one line")
T.ok(G2.h == 0.05 and G2.method == "gauss" and G2.stages == 2 and G2.order == 4 and G2.symplectic
     and G2.variational and not G2.explicit and G2.system == pol, "integrator fields")
local s0 = {q = {0.4, 0}, p = {0, 0.8}, t = 2.385}

-- sampling
local tr = G2:run(s0, {steps = 1000, every = 7})
T.is(#tr, 144, "1000 steps every 7: samples at 0, 7, ..., 994 and the last step (144)")
local t = tr:column("t")
T.ok(t[1] == 2.385 and t[2] == 2.385 + 7 * 0.05 and t[143] == 2.385 + 994 * 0.05 and t[144] == 2.385 + 1000 * 0.05,
     "sample times are exactly t0 + k h")
T.is(table.concat(tr:names(), ","), "t,r,theta,p_r,p_theta,v_r,v_theta,energy,momentum_theta",
     "columns: t, q, p, v, energy and the momentum of the cyclic coordinate")
local meta = tr:meta()
T.ok(meta.system == "Kepler (polar)" and meta.method == "gauss" and meta.stages == 2 and meta.h == 0.05
     and meta.order == 4 and meta["param.mu"] == 1 and meta.steps == 1000 and meta.status == 0
     and meta.message == nil, "metadata: system, method, stages, h, order, parameters, how it ended")
T.ok(tostring(tr):find("Kepler %(polar%) %(gauss s=2 h=0.05%)"), "tostring(traj) shows system and method")
local Lth, E = tr:momentum("theta"), tr:energy()
local dL, dE = 0, 0
for k = 1, #tr do
  dL = math.max(dL, math.abs(Lth[k] - 0.8))
  dE = math.max(dE, math.abs(E[k] - E[1]))
end
T.ok(dL < 1e-14, ("momentum_theta = r^2 thetadot conserved: %.2g"):format(dL))
T.near(E[1], pol:energy{q = s0.q, p = s0.p}, 1e-15, "energy column = sys:energy at the sample")
T.ok(dE < 1e-4 and dE > 1e-9, ("energy bounded, not exact (%.3g) for Gauss 2 on Kepler e=0.6"):format(dE))
local last = tr[#tr]
local direct = dm.integrator(pol, {method = "gauss", stages = 2, h = 0.05})
local s = s0
for _ = 1, 1000 do s = direct:step(s) end
T.ok(math.abs(last.r - s.q[1]) < 1e-13 and math.abs(last.p_r - s.p[1]) < 1e-13 and math.abs(s.t - last.t) < 1e-10,
     "run = 1000 calls of step")

local tt = G2:run({q = {0.4, 0}, p = {0, 0.8}}, {t = 10, every = 10, h = 0.1})
T.ok(#tt == 11 and tt:column("t")[11] == 10 and tt:meta().h == 0.1, "t = 10 with h = 0.1 in the run options: 100 steps")
local t0 = G2:run(s0, {steps = 0})
T.ok(#t0 == 1 and t0:column("t")[1] == 2.385, "steps = 0 records the initial state")
local none = G2:run(s0, {steps = 10, energy = false, momentum = false})
T.is(table.concat(none:names(), ","), "t,r,theta,p_r,p_theta,v_r,v_theta", "energy = false, momentum = false")
local both = G2:run(s0, {steps = 10, momentum = {"r", "theta"}})
T.ok(both:momentum("r")[11] == both:column("p_r")[11], "momentum = {'r', 'theta'} adds both")

-- chunked runs (progress updates between pieces) record the same samples:
-- t, q and p bit for bit; v (and the energy computed from it) to round-off,
-- since each piece starts its first velocity solve from a zero guess
local function same(a, b)
  if #a ~= #b then return false end
  for _, c in ipairs(a:names()) do
    local x, y = a:column(c), b:column(c)
    local exact = not (c:match("^v_") or c == "energy")
    for k = 1, #a do
      if (exact and x[k] ~= y[k]) or math.abs(x[k] - y[k]) > 4e-16 * math.max(1, math.abs(x[k])) then
        return false
      end
    end
  end
  return true
end
local kep = dm.systems.kepler()
local k0 = {q = {0.4, 0}, p = {0, 2}}
for _, c in ipairs{{every = 7, chunk = 64}, {every = 1000, chunk = 64}, {every = 1000, chunk = 41}, {every = 100, chunk = 100},
                   {every = 3, chunk = 1}, {every = 5000, chunk = 3000}} do
  local I1 = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.01})
  local I2 = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.01})
  local a = I1:run(k0, {steps = 3001, every = c.every, progress = false})
  local b = I2:run(k0, {steps = 3001, every = c.every, chunk = c.chunk, progress = true})
  T.ok(same(a, b), ("chunked run (every %d, %d steps a piece) = one piece (%d samples)"):format(
       c.every, c.chunk, #a))
end

-- a Newton failure keeps the partial trajectory and says where it stopped
local big = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.8})
local apo = {q = {-1.6, 0}, p = {0, 0.5}}
local ptr, msg = big:run(apo, {steps = 100})
T.ok(ptr ~= nil and #ptr == 4 and ptr:column("t")[4] == 3 * 0.8, "Newton failure at step 4: the 4 samples before are returned")
T.ok(type(msg) == "string" and msg:find("^run: step 4 of 100 from t = 2.40*4? failed: Newton") and msg:find("residual")
     and msg:find("tol") and msg:find("trajectory up to there is kept"), "the message names step, time, residual and tolerance: " .. tostring(msg))
local ptr2, msg2 = big:run(apo, {steps = 100, every = 10})
T.ok(#ptr2 == 2 and ptr2:column("t")[2] == 3 * 0.8 and msg2:find("step 4 of 100"),
     "every = 10: the last good state (step 3) is kept as well")
local b3 = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.8}):run(apo, {steps = 3})
T.ok(b3:column("x")[4] == ptr:column("x")[4], "the last sample is the state after the last good step")
-- in pieces between progress updates the message still counts from the start
local ptr3, msg3 = big:run(apo, {steps = 100, every = 10, chunk = 2, progress = true})
T.ok(#ptr3 == 2 and msg3 == msg2, "chunk = 2: the same samples and message: " .. tostring(msg3))
T.ok(ptr2:meta().status > 0 and ptr2:meta().steps == 3 and ptr2:meta().message == msg2:sub(6),
     "the trajectory records how the run ended: status, steps, message (without 'run: ')")

-- runaway: a stiff quartic well at a huge step ends early instead of "succeeding"
local quartic = dm.system{name = "quartic", coords = {"q"}, L = function(q, v) return 0.5 * v.q^2 - 1e12 * q.q^4 / 4 end}
for _, m in ipairs{"gauss", "midpoint", "trapezoid", "rk4"} do
  local tq, mq = dm.integrator(quartic, {method = m, h = 100}):run({q = {1}, v = {0}}, {steps = 100})
  T.ok(#tq < 101 and type(mq) == "string" and mq:find("trajectory up to there is kept"),
       m .. ": L = v^2/2 - 1e12 q^4/4 at h = 100 ends early: " .. tostring(mq))
end
local unstable = dm.integrator(dm.systems.harmonic{omega = 1, impl = "c"}, {method = "trapezoid", h = 2.385})
local tu, mu = unstable:run({q = {1}, p = {0}}, {steps = 50, max_energy_error = 1e3})
T.ok(#tu == 5 and mu:find("^run: the energy error |E %- E0| = [%d.]+ exceeds max_energy_error = 1000 x max%(1, |E0|%) at step 4 of 50"),
     "max_energy_error: Stormer-Verlet beyond its stability limit stops at step 4: " .. tostring(mu))
T.ok(#unstable:run({q = {1}, p = {0}}, {steps = 50}) == 51, "without max_energy_error the same run completes")
T.error_like(function() unstable:run({q = {1}, p = {0}}, {steps = 5, max_energy_error = -1}) end,
             "run: max_energy_error must be a finite number >= 0", "a negative max_energy_error is refused")

local st, smsg = big:step(k0, 1.5)
T.ok(st == nil and smsg:find("^step: Newton"), "step: a Newton failure returns nil and a message: " .. tostring(smsg))

-- state forms
local sv = dm.integrator(kep, {method = "trapezoid", h = 0.01})
local a, b = sv:step{q = {0.4, 0}, v = {0, 2}}, sv:step{q = dm.vec{0.4, 0}, p = dm.vec{0, 2}}
T.ok(a.q[1] == b.q[1] and a.p[2] == b.p[2] and a.v[2] == a.p[2] and a.t == 0.01, "{q, v} and {q, p} states agree (unit mass)")
local c = sv:step({q = {x = 0.4, y = 0}, p = {x = 0, y = 2}}, -0.01)
T.ok(c.t == -0.01 and c.q[1] == a.q[1] and c.q[2] == -a.q[2], "named vectors, and h given to step() (backwards: the mirror image)")
sv.h = 0.02
T.ok(sv.h == 0.02 and sv:step(k0).t == 0.02, "integ.h can be set")
local stats = G2.stats
T.ok(stats.steps > 0 and stats.iters >= 1 and stats.tol > 0 and stats.iters_total >= stats.steps,
     "integ.stats: steps, iters, tol, iters_total")
T.ok(G2:reset() == G2 and G2.stats.steps == 0, "reset returns the integrator and clears the statistics")
T.done()
