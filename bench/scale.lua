-- bench/scale.lua -- how the costs of defining and integrating a system grow
-- with its degrees of freedom N (run by bench/bench_scale, which provides
-- `bench`; `make bench-scale`).  Two systems, both defined as a user writes
-- them, L a Lua loop over plain coordinate names x1 .. xN:
--
--   FPU-beta chain of N unit masses, fixed ends, beta = 1;
--   planar N-body, N/2 unit masses, G = 1 (L = T + sum 1/r).
--
-- Per N: the definition (trace + derive + tape, native = "never", thread CPU
-- ms), Stormer-Verlet ns/step on the tape and native against the
-- hand-written C leapfrog (bench_scale.c), Gauss s=2 ns/step on the tape and
-- native (the default: the fixed-point iteration for these separable
-- systems), then Gauss s=2 native with Newton forced (iteration = "newton")
-- on the sparse KLU matrices and on the dense LU (linear = "sparse" and
-- "dense"), the first native compile with an empty cache (dm.system with
-- native = "always" minus the definition: CPU s of dmech and the C
-- compilers, and wall s), and the wall time from the start of dm.system to
-- the end of the first step with native = "auto" and an empty cache (a
-- tree without background compiles compiles first).  |dq|: the largest
-- difference of q and p between dmech (native) and the C loop after 1000
-- steps.  Then the growth exponents fitted by least squares on log-log from
-- N = 64 up.  A measurement whose predicted time exceeds the budget (the
-- last one times the growth so far) is skipped ("-"), so that an old tree
-- can run the same script.  Wall times depend on the machine's load; CPU
-- times much less.
--
-- args: [quick] [fpu|nbody] [maxN]; environment BENCH_BUDGET (s, default 60)
local B = bench
local quick = arg[1] == "quick"
local only = arg[2]
local maxN = tonumber(arg[3] or "") or (quick and 1024 or 4096)
local budget = tonumber(os.getenv("BENCH_BUDGET") or "") or 60
local has_wait = pcall(function()      -- a tree with background compiles
  return dm.system{name = "probe", coords = {"x"}, native = "wait", L = function(q, v) return v[1]^2 end}
end)

print("machine: " .. B.machine())
print(("dmech: %s; background compile: %s; budget %g s per measurement"):format(
  dm._VERSION or "?", has_wait and "yes" or "no", budget))
print()

