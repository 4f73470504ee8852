-- b5_compile.lua -- B5: what an interactive user waits for when defining a
-- system: dm.systems.<name>{} end to end (trace the Lua Lagrangian, derive
-- L_q, L_v and all second derivatives, compile to tapes, and with
-- native = "always" emit C, run the C compiler, dlopen, check against the
-- tape), for every system of the catalog; and the memory it takes.
-- Run by bench/bpeers.sh with XDG_CACHE_HOME pointing at an empty
-- directory, so the first native build of each system is a cold compile
-- and the later ones load the cached object.
--   dmech bench/b5_compile.lua
-- Times: tape builds and cached native builds in CPU seconds of this
-- process (os.clock); the cold native build in wall time (it runs the C
-- compiler as a child process), read with `date +%s%N` (a fork, ~1 ms).
local R = tonumber(os.getenv("BENCH_REPEAT") or "") or 5

local function wall()
  local p = io.popen("date +%s%N")
  local t = tonumber(p:read("l"))
  p:close()
  return t * 1e-9
end

local function median(t)
  local s = {}
  for i, x in ipairs(t) do s[i] = x end
  table.sort(s)
  local n = #s
  return n % 2 == 1 and s[(n + 1) // 2] or 0.5 * (s[n // 2] + s[n // 2 + 1])
end

local function status(key)
  local f = io.open("/proc/self/status")
  if not f then return nil end
  for line in f:lines() do
    local v = line:match("^" .. key .. ":%s*(%d+)")
    if v then f:close() return tonumber(v) end
  end
  f:close()
end

local names = {}
for k, v in pairs(dm.systems) do
  if type(v) == "function" then names[#names + 1] = k end
end
table.sort(names)

print("# B5 trace + derive + compile of the catalog systems (bench/b5_compile.lua)")
print(("# tape: median of %d builds (CPU ms); native cold: first build with an empty cache "
  .. "(wall ms, includes the C compiler; * = fell back to the tape); native warm: median of %d builds "
  .. "from the cache (CPU ms)"):format(R, R))
print(("%-30s %3s %3s %10s %12s %12s %9s"):format("system", "n", "m", "tape ms", "native cold",
  "native warm", "Lua KB"))
collectgarbage()
local rss0, lua0 = status("VmRSS"), collectgarbage("count")
local rows = {}
for _, name in ipairs(names) do
  local ok, err = pcall(function()
    local t = {}
    local sys
    dm.config.native = "never"
    for i = 1, R do
      local t0 = os.clock()
      sys = dm.systems[name]{}
      t[i] = os.clock() - t0
    end
    local tape = median(t)
    dm.config.native = "always"
    local w0 = wall()
    local okn, s2 = pcall(dm.systems[name], {})
    local isnative = okn and s2.native
    local cold = wall() - w0
    local warm = {}
    if okn then
      for i = 1, R do
        local w1 = os.clock()
        dm.systems[name]{}
        warm[i] = os.clock() - w1
      end
    end
    dm.config.native = "auto"
    local n = sys.n
    rows[#rows + 1] = {name = name, n = n, tape = tape, cold = okn and cold or nil,
      warm = okn and median(warm) or nil}
    print(("%-30s %3s %3s %10.2f %12s %12s %9.0f"):format(name, tostring(n), tostring(sys.m or 0),
      1e3 * tape, okn and ("%.1f"):format(1e3 * cold) .. (isnative and "" or "*") or "failed",
      okn and ("%.2f"):format(1e3 * median(warm)) or "-", collectgarbage("count")))
  end)
  if not ok then print(("%-30s error: %s"):format(name, tostring(err))) end
end
collectgarbage()
print(("# memory: VmRSS %s KB before the catalog builds, %s KB after (peak VmHWM %s KB); "
  .. "Lua heap %.0f KB -> %.0f KB"):format(tostring(rss0), tostring(status("VmRSS")),
  tostring(status("VmHWM")), lua0, collectgarbage("count")))
