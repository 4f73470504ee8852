-- b1_lua.lua -- B1 through the real program: per-step cost of dmech as a
-- user runs it (src/dmech, dm.system traced from Lua, dm.integrator,
-- integ:run with one sample at the end), in one run, side by side:
--   Kepler e = 0.6, Stormer-Verlet (trapezoid) h = 0.01
--   J2 Cartesian (J2 = 0.05), Gauss s = 2, h = 0.05
-- each on dm.systems.<name>{impl = "c"} (hand-written C system; ratio 1), dm.systems traced to
-- a tape (native = "never") and to native code (native = "always").
-- Median of BENCH_REPEAT (default 7) interleaved runs, steps calibrated to
-- ~0.15 s per run.  Usage: dmech bench/b1_lua.lua
local R = tonumber(os.getenv("BENCH_REPEAT") or "") or 7
local TARGET = tonumber(os.getenv("BENCH_B1_SEC") or "") or 0.15

local function machine()
  local model = "?"
  local f = io.open("/proc/cpuinfo")
  if f then
    for line in f:lines() do
      local m = line:match("^model name%s*:%s*(.*)")
      if m then model = m break end
    end
    f:close()
  end
  print("# B1 through src/dmech (bench/b1_lua.lua): dm.system / dm.integrator / integ:run")
  print(("# machine: %s, %s; %s"):format(model, (io.popen("nproc"):read("l") or "?") .. " cores",
    _VERSION))
  print(("# median of %d interleaved runs, each ~%.2f s CPU; ratios are to the C implementation in this run"):format(R, TARGET))
end

local function median(t)
  local s = {}
  for i, x in ipairs(t) do s[i] = x end
  table.sort(s)
  local n = #s
  return n % 2 == 1 and s[(n + 1) // 2] or 0.5 * (s[n // 2] + s[n // 2 + 1])
end

local function make(which, kind)
  local sys
  if kind == "builtin" then
    sys = which == "kepler" and dm.systems.kepler{impl = "c"} or dm.systems.j2{J2 = 0.05, impl = "c"}
  else
    dm.config.native = kind
    sys = which == "kepler" and dm.systems.kepler{} or dm.systems.j2{J2 = 0.05}
    dm.config.native = "auto"
  end
  local opts = which == "kepler" and {method = "trapezoid", h = 0.01}
                                  or {method = "gauss", stages = 2, h = 0.05}
  local state = which == "kepler" and {q = {0.4, 0}, p = {0, 2}}
                                   or {q = {2, 0, 0.3}, p = {0, 0.6, 0.1}}
  return {sys = sys, integ = dm.integrator(sys, opts), state = state, t = {}}
end

local function run(V, n)
  V.integ:reset()
  local t0 = os.clock()
  local tr, msg = V.integ:run(V.state, {steps = n, every = n, energy = false, progress = false})
  local dt = os.clock() - t0
  assert(msg == nil, msg)
  return dt, tr
end

local function bench(title, which)
  local kinds = {{"builtin", "impl = \"c\" (hand-written C system)"},
                 {"never", "dm.systems traced, tape"},
                 {"always", "dm.systems traced, native"}}
  local Vs = {}
  for i, k in ipairs(kinds) do
    local ok, V = pcall(make, which, k[1])
    if ok then
      V.name = k[2]
      local n = 1000
      while true do
        local dt = run(V, n)
        if dt >= 0.3 * TARGET then
          V.n = math.max(100, math.floor(n * TARGET / dt))
          break
        end
        n = n * 4
      end
    else
      V = {name = k[2], err = tostring(V)}
    end
    Vs[i] = V
  end
  for _ = 1, R do
    for _, V in ipairs(Vs) do
      if V.n then V.t[#V.t + 1] = run(V, V.n) / V.n end
    end
  end
  print(("\n## %s"):format(title))
  print(("%-40s %10s %10s %9s"):format("variant", "ns/step", "x builtin", "steps"))
  local ref = Vs[1].n and median(Vs[1].t)
  for _, V in ipairs(Vs) do
    if V.n then
      local m = median(V.t)
      print(("%-40s %10.1f %10.2f %9d"):format(V.name, 1e9 * m, ref and m / ref or 0 / 0, V.n))
    else
      print(("%-40s skipped: %s"):format(V.name, V.err))
    end
  end
end

machine()
bench("B1a (Lua) Kepler e=0.6, Stormer-Verlet, h = 0.01", "kepler")
bench("B1b (Lua) J2 Cartesian, Gauss s=2, h = 0.05", "j2")