local function median(t)
  table.sort(t)
  return t[(#t + 1) // 2]
end

-- {======================================================================
-- the systems
-- =======================================================================

local function names(N)
  local c = {}
  for i = 1, N do c[i] = "x" .. i end
  return c
end

local function fpu(N, native)
  return dm.system{name = "fpu", coords = names(N), params = {beta = 1.0}, native = native,
    L = function(q, v, p)
      local T, V, prev = 0, 0, 0
      for i = 1, N do T = T + 0.5 * v[i]^2 end
      for i = 1, N do
        local d = q[i] - prev
        V = V + 0.5 * d^2 + 0.25 * p.beta * d^4
        prev = q[i]
      end
      local d = -prev
      V = V + 0.5 * d^2 + 0.25 * p.beta * d^4
      return T - V
    end}
end

local function nbody(N, native)
  local nb = N // 2
  return dm.system{name = "nbody", coords = names(N), native = native,
    L = function(q, v)
      local T, V = 0, 0
      for i = 1, N do T = T + 0.5 * v[i]^2 end
      for a = 1, nb do
        for b = a + 1, nb do
          local dx, dy = q[2 * a - 1] - q[2 * b - 1], q[2 * a] - q[2 * b]
          V = V - 1 / dm.sqrt(dx^2 + dy^2)
        end
      end
      return T - V
    end}
end

-- starting states: a standing wave of small amplitude; bodies on a circle
-- of radius nb with near-circular speeds
local function fpu_state(N)
  local q, p = {}, {}
  for i = 1, N do
    q[i] = 0.3 * math.sin(math.pi * i / (N + 1)) + 0.01 * math.sin(7 * i)
    p[i] = 0.01 * math.cos(3 * i)
  end
  return q, p
end

local function nbody_state(N)
  local nb, q, p = N // 2, {}, {}
  local R = nb
  local v = math.sqrt(nb / (4 * R)) * 0.9
  for a = 1, nb do
    local th = 2 * math.pi * (a - 1) / nb
    q[2 * a - 1], q[2 * a] = R * math.cos(th), R * math.sin(th)
    p[2 * a - 1], p[2 * a] = -v * math.sin(th), v * math.cos(th)
  end
  return q, p
end

local kinds = {
  fpu = {name = "FPU-beta chain, fixed ends (L a Lua loop)", sys = fpu, state = fpu_state,
         hand = function(q, p, h, n) return B.fpu_sv(q, p, h, n, 1.0) end, h = 0.05,
         Ns = {8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096}},
  nbody = {name = "planar N-body, N/2 unit masses (L a Lua loop over pairs)", sys = nbody,
           state = nbody_state, hand = B.nbody_sv, h = 1e-3,
           Ns = {8, 16, 32, 64, 128, 256}},
}

-- }======================================================================

-- {======================================================================
-- measurements
-- =======================================================================

-- ns/step of integ:run (one sample at the end), the step count grown until
-- a run takes 0.05 s, median of 3; also the final state
local function per_step(I, s, guess)
  local n = math.max(1, guess)
  local o = {steps = n, every = n, energy = false, momentum = false, progress = false}
  local t0 = B.now()
  local tr = I:run(s, o)
  local t = B.now() - t0
  while t < 0.05 and n < 1e8 do
    n = math.ceil(n * math.min(100, 0.08 / math.max(t, 1e-6)))
    o.steps, o.every = n, n
    t0 = B.now(); tr = I:run(s, o); t = B.now() - t0
  end
  local ts = {t / n}
  for r = 2, 3 do
    t0 = B.now(); tr = I:run(s, o); ts[r] = (B.now() - t0) / n
  end
  return median(ts) * 1e9, tr, n
end

local function hand_per_step(K, q, p, guess)
  local n = math.max(1, guess)
  local t = K.hand(q, p, K.h, n)
  while t < 0.05 do
    n = math.ceil(n * math.min(100, 0.08 / math.max(t, 1e-6)))
    t = K.hand(q, p, K.h, n)
  end
  local ts = {t / n}
  local qf, pf
  for r = 2, 3 do
    local tt
    tt, qf, pf = K.hand(q, p, K.h, n)
    ts[r] = tt / n
  end
  return median(ts) * 1e9, qf, pf, n
end

-- the state at the end of a run, for the distance to the hand loop
local function last(tr, N)
  local q, p = {}, {}
  for i = 1, N do
    q[i] = tr:column("x" .. i)[#tr]
    p[i] = tr:column("p_x" .. i)[#tr]
  end
  return q, p
end

local function dist(a, b)
  local d = 0
  for i = 1, #a do d = math.max(d, math.abs(a[i] - b[i])) end
  return d
end

-- a fresh, empty native cache
local function cold_cache()
  B.setenv("XDG_CACHE_HOME", B.mkdtemp())
end

local function fmt(x, f)
  if x == nil then return "-" end
  return (f or "%.3g"):format(x)
end

-- within budget: the previous value of this column (s) times the growth
-- from the one before it, extrapolated to N
local function affordable(col, N)
  local n = #col
  if n == 0 then return true end
  local a = col[n]
  if a.v == nil then return false end
  local grow = 4
  if n >= 2 and col[n - 1].v then
    grow = math.max(1, math.log(a.v / col[n - 1].v) / math.log(a.N / col[n - 1].N))
  end
  return a.v * (N / a.N)^grow <= budget
end

local function fit(col, from)
  local sx, sy, sxx, sxy, m = 0, 0, 0, 0, 0
  for _, r in ipairs(col) do
    if r.N >= from and r.v and r.v > 0 then
      local x, y = math.log(r.N), math.log(r.v)
      sx, sy, sxx, sxy, m = sx + x, sy + y, sxx + x * x, sxy + x * y, m + 1
    end
  end
  if m < 2 then return nil end
  return (m * sxy - sx * sy) / (m * sxx - sx * sx)
end

local function bench_kind(key)
  local K = kinds[key]
  print(K.name)
  local cols = {}
  local keys = {"def", "sv_tape", "sv_nat", "sv_hand", "g2_tape", "g2_nat", "g2_sp", "g2_dn",
                "compile", "cwall", "first"}
  for _, k in ipairs(keys) do cols[k] = {} end
  -- each column holds the seconds one measurement takes (3 steps for the
  -- per-step ones): the budget extrapolates them; the exponents are those
  -- of the per-step costs
  local function want(k, N) return affordable(cols[k], N) end
  local hfmt = "  %6s %9s %9s %9s %9s %6s %11s %11s %7s %11s %11s %8s %8s %9s %8s"
  print(hfmt:format("N", "define", "SV tape", "SV native", "SV C", "nat/C", "G2 tape",
    "G2 native", "G2/SV", "G2 KLU", "G2 dense", "compile", "compile", "1st step", "|dq|"))
  print(hfmt:format("", "ms", "ns/step", "ns/step", "ns/step", "", "ns/step", "ns/step", "",
    "ns/step", "ns/step", "CPU s", "wall s", "wall s", ""))
  for _, N in ipairs(K.Ns) do
    if N > maxN then break end
    local row = {N = N}
    local q0, p0 = K.state(N)
    local s0 = {q = q0, p = p0}
    -- definition on the tape
    local sys
    if want("def", N) then
      collectgarbage()
      local t0 = B.now()
      sys = K.sys(N, "never")
      row.def = B.now() - t0
    end
    table.insert(cols.def, {N = N, v = row.def})
    -- Stormer-Verlet and Gauss s=2 on the tape
    local sv = {method = "trapezoid", h = K.h}
    local g2 = {method = "gauss", stages = 2, h = K.h}
    if sys and want("sv_tape", N) then
      local ns = per_step(dm.integrator(sys, sv), s0, math.ceil(1e6 / N))
      row.sv_tape = ns
    end
    table.insert(cols.sv_tape, {N = N, v = row.sv_tape and row.sv_tape * 3e-9})
    if sys and want("g2_tape", N) then
      -- the first run is a step or a few: the budget counts from there
      row.g2_tape = per_step(dm.integrator(sys, g2), s0, 1)
    end
    table.insert(cols.g2_tape, {N = N, v = row.g2_tape and row.g2_tape * 3e-9})
    sys = nil
    collectgarbage()
    -- hand-written C
    local hq, hp
    row.sv_hand, hq, hp = hand_per_step(K, q0, p0, math.ceil(1e6 / N))
    table.insert(cols.sv_hand, {N = N, v = row.sv_hand * 3e-9})
    -- native: the compile with an empty cache, then the steps
    local nsys
    if want("compile", N) then
      cold_cache()
      collectgarbage()
      local w0, c0, k0 = B.wall(), B.now(), B.children()
      local ok, r = pcall(K.sys, N, "always")
      local w, c = B.wall() - w0, B.now() - c0 + B.children() - k0
      if ok then
        nsys = r
        row.cwall = math.max(0, w - (row.def or 0))
        row.compile = math.max(0, c - (row.def or 0))
      else
        print("  native: " .. tostring(r))
      end
    end
    table.insert(cols.compile, {N = N, v = row.compile})
    table.insert(cols.cwall, {N = N, v = row.cwall})
    if nsys then
      local I = dm.integrator(nsys, sv)
      row.sv_nat = per_step(I, s0, math.ceil(1e6 / N))
      -- 1000 steps both ways, for the distance
      local tr = I:run(s0, {steps = 1000, every = 1000, energy = false, momentum = false,
                            progress = false})
      local _, qh, ph = K.hand(q0, p0, K.h, 1000)
      local qd, pd = last(tr, N)
      row.dq = math.max(dist(qd, qh), dist(pd, ph))
      if want("g2_nat", N) then
        row.g2_nat = per_step(dm.integrator(nsys, g2), s0, 1)
      end
      -- Newton with either linear solver (a tree without the options
      -- errs: "-")
      for _, lin in ipairs{{"g2_sp", "sparse"}, {"g2_dn", "dense"}} do
        if want(lin[1], N) then
          local ok, I2 = pcall(dm.integrator, nsys, {method = "gauss", stages = 2, h = K.h,
                                                     iteration = "newton", linear = lin[2]})
          if ok then row[lin[1]] = per_step(I2, s0, 1) end
        end
      end
    end
    table.insert(cols.sv_nat, {N = N, v = row.sv_nat and row.sv_nat * 3e-9})
    table.insert(cols.g2_nat, {N = N, v = row.g2_nat and row.g2_nat * 3e-9})
    table.insert(cols.g2_sp, {N = N, v = row.g2_sp and row.g2_sp * 3e-9})
    table.insert(cols.g2_dn, {N = N, v = row.g2_dn and row.g2_dn * 3e-9})
    nsys = nil
    collectgarbage()
    -- the first step after the definition, native = "auto", an empty cache
    if want("first", N) then
      cold_cache()
      collectgarbage()
      local w0 = B.wall()
      local a = K.sys(N, "auto")
      dm.integrator(a, sv):step(s0)
      row.first = B.wall() - w0
      a = nil
      collectgarbage()          -- cancels the compile still going on
    end
    table.insert(cols.first, {N = N, v = row.first})
    local g2best = row.g2_nat or row.g2_tape
    local svbest = row.sv_nat or row.sv_tape
    print(hfmt:format(N,
      fmt(row.def and row.def * 1e3), fmt(row.sv_tape, "%.0f"), fmt(row.sv_nat, "%.0f"),
      fmt(row.sv_hand, "%.0f"), fmt(row.sv_nat and row.sv_nat / row.sv_hand, "%.2f"),
      fmt(row.g2_tape, "%.0f"), fmt(row.g2_nat, "%.0f"),
      fmt(g2best and svbest and g2best / svbest, "%.1f"), fmt(row.g2_sp, "%.0f"),
      fmt(row.g2_dn, "%.0f"), fmt(row.compile, "%.2f"),
      fmt(row.cwall, "%.2f"), fmt(row.first, "%.3f"), fmt(row.dq, "%.0e")))
    io.stdout:flush()
  end
  local from = 64
  local function ex(k)
    return fmt(fit(cols[k], from), "%.2f")
  end
  print(("  fitted exponents (N >= %d): define %s, SV tape %s, SV native %s, SV C %s, "
         .. "G2 tape %s, G2 native %s, G2 KLU %s, G2 dense %s, compile CPU %s"):format(from,
         ex("def"), ex("sv_tape"), ex("sv_nat"), ex("sv_hand"), ex("g2_tape"), ex("g2_nat"),
         ex("g2_sp"), ex("g2_dn"), ex("compile")))
  print()
end

-- }======================================================================

for _, key in ipairs{"fpu", "nbody"} do
  if only == nil or only == key then bench_kind(key) end
end
