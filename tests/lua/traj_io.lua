-- traj_io.lua -- traj:save / dm.load_trajectory: exact round trips, the file
-- format, atomic writes, and clear messages for bad files.
local T = require "dmech.test"
local dm = require "dmech"
local dir = T.tmpdir("traj_io")

local vals = {2.385, 1 / 3, 1e-300, -0.0, 1.7976931348623157e308, 4.9406564584124654e-324,
              -123456789.12345679, math.pi, 0.1 + 0.2, 1e22, math.huge, -math.huge}
local n = #vals
local t, q1, q2, p1, p2, ex = {}, {}, {}, {}, {}, {}
for k = 1, n do
  t[k] = k * 0.1
  q1[k], q2[k] = vals[k], vals[(k + 2) % n + 1]
  p1[k], p2[k] = -vals[k], vals[(k + 5) % n + 1]
  ex[k] = vals[(k + 7) % n + 1]
end
local tr = dm.trajectory{t = t, coords = {"x", "y"}, q = {x = q1, y = q2}, p = {x = p1, y = p2},
  columns = {energy = ex}, meta = {system = 'Kepler "e=0.6"', note = "line1\nline2\\tab\t", h = 0.01}}
local file = dir .. "/rt.csv"
T.is(tr:save(file), true, "save returns true")
local back, err = dm.load_trajectory(file)
T.ok(back ~= nil, "load " .. tostring(err))

local function bits(x) return string.pack("<d", x) end
local same = #back == n
for _, name in ipairs(tr:names()) do
  local a, b = tr:column(name), back:column(name)
  for k = 1, n do
    if bits(a[k]) ~= bits(b[k]) then same = false end
  end
end
T.ok(same, "every value round-trips bit for bit (2.385, 1/3, 1e-300, -0.0, DBL_MAX, denormal, inf)")
T.is(1 / back:column("x")[4], -math.huge, "-0.0 keeps its sign")
T.is(table.concat(back:names(), ","), table.concat(tr:names(), ","), "names round-trip")
T.is(back:kinds().energy, "diag", "kinds round-trip")
local m = back:meta()
T.ok(m.system == 'Kepler "e=0.6"' and m.note == "line1\nline2\\tab\t" and m.h == 0.01,
     "metadata with quotes, newline, backslash and tab round-trips, numbers as numbers")
T.is(tostring(back), tostring(tr), "tostring identical after the round trip")

-- the file: magic, metadata comments, kinds, header, %.17g numbers
local f = assert(io.open(file))
local text = f:read("a")
f:close()
T.ok(text:find("^# dmech trajectory 2\n"), "first line is the format magic (version 2: numeric metadata)")
T.ok(text:find("\n# meta note=line1\\nline2\\\\tab\\t\n", 1, true), "escaped metadata line")
T.ok(text:find("\n# number h=0.01\n", 1, true), "numeric metadata line")
T.ok(text:find("\n# kinds t,q,q,p,p,diag\nt,x,y,p_x,p_y,energy\n", 1, true), "kinds and header lines")
T.ok(text:find("\n0.10000000000000001,2.3849999999999998,", 1, true), "numbers as %.17g")

-- overwrite atomically: a failed save keeps the old file and leaves no temporary
T.is(tr:slice(1, 3):save(file), true, "overwrite")
T.is(#assert(dm.load_trajectory(file)), 3, "the new content replaced the old")
local ok, msg = tr:save(dir .. "/no/such/dir/x.csv")
T.ok(ok == nil and msg:find("cannot create a temporary file next to it: No such file or directory"),
     "save into a missing directory: nil, " .. tostring(msg))
ok, msg = tr:save("/proc/dmech-traj.csv")
T.ok(ok == nil and msg:find("cannot create a temporary file"), "save into /proc: nil, " .. tostring(msg))
local leftovers = io.popen("ls -a '" .. dir .. "'"):read("a")
T.ok(not leftovers:find("%.tmp%-"), "no temporary files left behind")

-- reading errors: nil plus a message with the file and line
local function load_text(name, body)
  local g = assert(io.open(dir .. "/" .. name, "w"))
  g:write(body)
  g:close()
  return dm.load_trajectory(dir .. "/" .. name)
end
local r, e = dm.load_trajectory(dir .. "/missing.csv")
T.ok(r == nil and e:find("cannot open '.-missing.csv': No such file or directory"), "missing file: " .. tostring(e))
r, e = load_text("short.csv", "t,a\n1,2\n3\n")
T.ok(r == nil and e:find("short.csv:3: expected 2 comma%-separated numbers, got 1"), "short line: " .. tostring(e))
r, e = load_text("word.csv", "t,a\n1,two\n")
T.ok(r == nil and e:find("word.csv:2: field 2 %(column 'a'%): 'two' is not a number"), "bad number: " .. tostring(e))
r, e = load_text("hdr.csv", "time,a\n1,2\n")
T.ok(r == nil and e:find("hdr.csv:1: the first column must be 't'"), "bad header: " .. tostring(e))
r, e = load_text("kinds.csv", "# dmech trajectory 1\n# kinds t,q,p\nt,r,p_z\n")
T.ok(r == nil and e:find("kinds.csv:3: expected momentum column 'p_r'"), "inconsistent kinds: " .. tostring(e))
r, e = load_text("empty.csv", "")
T.ok(r == nil and e:find("no header line"), "empty file: " .. tostring(e))

-- a plain CSV from elsewhere loads as data columns
r = load_text("plain.csv", "t,E\n0,-0.5\n0.5,-0.49999999999999994\n")
T.ok(r and #r == 2 and r:column("E")[2] == -0.49999999999999994 and r:kinds().E == "data",
     "plain CSV: data columns")
os.execute("rm -rf '" .. dir .. "'")
T.done()
