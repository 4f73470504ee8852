-- b_report.lua -- turn the benchmark tables into plots (dm.plot, gnuplot
-- pngcairo) and Markdown tables.  Run by src/dmech from bench/bpeers.sh:
--   dmech bench/b_report.lua <results-dir>
-- Reads <dir>/b2_<problem>_{c,odeint,scipy}.tsv, <dir>/b3_trace_*.tsv,
-- <dir>/b3_summary.tsv; writes <dir>/b2_<problem>.png, <dir>/b3_energy.png
-- and <dir>/tables.md.  Missing inputs (skipped peers) are left out.
local dir = assert(arg and arg[1], "usage: dmech bench/b_report.lua <results-dir>")

local function readtsv(path, header)
  local f = io.open(path)
  if not f then return nil end
  local rows, cols = {}, nil
  for line in f:lines() do
    local w = {}
    for x in (line .. "\t"):gmatch("([^\t]*)\t") do w[#w + 1] = x end
    if header and not cols then
      cols = w
    else
      if cols then
        local r = {}
        for i, c in ipairs(cols) do
          local x = w[i]
          r[c] = tonumber(x) or ((x == "nan" or x == "-nan") and 0 / 0) or x
        end
        rows[#rows + 1] = r
      else
        rows[#rows + 1] = w
      end
    end
  end
  f:close()
  return rows
end

local out = assert(io.open(dir .. "/tables.md.tmp", "w"))
local function md(...) out:write(string.format(...), "\n") end

-- {==== B2 =================================================================
local STYLE = {   -- label -> gnuplot style (dmech solid, peers dashed)
  ["dmech SV"] = "linespoints lw 2 pt 7 lc rgb '#1f77b4'",
  ["dmech comp4 yoshida4"] = "linespoints lw 2 pt 5 lc rgb '#ff7f0e'",
  ["dmech comp6 kahanli6"] = "linespoints lw 2 pt 9 lc rgb '#2ca02c'",
  ["dmech comp8 kahanli8"] = "linespoints lw 2 pt 11 lc rgb '#d62728'",
  ["dmech Gauss s=2"] = "linespoints lw 2 pt 13 lc rgb '#9467bd'",
  ["dmech Gauss s=3"] = "linespoints lw 2 pt 15 lc rgb '#8c564b'",
  ["dmech Lobatto s=3"] = "linespoints lw 2 pt 4 lc rgb '#e377c2'",
  ["odeint velocity_verlet"] = "linespoints lw 1 dt 2 pt 6 lc rgb '#1f77b4'",
  ["odeint sb3a_m4_mclachlan"] = "linespoints lw 1 dt 2 pt 8 lc rgb '#ff7f0e'",
  ["odeint sb3a_mclachlan"] = "linespoints lw 1 dt 2 pt 10 lc rgb '#bcbd22'",
  ["GSL rk8pd"] = "linespoints lw 1 dt 2 pt 12 lc rgb '#7f7f7f'",
  ["SciPy DOP853"] = "linespoints lw 1 dt 2 pt 14 lc rgb '#17becf'",
}

-- CPU time at which a method's curve first reaches `target` (log-log
-- interpolation between sweep points sorted by CPU time); nil if never
local function time_to(pts, key, target)
  for i, p in ipairs(pts) do
    local y = p[key]
    if type(y) == "number" and y <= target then
      local q = pts[i - 1]
      if not q or type(q[key]) ~= "number" or q[key] <= target then return p.cpu_s, i == 1 end
      local a = (math.log(target) - math.log(q[key])) / (math.log(y) - math.log(q[key]))
      return math.exp(math.log(q.cpu_s) + a * (math.log(p.cpu_s) - math.log(q.cpu_s)))
    end
  end
  return nil
end

for _, prob in ipairs({"kepler", "j2"}) do
  local rows = {}
  for _, impl in ipairs({"c", "odeint", "scipy"}) do
    for _, r in ipairs(readtsv(("%s/b2_%s_%s.tsv"):format(dir, prob, impl), true) or {}) do
      rows[#rows + 1] = r
    end
  end
  if #rows > 0 then
    local order, by = {}, {}
    for _, r in ipairs(rows) do
      if not by[r.method] then by[r.method] = {} order[#order + 1] = r.method end
      table.insert(by[r.method], r)
    end
    local err_series, dh_series = {}, {}
    for _, m in ipairs(order) do
      local pts = by[m]
      table.sort(pts, function(a, b) return a.cpu_s < b.cpu_s end)
      local x, ye, yh = {}, {}, {}
      for _, p in ipairs(pts) do
        if type(p.cpu_s) == "number" and p.cpu_s > 0 then
          if type(p.err_end) == "number" and p.err_end > 0 then
            x[#x + 1] = p.cpu_s
            ye[#ye + 1] = p.err_end
          end
        end
      end
      local xh = {}
      for _, p in ipairs(pts) do
        if type(p.cpu_s) == "number" and p.cpu_s > 0 and type(p.max_dH) == "number" and p.max_dH > 0 then
          xh[#xh + 1] = p.cpu_s
          yh[#yh + 1] = p.max_dH
        end
      end
      local st = STYLE[m] or "linespoints"
      if #x > 0 then err_series[#err_series + 1] = {x, ye, title = m, with = st} end
      if #xh > 0 then dh_series[#dh_series + 1] = {xh, yh, title = m, with = st} end
    end
    local name = prob == "kepler" and "Kepler e=0.6, 1000 periods" or "J2 (J2=0.05), T=12750 (~1000 orbits)"
    err_series.title = name .. ": error at the end"
    err_series.xlabel = "CPU time [s]"
    err_series.ylabel = "|(q,p) - reference| at T"
    err_series.logscale = "xy"
    err_series.grid = true
    err_series.key = "bottom left"
    dh_series.title = name .. ": max |H - H0|"
    dh_series.xlabel = "CPU time [s]"
    dh_series.ylabel = "max |H - H0|"
    dh_series.logscale = "xy"
    dh_series.grid = true
    dh_series.key = false
    local panels = {}
    if #err_series > 0 then panels[#panels + 1] = err_series end
    if #dh_series > 0 then panels[#panels + 1] = dh_series end
    if #panels == 2 then
      dm.plot{err_series, dh_series, layout = "1,2", size = {1600, 640},
              output = ("%s/b2_%s.png"):format(dir, prob)}
    elseif #panels == 1 then
      panels[1].key = "bottom left"
      panels[1].output = ("%s/b2_%s.png"):format(dir, prob)
      panels[1].size = {900, 640}
      dm.plot(panels[1])
    end

    md("### B2 %s\n", name)
    md("| method | h or tol | steps | CPU s | reps | error at T | max abs dH |")
    md("|---|---:|---:|---:|---:|---:|---:|")
    for _, m in ipairs(order) do
      local pts = by[m]
      table.sort(pts, function(a, b) return a.value > b.value end)
      for _, p in ipairs(pts) do
        md("| %s | %s=%g | %d | %.4f | %d | %.3e | %.3e |", m, p.par, p.value, p.steps, p.cpu_s,
           p.reps, p.err_end, p.max_dH)
      end
    end
    md("\nCPU seconds to reach a target (log-log interpolation along each curve; <= : the cheapest point is already below it; - : not reached):\n")
    md("| method | error at T <= 1e-4 | error at T <= 1e-8 | max abs dH <= 1e-8 | max abs dH <= 1e-12 |")
    md("|---|---:|---:|---:|---:|")
    for _, m in ipairs(order) do
      local pts = by[m]
      table.sort(pts, function(a, b) return a.cpu_s < b.cpu_s end)
      local function f(key, tgt)
        local t, first = time_to(pts, key, tgt)
        return t and ((first and "<= " or "") .. ("%.3g"):format(t)) or "-"
      end
      md("| %s | %s | %s | %s | %s |", m, f("err_end", 1e-4), f("err_end", 1e-8), f("max_dH", 1e-8),
         f("max_dH", 1e-12))
    end
    md("")
  end
end
-- }====

-- {==== B3 =================================================================
do
  local curves, order = {}, {}
  for _, impl in ipairs({"c", "odeint", "scipy"}) do
    for _, w in ipairs(readtsv(("%s/b3_trace_%s.tsv"):format(dir, impl), false) or {}) do
      local m, k, v = w[1], tonumber(w[2]), tonumber(w[3])
      if m and k and v then
        if not curves[m] then curves[m] = {} order[#order + 1] = m end
        curves[m][k] = v
      end
    end
  end
  if #order > 0 then
    local B3STYLE = {
      ["dmech SV h=0.01"] = "lines lw 2 lc rgb '#1f77b4'",
      ["dmech Gauss s=2 h=0.05"] = "lines lw 2 lc rgb '#9467bd'",
      ["dmech comp8 kahanli8 h=0.05"] = "lines lw 2 lc rgb '#2ca02c'",
      ["dmech rk4 h=0.01"] = "lines lw 2 lc rgb '#d62728'",
      ["GSL rk8pd tol 1e-10"] = "lines lw 1 dt 2 lc rgb '#7f7f7f'",
      ["odeint sb3a_m4_mclachlan"] = "lines lw 1 dt 2 lc rgb '#ff7f0e'",
      ["odeint runge_kutta4"] = "lines lw 1 dt 2 lc rgb '#bcbd22'",
      ["SciPy DOP853 tol 1e-10"] = "lines lw 1 dt 2 lc rgb '#17becf'",
    }
    local series = {title = "Kepler e=0.6: per-period max |H - H0| (maximum over log-spaced bins of periods)",
      xlabel = "period", ylabel = "max |H - H0| in the period", logscale = "xy", grid = true,
      key = "outside right", size = {1300, 600}, output = dir .. "/b3_energy.png"}
    for _, m in ipairs(order) do
      local c, n = curves[m], 0
      for k in pairs(c) do if k > n then n = k end end
      -- log-spaced bins: [1], [2], ... up to ~600 bins
      local x, y, lo = {}, {}, 1
      while lo <= n do
        local hi = math.max(lo, math.floor(lo * 1.012))
        local mx = 0
        for k = lo, math.min(hi, n) do mx = math.max(mx, c[k] or 0) end
        if mx > 0 then
          x[#x + 1] = math.sqrt(lo * math.min(hi, n))
          y[#y + 1] = mx
        end
        lo = hi + 1
      end
      series[#series + 1] = {x, y, title = m, with = B3STYLE[m] or "lines"}
    end
    dm.plot(series)
  end
  local S = readtsv(dir .. "/b3_summary.tsv", false)
  if S and #S > 0 then
    md("### B3 long time (Kepler e=0.6)\n")
    md("| method | steps | CPU s (unmonitored) | CPU s (dH every step) | periods | max abs dH | max, first 10%% of periods | max, last 10%% | trend (LSQ slope x periods) |")
    md("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for _, w in ipairs(S) do
      local c, n = curves[w[2]] or {}, 0
      for k in pairs(c) do if k > n then n = k end end
      local mx, first, last, sx, sy, sxx, sxy = 0, 0, 0, 0, 0, 0, 0
      local tenth = math.max(1, n // 10)
      for k = 1, n do
        local y = c[k] or 0
        mx = math.max(mx, y)
        if k <= tenth then first = math.max(first, y) end
        if k > n - tenth then last = math.max(last, y) end
        sx, sy, sxx, sxy = sx + k, sy + y, sxx + k * k, sxy + k * y
      end
      local slope = n > 1 and (n * sxy - sx * sy) / (n * sxx - sx * sx) or 0 / 0
      md("| %s | %s | %.3f | %.3f | %d | %.3e | %.3e | %.3e | %.2e |", w[2], w[3], tonumber(w[4]),
         tonumber(w[5]), n, mx, first, last, slope * n)
    end
    md("")
  end
end
-- }====

out:close()
assert(os.rename(dir .. "/tables.md.tmp", dir .. "/tables.md"))
print("report: " .. dir .. "/tables.md and PNGs written")
