-- mech_memory.lua -- long runs in bounded memory: integ:run{sink = function
-- | "file.csv", sink_every = k} hands the samples over in blocks of k (the
-- blocks together are the samples of the same run without a sink) and
-- returns the last sample; the CSV written in pieces loads back as the
-- whole run; a sink's error stops the run with its message; the warning
-- before a run larger than dm.config.memory_limit; option errors.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"

local sys = dm.systems.fpu{n = 4, beta = 1}
local I = dm.integrator(sys, {method = "gauss", h = 0.01})
local s0 = {q = {0.1, 0.2, -0.1, 0.3}, v = {0, 0, 0, 0}}
local full = I:run(s0, {steps = 1000, every = 3})

-- a function: blocks of sink_every samples, in order
local got, sizes = {}, {}
local last = I:run(s0, {steps = 1000, every = 3, sink_every = 50, sink = function(tr)
  sizes[#sizes + 1] = #tr
  local E = tr:column("energy")
  for k = 1, #tr do got[#got + 1] = {tr.t[k], tr.q.x[3][k], tr.v.x[1][k], E[k]} end
end})
local same, E = #got == #full, full:column("energy")
for k = 1, #full do
  same = same and got[k][1] == full.t[k] and got[k][2] == full.q.x[3][k]
         and got[k][3] == full.v.x[1][k] and got[k][4] == E[k]
end
T.ok(same, "the blocks together are the samples of the run without a sink, bitwise")
T.ok(#sizes == 7 and sizes[1] == 50 and sizes[7] == #full - 300,
     "335 samples in blocks of 50: 6 full ones and the rest at the end")
T.ok(#last == 1 and last.t[1] == 10 and last.q.x[2][1] == full.q.x[2][#full],
     "the run returns the last sample only")

-- a CSV file: written in pieces, loads back as the whole run
local dir = T.tmpdir("mech_memory")
local f = dir .. "/fpu.csv"
local r = I:run(s0, {steps = 1000, every = 3, sink = f, sink_every = 7})
local back = dm.load_trajectory(f)
local eq = back and #back == #full
for k = 1, #full do
  eq = eq and back.t[k] == full.t[k] and back.q.x[4][k] == full.q.x[4][k] and back.p.x[1][k] == full.p.x[1][k]
end
T.ok(eq and #r == 1 and back:meta().method == "gauss", "sink = \"f.csv\": the file loads back as the whole run")

-- an early end keeps what was streamed
local g = dir .. "/early.csv"
local tr, msg = I:run(s0, {steps = 100000, max_energy_error = 1e-12, sink = g, sink_every = 3, warn = false})
back = dm.load_trajectory(g)
T.ok(msg and msg:find("exceeds max_energy_error") and back and #back == back.t[#back] / 0.01 + 1,
     "an early end (runaway): the file holds every sample up to it")

-- a sink's error stops the run: the trajectory so far and the message
local calls = 0
tr, msg = I:run(s0, {steps = 1000, sink_every = 100, warn = false, sink = function()
  calls = calls + 1
  if calls == 2 then error("no room left") end
end})
T.ok(tr and msg and msg:find("^run: step 199 of 1000 %(t = 1%.99%): the sink failed: .*no room left"),
     "a sink's error stops the run at the block that failed: " .. tostring(msg))

-- option errors
T.error_like(function() I:run(s0, {steps = 10, sink = 3}) end,
             "option 'sink' must be a function%(traj%) or a file name", "sink of the wrong type")
T.error_like(function() I:run(s0, {steps = 10, sink = f, sink_every = 0}) end,
             "sink_every must be >= 1, got 0", "sink_every < 1")
T.error_like(function() I:run(s0, {steps = 10, sink = dir .. "/no/such/dir.csv"}) end,
             "run: sink: saving .*cannot create", "a file that cannot be written")

-- the warning before a large run, on stderr
local exe = os.getenv("DMECH")
if exe then
  local code = [[dm.config.native = "never"; dm.config.memory_limit = 1e5
local I = dm.integrator(dm.systems.fpu{n = 4}, {h = 0.01})
I:run({q = {0, 0, 0, 0.1}, v = {0, 0, 0, 0}}, {steps = 2000})
I:run({q = {0, 0, 0, 0.1}, v = {0, 0, 0, 0}}, {steps = 2000, every = 100})
I:run({q = {0, 0, 0, 0.1}, v = {0, 0, 0, 0}}, {steps = 2000, sink = function() end, sink_every = 100})
I:run({q = {0, 0, 0, 0.1}, v = {0, 0, 0, 0}}, {steps = 2000, warn = false})
dm.config.warn = false
I:run({q = {0, 0, 0, 0.1}, v = {0, 0, 0, 0}}, {steps = 2000})]]
  local p = io.popen(exe .. " -e '" .. code .. "' 2>&1")
  local out = p:read("a")
  p:close()
  local _, count = out:gsub("warning:", "")
  T.ok(count == 1 and out:find("^warning: run: the trajectory will take 0%.21%d* MB %(2000 steps, every 1, 4 coordinates%), above dm%.config%.memory_limit"),
       "one warning, for the run that records every sample (none with warn = false): " .. out)
else
  T.skip("DMECH not set")
end
T.done()
