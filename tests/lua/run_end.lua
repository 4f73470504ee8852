-- run_end.lua -- nothing fails silently: a run that ends early records how
-- (tr.status, tr.message, print(tr)), warns on stderr, and with strict =
-- true (or dm.config.strict) raises instead; a reduced state remembers the
-- mu it was projected at and a run at another mu is an error.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"

local sys = dm.systems.kepler()
local I = dm.integrator(sys, {method = "gauss", stages = 2, h = 0.05})
local s0 = {q = {0.4, 0}, p = {0, 2}}

-- stderr through io.stderr: capture it
local function stderr_of(f, ...)
  local buf, real = {}, io.stderr
  io.stderr = {write = function(self, ...)
    for i = 1, select("#", ...) do buf[#buf + 1] = tostring((select(i, ...))) end
    return self
  end}
  local r = table.pack(pcall(f, ...))
  io.stderr = real
  return table.concat(buf), table.unpack(r, 1, r.n)
end

-- a run that diverges (energy error above max_energy_error) at its first step
local err, ok, tr, msg = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14})
T.ok(ok and tr and #tr == 2, "the partial trajectory is returned (2 samples)")
T.is(tr.status, "diverged", "tr.status says how it ended")
T.like(tr.message, "^the energy error |E %- E0| = .* exceeds max_energy_error = 1e%-14 .* at step 1 of 1000 %(t = 0%.05%)",
       "tr.message says where")
T.is(msg, "run: " .. tr.message, "and the second value is the same message")
T.like(tostring(tr), ", ended early: diverged>$", "print(tr) shows it")
T.like(err, "^warning: run ended early %(diverged%): the energy error", "a warning on stderr")
T.is(select(2, string.gsub(err, "\n", "")), 1, "one line")

local good = I:run(s0, {steps = 20})
T.is(good.status, "success", "a complete run: status success")
T.is(good.message, nil, "and no message")
T.ok(not tostring(good):find("ended early", 1, true), "print(tr) says nothing more")
T.is(dm.trajectory{t = {0, 1}}.status, nil, "a trajectory no run made has no status")

err, ok, tr = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14, warn = false})
T.ok(ok and tr.status == "diverged" and err == "", "warn = false: no warning")
err, ok, tr = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14, strict = true})
T.ok(not ok and tostring(tr):find("^run: the energy error") and err == "",
     "strict = true: an error instead: " .. tostring(tr))
dm.config.strict = true
err, ok, tr = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14})
T.ok(not ok and tostring(tr):find("^run: the energy error"), "dm.config.strict = true: an error")
err, ok, tr = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14, strict = false})
T.ok(ok and tr.status == "diverged", "strict = false overrides dm.config.strict")
dm.config.strict = nil
dm.config.warn = false
err, ok, tr = stderr_of(I.run, I, s0, {steps = 1000, max_energy_error = 1e-14})
T.ok(ok and err == "", "dm.config.warn = false: no warning")
dm.config.warn = nil
T.error_like(function() I:run(s0, {steps = 1, strict = "yes"}) end,
             "run: option 'strict' must be a boolean, got string", "strict must be a boolean")
T.error_like(function() I:run(s0, {steps = 1, warn = 0}) end,
             "run: option 'warn' must be a boolean, got number", "warn must be a boolean")

-- Lie group runs follow the same rules
local SO3 = dm.lie.SO3()
local body = dm.system{space = SO3, params = {J1 = 1, J2 = 2, J3 = 3},
  L = function(R, Om, p) return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) end}
local B = dm.integrator(body, {method = "lgvi", h = 0.05})
local ls = {g = SO3.identity(), mu = {1, 0.2, -0.5}}
err, ok, tr = stderr_of(B.run, B, ls, {steps = 10})
T.ok(ok and tr.status == "success" and err == "", "a Lie group run: success, no warning")
T.error_like(function() B:run(ls, {steps = 1, strict = 1}) end, "option 'strict' must be a boolean",
             "strict checked on Lie group runs too")

-- an ensemble with failed members says so on stderr as well
do
  local K = dm.integrator(sys, {method = "gauss", stages = 2, h = 0.01})
  local e2, okE, res, emsg = stderr_of(dm.ensemble, {integrator = K, members = 4, threads = 1, run = {t = 2},
    states = function(k) return {q = {k == 2 and 1e-3 or 1, 0}, p = {0, k == 2 and 0 or 1}} end,
    reduce = {"final"}})
  T.ok(okE and res and emsg and emsg:find("1 of 4 members failed", 1, true), "the ensemble keeps the table and says 1 of 4 failed")
  T.is(e2, "warning: " .. tostring(emsg) .. "\n", "and warns on stderr")
end

-- a reduced state remembers its mu
local red = dm.routh(dm.systems.j2_cylindrical{J2 = 0.05}, {cyclic = {"theta"}})
local rs, mu = red:project{q = {1.6, 0, 0}, v = {0, 0.5, 0.25}}
T.is(rs.mu, mu, "red:project's state carries its mu")
T.is(red.mu, mu, "and the reduction takes it")
local R = dm.integrator(red, {method = "gauss", stages = 2, h = 0.02})
T.is(#R:run(rs, {steps = 10}), 11, "a run at the projected mu")
red:set{mu = 2.385}
T.error_like(function() R:run(rs, {steps = 10}) end,
  "run: the state was projected at mu_theta = " .. dm.format_number(mu)
  :gsub("%p", "%%%0") .. " but the reduction's mu_theta is 2%.385: red:set{mu = ",
  "a run at another mu is an error that says how to go on")
T.error_like(function() R:step(rs) end, "step: the state was projected at mu_theta", "so is a step")
rs.mu = nil
T.is(#R:run(rs, {steps = 10}), 11, "without state.mu the shape state runs at the current mu")
rs.mu = "x"
T.error_like(function() R:run(rs, {steps = 1}) end, "run: state.mu must be a number or a list of numbers, got string",
             "state.mu checked")
red:set{mu = mu}
rs.mu = mu
T.is(#R:run(rs, {steps = 5}), 6, "back at the projected mu")
T.done()
