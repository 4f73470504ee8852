-- plot_defaults.lua -- what dm.plot does without being asked, read from the
-- gnuplot command log: axis labels from column names, a panel's title apart
-- from a series' legend, the key where no data is, equal aspect for
-- configuration-space orbits, values <= 0 left out on log axes (no offsets),
-- thinned tics on narrow panels, "wrote file" at the prompt, help and
-- errors naming every option.
local T = require "dmech.test"
local dm = require "dmech"
local H = dofile(os.getenv("DMECH_SRCDIR") .. "/tests/lua/plot_helpers.lua")
H.need_gnuplot(T, dm)

local dir = os.getenv("DMECH_TESTTMP") .. "/plot_defaults"
os.execute("mkdir -p '" .. dir .. "'")
local log = dir .. "/commands.gp"

-- run f with the command log on; return the commands it sent (data blocks
-- kept, so the data can be checked too)
local function logged(f)
  os.remove(log)
  dm._gp.log(log)
  local ok, err = pcall(f)
  dm._gp.log(false)
  assert(ok, err)
  return H.read(log) or ""
end

local function has(text, s) return text:find(s, 1, true) ~= nil end

-- a planar orbit (coordinates x, y) and a reduced curve (r, z)
local t, xs, ys, rs, zs = {}, {}, {}, {}, {}
for k = 1, 400 do
  local s = (k - 1) * 0.05
  t[k] = s
  xs[k], ys[k] = 2.385 * math.cos(s), 2.1 * math.sin(s)
  rs[k], zs[k] = 1.5 + 0.1 * math.cos(3 * s), 0.7 * math.sin(s)
end
local orbit = dm.trajectory{t = t, coords = {"x", "y"}, q = {x = xs, y = ys}}
local merid = dm.trajectory{t = t, coords = {"r", "z"}, q = {r = rs, z = zs}}

