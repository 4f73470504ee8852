-- dmech.test -- TAP output for dmech's Lua test scripts.
--
--   local T = require "dmech.test"
--   T.plan(3)                       -- optional; done() prints it otherwise
--   T.ok(cond, "name")
--   T.is(got, want, "name")         -- equality (numbers, strings, booleans)
--   T.near(got, want, tol, "name")  -- |got-want| <= tol*max(1,|want|)
--   T.error_like(f, "pattern", "name")  -- f must raise an error matching pattern
--   T.skip("reason") ; T.skip_all("reason") ; T.diag("text")
--   T.done()                        -- exits 0 iff every test passed
local T = {}
local n, failed, planned = 0, 0, nil

local function report(pass, name, extra)
  n = n + 1
  if not pass then failed = failed + 1 end
  io.stdout:write(pass and "ok " or "not ok ", n, " - ", (name or ""):gsub("\n", " "), "\n")
  if not pass and extra then
    for line in (extra .. "\n"):gmatch("(.-)\n") do io.stdout:write("#   ", line, "\n") end
  end
  io.stdout:flush()
  return pass
end

function T.plan(k)
  planned = k
  io.stdout:write("1..", k, "\n")
end

function T.diag(msg)
  for line in (tostring(msg) .. "\n"):gmatch("(.-)\n") do io.stdout:write("# ", line, "\n") end
end

function T.ok(cond, name)
  return report(not not cond, name)
end

function T.is(got, want, name)
  return report(got == want, name,
    string.format("got:  %s\nwant: %s", tostring(got), tostring(want)))
end

function T.near(got, want, tol, name)
  local pass = type(got) == "number" and type(want) == "number" and
    math.abs(got - want) <= tol * math.max(1, math.abs(want))
  return report(pass, name, string.format("got:  %.17g\nwant: %.17g\ntol:  %g", tonumber(got) or 0/0,
    tonumber(want) or 0/0, tol))
end

function T.error_like(f, pattern, name)
  local ok, err = pcall(f)
  if ok then return report(false, name, "no error raised") end
  err = tostring(err)
  return report(err:find(pattern) ~= nil, name,
    string.format("error: %s\nwanted pattern: %s", err, pattern))
end

function T.skip(reason)
  n = n + 1
  io.stdout:write("ok ", n, " # SKIP ", reason or "", "\n")
end

function T.skip_all(reason)
  io.stdout:write("1..0 # SKIP ", reason or "", "\n")
  os.exit(0)
end

function T.done()
  if planned == nil then io.stdout:write("1..", n, "\n") end
  if planned and planned ~= n then
    io.stdout:write("# planned ", planned, " tests but ran ", n, "\n")
    failed = failed + 1
  end
  io.stdout:flush()
  os.exit(failed == 0 and 0 or 1)
end

-- A temporary directory under the build tree for this script's files.
function T.tmpdir(name)
  local base = os.getenv("DMECH_TESTTMP") or "."
  local dir = base .. "/" .. (name or "t")
  os.execute("mkdir -p '" .. dir:gsub("'", "'\\''") .. "'")
  return dir
end

return T
