-- plot_errors.lua -- gnuplot's complaints become Lua errors with its text;
-- bad arguments are refused before anything is sent; user strings cannot
-- inject commands; a missing gnuplot gives a clear error and nothing else
-- breaks.
local T = require "dmech.test"
local dm = require "dmech"
local H = dofile(os.getenv("DMECH_SRCDIR") .. "/tests/lua/plot_helpers.lua")
H.need_gnuplot(T, dm)
local dir = T.tmpdir("plot_errors")
local out = dir .. "/e.png"
local x, y = dm.vec{0, 1, 2.385}, dm.vec{1, -0.5, 2.385}

-- checkpoint errors carry gnuplot's text and name the call
T.error_like(function() dm.plot{ {x, y, with = "foo"}, output = out } end,
  "^dm%.plot: gnuplot: unrecognized plot type %(at: plot .*with foo", "bad `with` style")
T.error_like(function() dm.plot{ {x, y}, xrange = {2.385, 2.385}, output = out } end,
  "^dm%.plot: gnuplot: .*empty x range", "bad (empty) range")
local fig = dm.figure{ output = out }
T.error_like(function() fig:add{ x, y, with = "nosuch" } end,
  "^figure:add: gnuplot: unrecognized plot type", "figure errors name the method")
fig:close()
T.error_like(function() dm.gnuplot("set xrange [1:2:3:]") end,
  "dm%.gnuplot: 'set xrange %[1:2:3:%]': gnuplot: expecting ']'", "dm.gnuplot errors surface")
T.is(dm.gnuplot("print 2.385*2"), "4.77", "dm.gnuplot returns what gnuplot printed")
dm.plot{ {x, y}, output = out, size = {300, 200} }
T.is(H.png_size(out), 300, "the session works after every error")

-- arguments are checked before anything is sent
local bad = {
  {function() dm.plot(3) end, "dm%.plot: a table {series%.%.%., options%.%.%.} expected, got number", "not a table"},
  {function() dm.plot{} end, "nothing to plot", "no series"},
  {function() dm.plot{ {{}, {}} } end, "nothing to plot %(every series is empty%)", "only empty series"},
  {function() dm.plot{ {x, y}, titel = "t" } end, "unknown option 'titel'", "misspelt option"},
  {function() dm.plot{ {x, y, colour = 1} } end, "series: unknown option 'colour'", "misspelt series option"},
  {function() dm.plot{ {x, {1, 2}} } end, "columns have different lengths %(3 and 2%)", "lengths differ"},
  {function() dm.plot{ {x, {1, "a", 3}} } end, "y: %(table of numbers expected, got string at index 2%)", "non-number"},
  {function() dm.plot{ {"x", "y"} } end, "element 1: expected a series", "strings are no series"},
  {function() dm.plot{ {math.sin} } end, "a function needs range = {a, b}", "function without range"},
  {function() dm.plot{ {function() end, range = {0, 1}} } end,
   "the function must return 1 to 3 numbers, got 0 values", "function returning nothing"},
  {function() dm.plot{ {function() return nil end, range = {0, 1}} } end,
   "the function returned nil %(value 1%) at 0", "function returning nil"},
  {function() dm.plot{ {function(t) if t > 0.5 then return "x" end return t end, range = {0, 1}} } end,
   "the function returned string %(value 1%) at 0%.5", "function returning a string later"},
  {function() dm.plot{ {x, y}, {x, y, y}, output = out } end, "2%-D and 3%-D series cannot share a panel", "2-D with 3-D"},
  {function() dm.plot{ {{x, y}, {x, y}}, output = out } end, "a list of series %(a panel%); give layout", "panel without layout"},
  {function() dm.plot{ {x, y}, {x, y}, {x, y}, layout = "1,2" } end, "layout 1,2 has room for 2 panels, got 3", "layout too small"},
  {function() dm.plot{ {x, y}, layout = "one" } end, "layout: \"rows,cols\" expected", "bad layout"},
  {function() dm.plot{ {x, y}, size = {0, 100}, output = out } end, "size: {width, height} with positive numbers", "bad size"},
  {function() dm.plot{ {x, y}, output = 3 } end, "output: file name expected, got number", "bad output"},
  {function() dm.plot{ {x, y}, xrange = {0, 0 / 0}, output = out } end, "xrange: finite numbers expected", "NaN range"},
  {function() dm.plot{ {x, y}, logscale = "y; system('x')", output = out } end, "logscale: axes like", "bad logscale"},
  {function() dm.plot{ {x, y}, key = "top; system('x')", output = out } end, "key: false, true or words", "bad key"},
  {function() dm.plot{ {x, y}, terminal = "png; system('x')", output = out } end,
   "terminal 'png; system%('x'%)': only plain words", "terminal with a command"},
  {function() dm.plot{ {x, y}, terminal = "nosuchterm", output = out } end, "no terminal 'nosuchterm'", "unknown terminal"},
  {function() dm.plot{ {x, y}, output = dir .. "/no/such/dir/x.png" } end, "plot output '.*no/such/dir/x%.png': cannot create a temporary file next to it: No such file or directory", "missing directory"},
  {function() dm.figure{}:splot{ {x, y} } end, "splot needs three", "splot with two columns"},
  {function() dm.figure{}:append(1, 1, 2) end, "no series 1", "append to a missing series"},
}
for _, b in ipairs(bad) do T.error_like(b[1], b[2], b[3]) end