-- {== labels from column names
local c = logged(function() dm.plot{ {orbit, "t", "x"}, output = dir .. "/l1.png" } end)
T.ok(has(c, "set xlabel 't'\n") and has(c, "set ylabel 'x'\n"), "axis labels from the column names")
c = logged(function() dm.plot{ {orbit, "t", "x"}, {orbit, "t", "y"}, output = dir .. "/l2.png" } end)
T.ok(has(c, "set xlabel 't'\n") and has(c, "unset ylabel\n"), "a label only where every series agrees")
c = logged(function() dm.plot{ {orbit, "t", "x"}, xlabel = "time", ylabel = false, output = dir .. "/l3.png" } end)
T.ok(has(c, "set xlabel 'time'\n") and has(c, "unset ylabel\n"), "the user's label, or none with false")
c = logged(function() dm.plot{ {dm.vec{1, 2}, dm.vec{3, 4}}, output = dir .. "/l4.png" } end)
T.ok(has(c, "unset xlabel\n") and has(c, "unset ylabel\n"), "no label for plain data")

-- {== a panel's title, a series' legend
c = logged(function()
  dm.plot{ {orbit, "x", "y", title = "orbital plane"}, {merid, "r", "z", title = "meridian", legend = "J2 orbit"},
           layout = "1,2", title = "both", output = dir .. "/t1.png" }
end)
T.ok(has(c, "set multiplot layout 1,2 title 'both'\n"), "the plot's title heads the multiplot")
T.ok(has(c, "set title 'orbital plane'\n") and has(c, "set title 'meridian'\n"),
     "a single-series panel's title is the panel's title")
T.ok(has(c, "with lines notitle\n") and has(c, "with lines title 'J2 orbit'\n"),
     "its legend (only) is a key entry")
c = logged(function()
  dm.plot{ {orbit, "t", "x", legend = "x(t)"}, {orbit, "t", "y", title = "y(t)"}, title = "Kepler",
           output = dir .. "/t2.png" }
end)
T.ok(has(c, "set title 'Kepler'\n") and has(c, "title 'x(t)'") and has(c, "title 'y(t)'"),
     "in one panel: title is the plot's, legend (or a series' title) the key's")
T.error_like(function() dm.plot{ {orbit, "t", "x", legend = "a", title = "b"} } end,
             "legend and title both given", "legend and title disagreeing")

-- {== the key where there is no data
local lx, ly = {}, {}
for k = 1, 200 do lx[k] = k / 200; ly[k] = (k / 200) ^ 2 end   -- rising: the top left corner is free
c = logged(function() dm.plot{ {lx, ly, legend = "x^2"}, output = dir .. "/k1.png" } end)
T.ok(has(c, "set key top left\n"), "a rising curve: key top left")
for k = 1, 200 do ly[k] = 1 - (k / 200) ^ 2 end               -- falling: top right free
c = logged(function() dm.plot{ {lx, ly, legend = "1 - x^2"}, output = dir .. "/k2.png" } end)
T.ok(has(c, "set key top right\n") and not has(c, "set offsets"), "a falling curve: key top right")
local nx, ny = {}, {}
for k = 1, 2000 do nx[k] = k; ny[k] = math.sin(k * 2.385) end  -- every corner taken
c = logged(function() dm.plot{ {nx, ny, legend = "noise"}, output = dir .. "/k3.png" } end)
T.ok(has(c, "set key top right\n") and has(c, "set offsets 0, 0, graph "),
     "data everywhere: room is made above it for the key")
c = logged(function() dm.plot{ {nx, ny, legend = "noise"}, yrange = {-1, 1}, output = dir .. "/k4.png" } end)
T.ok(has(c, "set key below\n"), "data everywhere and a fixed range: the key goes below")
c = logged(function() dm.plot{ {nx, ny, legend = "noise"}, key = "bottom left", output = dir .. "/k5.png" } end)
T.ok(has(c, "set key bottom left\n") and not has(c, "set offsets"), "the user's key position is kept")
c = logged(function() dm.plot{ {nx, ny}, output = dir .. "/k6.png" } end)
T.ok(not has(c, "set key top") and not has(c, "set key below"), "no key entries: nothing placed")

-- {== equal aspect for configuration-space orbits
c = logged(function() dm.plot{ {orbit, "x", "y"}, output = dir .. "/a1.png" } end)
T.ok(has(c, "set size ratio -1\n"), "coordinates on both axes: equal aspect")
c = logged(function() dm.plot{ {orbit, "t", "x"}, output = dir .. "/a2.png" } end)
T.ok(has(c, "set size noratio\n"), "time on an axis: free aspect")
c = logged(function() dm.plot{ {merid, "r", "z"}, output = dir .. "/a3.png" } end)
T.ok(has(c, "set size noratio\n"), "spans 0.2 and 1.4 (factor 7 > 4): free aspect, not a sliver")
c = logged(function() dm.plot{ {orbit, "x", "y"}, aspect = false, output = dir .. "/a4.png" } end)
T.ok(has(c, "set size noratio\n"), "aspect = false keeps it free")
local o3 = dm.trajectory{t = t, coords = {"x", "y", "z"}, q = {x = xs, y = ys, z = zs}}
c = logged(function() dm.plot{ {o3, "x", "y", "z"}, output = dir .. "/a5.png" } end)
T.ok(has(c, "set view equal xyz\n"), "3-D coordinates: equal units on every axis")

-- {== log axes: values <= 0 left out, no offset needed
local lt, le = {}, {}
for k = 1, 50 do lt[k] = k; le[k] = (k % 10 == 0) and 0 or 10 ^ (-k / 5) end
local before = le[10]
c = logged(function() dm.plot{ {lt, le, legend = "|d|"}, logscale = "y", output = dir .. "/g1.png" } end)
T.ok(has(c, "set logscale y\n") and c:lower():find("\n10 %-?nan\n") and c:lower():find("\n20 %-?nan\n"),
     "zeros on a log axis are sent as NaN (left out)")
T.is(le[10], before, "the caller's data are not changed")
local T2 = select(2, pcall(function()
  return logged(function() dm.plot{ {lt, le}, logscale = "y", output = dir .. "/g2.png" } end)
end))
T.ok(type(T2) == "string", "a plot with zeros on a log axis draws without error")

-- {== tics thinned on a narrow panel
local wx, wy = {}, {}
for k = 1, 300 do local s = k / 300 * 2 * math.pi; wx[k] = 0.84 * math.cos(s); wy[k] = 0.84 * math.sin(s) end
c = logged(function()
  dm.plot{ {{wx, wy}}, {{wx, wy}}, {{wx, wy}}, {{wx, wy}, aspect = "equal"},
           layout = "2,2", size = {1200, 900}, output = dir .. "/n1.png" }
end)
T.ok(has(c, "set xtics 0.5\n") and has(c, "set xrange [-1:1]\n"),
     "eleven labels in a small square: every 0.5, the range as gnuplot draws it")
c = logged(function() dm.plot{ {wx, wy}, size = {1200, 900}, output = dir .. "/n2.png" } end)
T.ok(not has(c, "set xtics"), "a wide panel keeps gnuplot's tics")

-- {== "wrote file" at the prompt
do
  local out = {}
  local real = io.stdout
  dm.config.interactive = true
  io.stdout = {write = function(self, ...) for i = 1, select("#", ...) do out[#out + 1] = select(i, ...) end return self end,
               flush = function() end}
  local ok, err = pcall(dm.plot, { {lx, ly}, output = dir .. "/w.png" })
  io.stdout = real
  dm.config.interactive = nil
  T.ok(ok, "plot at the prompt" .. (ok and "" or (": " .. tostring(err))))
  T.is(table.concat(out), "wrote " .. dir .. "/w.png\n", "one line names the file written")
end

-- {== every option in help and in errors
local byname = dm.docs()
local help = byname["dm.plot"].sig .. " " .. byname["dm.plot"].doc .. " " .. table.concat(byname["dm.plot"].opts, " ")
local gallery = H.read(os.getenv("DMECH_SRCDIR") .. "/examples/plot_gallery.lua")
local used, missing = {}, {}
for call in gallery:gmatch("dm%.plot(%b{})") do
  call = call:gsub('"[^"]*"', '""')
  for key in call:gmatch("[{,]%s*([%a_]+)%s*=") do used[key] = true end
end
for key in pairs(used) do
  if not help:find("%f[%w_]" .. key .. "%f[^%w_]") then missing[#missing + 1] = key end
end
table.sort(missing)
T.ok(next(used) ~= nil and #missing == 0, "help \"dm.plot\" names every option the gallery uses" ..
     (#missing > 0 and (": missing " .. table.concat(missing, ", ")) or ""))
local ok, err = pcall(dm.plot, { {lx, ly}, titel = "x" })
T.ok(not ok and tostring(err):find("unknown option 'titel' %(options: layout, output, size, terminal, enhanced, title,"),
     "an unknown option lists the options: " .. tostring(err))
T.is(require("dmech.help").hint(err), "\nhint: did you mean 'title'?", "and the prompt's hint names the right one")
ok, err = pcall(dm.plot, { {lx, ly, lengend = "x"} })
T.ok(not ok and tostring(err):find("unknown option 'lengend' %(options: with, legend, title, range, samples%)"),
     "an unknown series option lists the series options")
T.done()
