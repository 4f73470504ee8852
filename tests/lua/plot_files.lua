-- plot_files.lua -- dm.plot writes complete, valid files: PNG of the asked
-- size, well-formed SVG with one plotted path group per series, PDF, and a
-- text (dumb) plot identical to the stored transcript.
local T = require "dmech.test"
local dm = require "dmech"
local H = dofile(os.getenv("DMECH_SRCDIR") .. "/tests/lua/plot_helpers.lua")
H.need_gnuplot(T, dm)
local dir = T.tmpdir("plot_files")

local x = dm.linspace(0, 2.385, 200)
local y = x:map(math.sin)

-- PNG: signature, IHDR size as asked; complete when the call returns
local png = dir .. "/curve.png"
os.remove(png)
dm.plot{ {x, y, title = "sin"}, title = "a curve", xlabel = "t", ylabel = "sin t",
         output = png, size = {413, 227} }
local w, h = H.png_size(png)
T.ok(w == 413 and h == 227, "PNG 413x227 as asked (got " .. tostring(w) .. "x" .. tostring(h) .. ")")
local bytes = H.read(png)
T.ok(bytes and bytes:sub(-8, -5) == "IEND", "PNG ends with its IEND chunk: complete on return")

-- no size: the default, not the size of the previous plot
dm.plot{ {x, y}, output = dir .. "/default.png" }
w, h = H.png_size(dir .. "/default.png")
T.ok(w == 640 and h == 480, "default PNG size 640x480 (got " .. tostring(w) .. "x" .. tostring(h) .. ")")

-- shorthand: dm.plot{x, y, ...} and dm.plot{y, ...} are one series
dm.plot{ x, y, title = "shorthand", output = dir .. "/short.svg" }
local sinfo = H.svg(H.read(dir .. "/short.svg"))
T.ok(sinfo and #sinfo.groups == 1, "dm.plot{x, y, ...} plots one series")
dm.plot{ {2.385, 1, 3}, output = dir .. "/index.svg" }
sinfo = H.svg(H.read(dir .. "/index.svg"))
T.ok(sinfo and #sinfo.groups == 1, "dm.plot{y} plots y against its index")

-- a 1x2 multiplot in one PNG
dm.plot{ {{x, y, title = "sin"}, {x, x:map(math.cos), title = "cos"}, title = "left"},
         {function(t) return t * t end, range = {0, 2.385}, title = "t^2"},
         layout = "1,2", output = dir .. "/multi.png", size = {800, 300}, title = "two panels" }
w, h = H.png_size(dir .. "/multi.png")
T.ok(w == 800 and h == 300, "multiplot PNG 800x300")

-- SVG: well formed, one group with a path per series
local svg = dir .. "/three.svg"
dm.plot{ {x, y, title = "one"}, {x, x:map(math.cos), title = "two", with = "lines lw 2"},
         {function(t) return t / 2.385 end, range = {0, 2.385}, samples = 50, title = "three"},
         output = svg, size = {500, 350} }
local info, err = H.svg(H.read(svg))
T.ok(info ~= nil, "SVG is well formed" .. (err and (": " .. err) or ""))
info = info or {groups = {}, texts = {}}
T.ok(info.width == 500 and info.height == 350, "SVG size 500x350")
T.is(#info.groups, 3, "three plotted series in the SVG")
local paths_ok = #info.groups == 3
for _, n in ipairs(info.groups) do paths_ok = paths_ok and n >= 1 end
T.ok(paths_ok, "each series group holds a path")

-- 3-D: three columns give splot
local t = dm.linspace(0, 12.566, 400)
dm.plot{ {t:map(math.cos), t:map(math.sin), t * 0.1, title = "helix"},
         {function(s) return math.cos(s) * 0.5, math.sin(s) * 0.5, 0 end, range = {0, 6.2832},
          title = "ring"},
         output = dir .. "/helix.svg", xlabel = "x", ylabel = "y", zlabel = "z", view = {60, 30} }
info, err = H.svg(H.read(dir .. "/helix.svg"))
T.ok(info and #info.groups == 2, "3-D plot: well-formed SVG with two series" .. (err and (": " .. err) or ""))

-- PDF
local pdf = dir .. "/curve.pdf"
dm.plot{ {x, y}, output = pdf, size = {360, 216} }
local p = H.read(pdf) or ""
T.ok(p:sub(1, 5) == "%PDF-", "PDF header")
T.ok(p:find("%%%%EOF%s*$") ~= nil, "PDF trailer: the file is complete")

-- dumb: a known curve against the stored transcript
local txt = dir .. "/parabola.txt"
dm.plot{ {function(s) return s * s end, range = {0, 2.385}, samples = 40, title = "t^2"},
         output = txt, size = {60, 18}, title = "parabola", xlabel = "t" }
local want = H.read(os.getenv("DMECH_SRCDIR") .. "/tests/data/plot_dumb_parabola.txt")
local got = H.read(txt)
T.ok(want and got and H.normalized(got) == H.normalized(want), "dumb plot matches tests/data/plot_dumb_parabola.txt")
if want and got and H.normalized(got) ~= H.normalized(want) then T.diag(got) end

-- the same plot on the dumb terminal goes to standard output
local out = H.capture(dm.plot, { {function(s) return s * s end, range = {0, 2.385}, samples = 40,
  title = "t^2"}, terminal = "dumb", size = {60, 18}, title = "parabola", xlabel = "t" })
T.ok(want and H.normalized(out) == H.normalized(want), "terminal = \"dumb\" prints the same plot on stdout")

-- sixel on request: an image on stdout between DCS "ESC P ... q" and ST
local terms = dm._gp.terminals()
if (" " .. terms .. " "):find(" sixelgd ", 1, true) then
  local img = H.capture(dm.plot, { {x, y}, terminal = "sixel", size = {200, 100} })
  T.ok(img:match("^\27P[%d;]*q") and img:sub(-2) == "\27\\" and #img > 500,
       "terminal = \"sixel\" writes a sixel image to stdout (" .. #img .. " bytes)")
else
  T.skip("this gnuplot has no sixelgd terminal")
end

-- a file name with a quote, a backslash, ; and spaces
local odd = dir .. "/it's a \\ file; too.png"
dm.plot{ {x, y}, output = odd, size = {200, 100} }
w = H.png_size(odd)
T.is(w, 200, "file name with quote, backslash and ;")

-- a failed plot leaves an existing file untouched and no temporary behind
local before = H.read(png)
T.error_like(function() dm.plot{ {x, y, with = "nosuchstyle"}, output = png } end,
  "unrecognized plot type", "bad style into an existing file fails")
T.ok(H.read(png) == before, "the existing file is untouched")
local p2 = io.popen("ls -a " .. H.shq(dir) .. " | grep -c '\\.tmp$'")
T.is(tonumber(p2:read("a")), 0, "no temporary files left")
p2:close()

-- unknown extension: clear error, nothing written
T.error_like(function() dm.plot{ {x, y}, output = dir .. "/x.xyz" } end,
  "unknown plot file extension '%.xyz'", "unknown extension")
T.ok(not H.exists(dir .. "/x.xyz"), "nothing written for it")
T.done()
