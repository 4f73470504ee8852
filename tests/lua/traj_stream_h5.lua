-- traj_stream_h5.lua -- integ:run{sink = "file.h5"}: the HDF5 file written in
-- blocks during the run equals traj:save("file.h5") of the same run held in
-- memory, column by column bit for bit and in its metadata (steps, status);
-- an early end leaves the file complete up to the last sample, saying how
-- the run ended (status, message); a symbolic link stays a link, a FIFO is
-- refused and nothing is written where the file cannot be.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"

local dir = T.tmpdir("traj_stream_h5")
local sys = dm.systems.fpu{n = 6, beta = 1.3}
local I = dm.integrator(sys, {method = "gauss", h = 0.01})
local s0 = {q = {0.1, 0.2385, -0.1, 0.3, -0.2, 0.05}, v = {0, 0.1, 0, 0, 0, -0.07}}

-- every column bit for bit (string.format %a), then the metadata
local function same(a, b)
  local na, nb = a:names(), b:names()
  if #na ~= #nb or #a ~= #b then return false, ("%d x %d vs %d x %d"):format(#a, #na, #b, #nb) end
  for j, nm in ipairs(na) do
    if nb[j] ~= nm then return false, "column " .. j .. ": " .. nm .. " vs " .. nb[j] end
    local ca, cb = a:column(nm), b:column(nm)
    for k = 1, #ca do
      if ("%a"):format(ca[k]) ~= ("%a"):format(cb[k]) then
        return false, ("%s[%d]: %a vs %a"):format(nm, k, ca[k], cb[k])
      end
    end
  end
  local ma, mb = a:meta(), b:meta()
  for k, v in pairs(ma) do
    if mb[k] ~= v then return false, "meta " .. k .. ": " .. tostring(v) .. " vs " .. tostring(mb[k]) end
  end
  for k in pairs(mb) do
    if ma[k] == nil then return false, "meta " .. k .. " only in the stream" end
  end
  return true, ""
end

-- a whole run, blocks of 37 samples (the last one short)
local full = I:run(s0, {steps = 2000, every = 3})
full:save(dir .. "/saved.h5")
local last = I:run(s0, {steps = 2000, every = 3, sink = dir .. "/streamed.h5", sink_every = 37})
T.is(#last, 1, "the run returns the last sample only")
local a, b = dm.load_trajectory(dir .. "/saved.h5"), dm.load_trajectory(dir .. "/streamed.h5")
local ok, why = same(a, b)
T.ok(ok and #b == #full and #b > 600, ("streamed .h5 = traj:save(\".h5\") of the run in memory, %d samples bit for bit "):format(#b) .. why)
T.is(b:meta().steps, 2000, "the file says how many steps ran")
T.is(b.status, "success", "and that the run ended normally")

-- blocks of one sample and of more than the whole run give the same file
for _, k in ipairs{1, 5000} do
  I:run(s0, {steps = 2000, every = 3, sink = dir .. "/k.h5", sink_every = k})
  ok, why = same(a, dm.load_trajectory(dir .. "/k.h5"))
  T.ok(ok, "sink_every = " .. k .. ": the same file " .. why)
end

-- an early end (a radial Kepler fall: Newton fails at the collision, step
-- 112): the file is complete up to the last sample and says how it ended
local function K() return dm.integrator(dm.systems.kepler{}, {method = "gauss", h = 0.01}) end
local fall = {q = {1, 0}, v = {0, 0}}
local early = K():run(fall, {steps = 1000, warn = false})
early:save(dir .. "/early_saved.h5")
local tr, msg = K():run(fall, {steps = 1000, warn = false, sink = dir .. "/early.h5", sink_every = 10})
local e = dm.load_trajectory(dir .. "/early.h5")
T.ok(msg and msg:find("run: step 112 of 1000", 1, true), "the run ended early: " .. tostring(msg))
ok, why = same(dm.load_trajectory(dir .. "/early_saved.h5"), e)
T.ok(ok and #e == 112, ("an early end: the %d samples so far (12 blocks), as the run in memory "):format(#e) .. why)
T.is(e.status, "no convergence", "the file's status is the run's")
T.ok(e:meta().message and e:meta().message:find("did not converge", 1, true),
     "the file's message says why it ended")

-- a symbolic link stays a link; the file it points to is replaced
full:save(dir .. "/target.h5")
os.execute(("rm -f '%s/link.h5' '%s/fifo.h5'; ln -s target.h5 '%s/link.h5'"):format(dir, dir, dir))
I:run(s0, {steps = 30, sink = dir .. "/link.h5", sink_every = 4})
local p = io.popen(("test -L '%s/link.h5' && test -f '%s/target.h5' && echo link"):format(dir, dir))
local kind = p:read("l")
p:close()
T.is(kind, "link", "a symbolic link stays a link")
T.is(#dm.load_trajectory(dir .. "/target.h5"), 31, "the file it points to holds the run")

-- refused: a FIFO (an HDF5 file cannot be written through one), a missing directory
if os.execute(("mkfifo '%s/fifo.h5'"):format(dir)) then
  T.error_like(function() I:run(s0, {steps = 10, sink = dir .. "/fifo.h5"}) end,
               "run: sink: saving '.*fifo.h5'", "a FIFO is refused")
end
T.error_like(function() I:run(s0, {steps = 10, sink = dir .. "/no/such/dir.h5"}) end,
             "run: sink: saving .*cannot create", "a file that cannot be written")
local p2 = io.popen(("ls -a '%s' | grep -c tmp"):format(dir))
T.is(p2:read("l"), "0", "no temporary file left behind")
p2:close()

T.done()