-- without a display and with stdout not a terminal there is nowhere to show
if not os.getenv("DISPLAY") and not os.getenv("WAYLAND_DISPLAY") and not os.getenv("GNUTERM") then
  T.error_like(function() dm.plot{ {x, y} } end, "nowhere to show the plot.*output = ", "no display, no tty: asks for output=")
else
  T.skip("a display or GNUTERM is set")
end

-- injection: every user string renders literally, no command runs
local flag = dir .. "/injected"
os.remove(flag)
dm.gnuplot("m = \"system('touch " .. flag .. "')\"")   -- a macro an expansion would run
local nasty = "T' ; system(\"touch " .. flag .. "\") ; print '\n`touch " .. flag .. "` @m \\' \" ;@m x'y @m"
local svg = dir .. "/inject.svg"
dm.plot{ {x, y, title = nasty}, title = nasty, xlabel = nasty, ylabel = "@m", output = svg }
local cwdflag = "dmech_injected_flag"
os.remove(cwdflag)
local file_nasty = dir .. "/a'b @m `touch " .. cwdflag .. "`.svg"
dm.plot{ {x, y}, output = file_nasty }
local f = dm.figure{ title = nasty, output = dir .. "/inject2.svg" }
f:add{ x, y, title = nasty }
f:close()
T.ok(not H.exists(flag) and not H.exists(cwdflag), "no command ran (" .. flag .. " was not created)")
local info = H.svg(H.read(svg))
local texts = info and table.concat(info.texts, "|") or ""
T.ok(texts:find("T' ; system(\"touch ", 1, true) and texts:find("`touch ", 1, true)
     and texts:find("@m \\' \" ;@m x'y @m", 1, true), "the text renders literally")
T.ok(H.exists(file_nasty), "a file name with quotes, @ and backticks is used as it is")
T.error_like(function() dm.plot{ {x, y, with = "lines; system('touch " .. flag .. "')"}, output = out } end,
  "with: a plain style expected", "a style with a command is refused")
T.error_like(function() dm.plot{ {x, y, with = "lines `touch " .. flag .. "`"}, output = out } end,
  "with: a plain style expected", "a style with backticks is refused")
T.ok(not H.exists(flag), "still no command ran")

-- gnuplot missing: a clear error, everything else keeps working
dm._gp.stop()
dm._gp.program("/nonexistent/gnuplot")
T.error_like(function() dm.plot{ {x, y}, output = out } end,
  "^dm%.plot: gnuplot program '/nonexistent/gnuplot' not found; install gnuplot or set DMECH_GNUPLOT",
  "missing gnuplot: clear error")
T.error_like(function() dm.gnuplot("print 1") end, "dm%.gnuplot: gnuplot program .* not found", "dm.gnuplot too")
T.near((dm.vec{3, 4}):norm(), 5, 1e-15, "dm.vec still works")
dm._gp.program(false)
T.is(dm.gnuplot("print 6*7"), "42", "the real gnuplot again")

local cmd = "DMECH_GNUPLOT=/nonexistent " .. H.shq(os.getenv("DMECH")) .. " -e " .. H.shq(
  "local ok, e = pcall(dm.plot, {{dm.vec{1,2}, dm.vec{3,4}}, output='x.png'}) " ..
  "print(ok, e) print(dm.vec{3,4}:norm())") .. " 2>&1"
local p = io.popen(cmd)
local res = p:read("a")
p:close()
T.ok(res:find("false\tdm.plot: gnuplot program '/nonexistent' not found", 1, true) and res:find("\n5.0\n", 1, true),
     "DMECH_GNUPLOT=/nonexistent: clear error, dm.vec fine")
if not res:find("\n5.0\n", 1, true) then T.diag(res) end

-- a hung gnuplot is killed after the timeout and replaced
local script = dir .. "/hung-gnuplot.sh"
local sf = io.open(script, "w")
sf:write("#!/bin/sh\nexec sleep 100\n")
sf:close()
os.execute("chmod 755 " .. H.shq(script))
dm._gp.stop()
dm._gp.program(script)
dm._gp.timeout(0.5)
local t0 = os.time()
T.error_like(function() dm.plot{ {x, y}, output = out } end, "did not answer within 0%.5 s", "hung gnuplot: timeout error")
T.ok(os.time() - t0 <= 3, "within the timeout")
dm._gp.program(false)
dm._gp.timeout(30)
dm.plot{ {x, y}, output = out, size = {320, 200} }
T.is(H.png_size(out), 320, "recovered with the real gnuplot")
T.done()
