-- plot_session.lua -- the gnuplot session over time: a killed gnuplot is
-- replaced, 10^6 points stream through, figures update live and close,
-- objects with :column(name) plot (trajectories too), the command log.
local T = require "dmech.test"
local dm = require "dmech"
local H = dofile(os.getenv("DMECH_SRCDIR") .. "/tests/lua/plot_helpers.lua")
H.need_gnuplot(T, dm)
local dir = T.tmpdir("plot_session")

local function vertices(svgfile)
  -- number of path vertices per plotted series (a key entry adds 2)
  local s = H.read(svgfile) or ""
  local counts = {}
  for start in s:gmatch('()<g id="gnuplot_plot_%d+%a*" >') do
    local depth, pos, n = 0, start, 0
    repeat                                  -- to the matching </g>
      local a, b, close, body = s:find("<(/?)g([^>]*)>", pos)
      if not a then break end
      if close == "/" then depth = depth - 1
      elseif body:sub(-1) ~= "/" then depth = depth + 1 end
      pos = b + 1
    until depth == 0
    for d in s:sub(start, pos - 1):gmatch("d='([^']*)'") do
      for _ in d:gmatch("[ML]%s*%-?[%d.]+,%-?[%d.]+") do n = n + 1 end
    end
    counts[#counts + 1] = n
  end
  return counts
end

-- killed mid-session: the next plot starts a new gnuplot
local x = dm.linspace(0, 2.385, 100)
local y = x * x
dm.plot{ {x, y}, output = dir .. "/a.png", size = {300, 200} }
local pid, gen = dm._gp.pid(), dm._gp.generation()
T.ok(pid ~= nil, "gnuplot runs (pid " .. tostring(pid) .. ")")
os.execute("kill -9 " .. pid)
T.ok(H.wait_dead(pid), "gnuplot killed")
os.remove(dir .. "/b.png")
dm.plot{ {x, y}, output = dir .. "/b.png", size = {310, 200} }
T.is(H.png_size(dir .. "/b.png"), 310, "the next plot works")
T.ok(dm._gp.pid() ~= pid and dm._gp.generation() == gen + 1, "with a new gnuplot process")

-- 10^6 points: streamed without deadlock, all of them arrive
local n = 1000000
local big = dm.linspace(0, 2.385, n)
local t0 = os.clock()
local wall0 = os.time()
dm.plot{ {big, big * big, title = "10^6 points"}, output = dir .. "/million.png", size = {400, 300} }
local w, h = H.png_size(dir .. "/million.png")
T.ok(w == 400 and h == 300, "10^6-point plot written")
T.is(dm.gnuplot("stats $dmp_1 using 2 nooutput; print STATS_records"), tostring(n), "gnuplot received all 10^6 points")
T.diag(string.format("10^6 points: %.2f s CPU here, %d s wall", os.clock() - t0, os.time() - wall0))

-- a live figure: append + refresh
local svg = dir .. "/live.svg"
os.remove(svg)
local fig = dm.figure{ title = "live", output = svg, xlabel = "step" }
local id = fig:add{ {}, {} }
T.is(id, 1, "first series id")
T.ok(not H.exists(svg), "an empty series draws nothing")
for k = 1, 40 do fig:append(id, k, math.sin(k / 7)) end
fig:refresh()
T.is(vertices(svg)[1], 40, "refresh draws the 40 appended points")
fig:append(id, {41, 42, 43}, dm.vec{0.5, 0.25, 2.385})
fig:refresh()
T.is(vertices(svg)[1], 43, "appending tables/vecs adds points")
local id2 = fig:add{ x, y }
T.is(id2, 2, "second series id")
T.is(#vertices(svg), 2, "add redraws with both series")
T.error_like(function() fig:append(id, 1, 2, 3) end, "series 1 has 2 columns; give x, y", "append checks the columns")
T.error_like(function() fig:append(id, {1, 2}, {1}) end, "different lengths", "append checks lengths")
fig:save(dir .. "/live.pdf")
T.ok((H.read(dir .. "/live.pdf") or ""):sub(1, 5) == "%PDF-", "save writes another format")
fig:save(dir .. "/live.png", {size = {333, 222}})
w, h = H.png_size(dir .. "/live.png")
T.ok(w == 333 and h == 222, "save with a size")
T.ok(tostring(fig):match("^figure %d+: 2 series in 1 panel %-> .*live%.svg$"), "tostring: " .. tostring(fig))
fig:close()
fig:close()
T.ok(tostring(fig):match("%(closed%)$"), "close is idempotent")
T.error_like(function() fig:refresh() end, "figure:refresh: the figure is closed", "a closed figure refuses work")

-- <close>: the figure is closed at the end of the block
local closed_fig
do
  local f <close> = dm.figure{ output = dir .. "/scoped.png" }
  f:add{ x, y }
  closed_fig = f
end
T.ok(tostring(closed_fig):match("%(closed%)$"), "<close> closes the figure")

-- layout in a figure: add to panels
local pf = dm.figure{ layout = "1,2", output = dir .. "/panels.svg" }
pf:add({ x, y }, 1)
pf:add({ x, x * 2 }, 2)
pf:add({ x, x * 3 }, 2)
T.is(#vertices(dir .. "/panels.svg"), 3, "a 1x2 figure with series added per panel")
T.error_like(function() pf:add({ x, y }, 3) end, "panel: 1%.%.2 expected", "no third panel")
pf:close()

-- any object with :column(name) plots, and is read again on refresh
local obj = {data = {u = {1, 2, 3}, v = {2.385, 1, 0.5}}}
function obj:column(name)
  local c = self.data[name]
  if not c then error("no column '" .. name .. "'") end
  return c
end
local of = dm.figure{ output = dir .. "/obj.svg" }
of:add{ obj, "u", "v" }
T.is(vertices(dir .. "/obj.svg")[1], 3, "object series drawn")
obj.data.u[4], obj.data.v[4] = 4, 3
of:refresh()
T.is(vertices(dir .. "/obj.svg")[1], 4, "refresh asks the object again")
T.error_like(function() of:add{ obj, "u", "nosuch" } end, "column 'nosuch': .*no column 'nosuch'", "missing column names it")
T.error_like(function() of:append(1, 1, 2) end, "series 1 is an object series", "append only on data series")
of:close()

-- a trajectory is such an object (dm.trajectory is part of dmech: its absence is a failure)
T.is(type(dm.trajectory), "function", "dm.trajectory exists")
do
  local tt, r, th = {}, {}, {}
  for k = 1, 101 do
    tt[k] = (k - 1) * 0.05
    r[k] = 2.385 + 0.3 * math.sin(tt[k])
    th[k] = 0.6 * tt[k]
  end
  local tr = dm.trajectory{ t = tt, coords = {"r", "theta"}, q = {r = r, theta = th} }
  dm.plot{ {tr, "t", "r", title = "r(t)"}, {tr, "t", "theta"}, output = dir .. "/traj.svg" }
  local c = vertices(dir .. "/traj.svg")
  T.ok(c[1] == 101 + 2 and c[2] == 101, "a trajectory plots through :column (101 samples)")
  dm.plot{ {tr, "r", "theta", "t"}, output = dir .. "/traj3.png" }
  T.ok(H.png_size(dir .. "/traj3.png") == 640, "three trajectory columns: splot")
end

-- DMECH_GNUPLOT_LOG records every command sent
local log = dir .. "/session.gp"
os.remove(log)
local cmd = "cd " .. H.shq(dir) .. " && DMECH_GNUPLOT_LOG=" .. H.shq(log) .. " " .. H.shq(os.getenv("DMECH")) ..
  " -e " .. H.shq("dm.plot{ {dm.vec{1, 2.385}, dm.vec{3, 4}, title = \"it's\"}, output = 'logged.png' }") .. " 2>&1"
local p = io.popen(cmd)
local res = p:read("a")
p:close()
local text = H.read(log) or ""
T.ok(text:find("$dmp_1 << EOD\n1 3\n2.3849999999999998 4\nEOD\n", 1, true)
     and text:find("plot $dmp_1 using 1:2 with lines title 'it'.\"\\047\".'s'", 1, true)
     and text:find("set terminal pngcairo size 640,480 noenhanced", 1, true)
     and text:find("# dmech: checkpoint (dm.plot)", 1, true),
     "the log holds terminal, data, plot command and checkpoints")
if res ~= "" then T.diag(res) end

-- panels of a multiplot do not inherit each other's settings: a log scale
-- and raw commands of panel 1 are gone in panel 2 (gnuplot prints no
-- warning about a range on a log axis, and the log shows the reset)
local log2 = dir .. "/panels.gp"
os.remove(log2)
local script = [[
local x = dm.linspace(0.1, 3, 20)
dm.plot{ {{x, x:map(math.exp)}, logscale = "y", commands = {"set format y '%.3f'"}},
         {{x, x:map(math.sin)}, yrange = {-1, 1}}, layout = "1,2", output = "panels.png" }]]
local cmd2 = "cd " .. H.shq(dir) .. " && DMECH_GNUPLOT_LOG=" .. H.shq(log2) .. " " ..
  H.shq(os.getenv("DMECH")) .. " -e " .. H.shq(script) .. " 2>&1"
local p2 = io.popen(cmd2)
local out2 = p2:read("a")
p2:close()
local t2 = H.read(log2) or ""
local second = t2:match("set format y '%%.3f'.-\nreset\n(.*)$") or ""
T.ok(second:find("unset logscale", 1, true) and not second:find("\nset logscale", 1, true)
     and not second:find("set format", 1, true) and second:find("set yrange [-1:1]", 1, true),
     "panel 2 starts from a reset: no log scale, no raw commands of panel 1")
T.ok(not out2:lower():find("warning"), "no gnuplot warning about ranges on a log axis: " .. out2)
T.done()
