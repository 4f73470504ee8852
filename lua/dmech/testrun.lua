-- dmech.testrun -- `dmech test [options] [files or directories]`.
--
-- Finds every *_test.lua under the directories (and takes the files named),
-- runs each in a fresh dmech process (dm.test's _run_file: the file, then
-- done(), the TAP on descriptor 3 so that what the file prints is never
-- taken for a test line), several at a time, reads the TAP and reports per
-- file in the order of the files -- the same report whatever the number of
-- jobs -- then a summary.  The processes, directory listings and clock come
-- from src/app/testrun.c as `sys`.
local M = {}

local USAGE = [[
usage: dmech test [options] [files or directories]
Run every *_test.lua file under the directories (default: the current one,
hidden directories excepted) and the files named, each in a fresh dmech
process, several at a time, and report per file, then the summary.
Options:
  -j N, --jobs N     run N files at a time (default: the usable cores, %d)
  --filter TEXT      only the files whose path contains TEXT
  --tap              print one TAP stream (for prove and CI) instead
  -v, --verbose      also show every test line and the output of passing files
  -h, --help         show this help and exit
A test file uses dm.test (help "dm.test"); a file that raises an error, dies,
or ends without its plan is an error.  Exit status: 0 when every test passed
(skipped and TODO tests allowed), 1 when a test failed or a file errored or
no file was found, 2 for bad usage, 130 when interrupted.
]]

local function usage_error(msg)
  error({usage = msg}, 0)
end

-- {==== command line and files ============================================

local function parse_args(args)
  local o = {paths = {}, verbose = false, tap = false}
  local i = 1
  local function value(opt)
    i = i + 1
    if args[i] == nil then usage_error("option '" .. opt .. "' needs an argument") end
    return args[i]
  end
  while i <= #args do
    local a = args[i]
    if a == "--" then
      table.move(args, i + 1, #args, #o.paths + 1, o.paths)
      break
    elseif a == "-h" or a == "--help" then o.help = true
    elseif a == "--tap" then o.tap = true
    elseif a == "-v" or a == "--verbose" then o.verbose = true
    elseif a == "-j" or a == "--jobs" then o.jobs = value(a)
    elseif a:match("^%-j.") then o.jobs = a:sub(3)
    elseif a:match("^%-%-jobs=") then o.jobs = a:match("=(.*)")
    elseif a == "--filter" then o.filter = value(a)
    elseif a:match("^%-%-filter=") then o.filter = a:match("=(.*)")
    elseif a:sub(1, 1) == "-" then usage_error("unrecognized option '" .. a .. "'")
    else o.paths[#o.paths + 1] = a end
    i = i + 1
  end
  if o.jobs ~= nil then
    local n = math.tointeger(tonumber(o.jobs))
    if n == nil or n < 1 then usage_error("-j expects a positive integer, got '" .. o.jobs .. "'") end
    o.jobs = n
  end
  if #o.paths == 0 then o.paths[1] = "." end
  return o
end

local function join(dir, name)
  if dir == "." then return name end
  return dir:sub(-1) == "/" and dir .. name or dir .. "/" .. name
end

-- Depth first, by name: *_test.lua files, hidden entries skipped.
local function walk(sys, dir, out, depth)
  if depth > 40 then usage_error("directories nested deeper than 40 under '" .. dir .. "' (a link loop?)") end
  local names, kinds = sys.list(dir)
  if names == nil then usage_error("cannot read directory " .. kinds) end
  local idx = {}
  for k = 1, #names do idx[k] = k end
  table.sort(idx, function(a, b) return names[a] < names[b] end)
  for _, k in ipairs(idx) do
    local name = names[k]
    if name:sub(1, 1) ~= "." then
      local path = join(dir, name)
      if kinds[k] == "dir" then
        walk(sys, path, out, depth + 1)
      elseif kinds[k] == "file" and name:match("_test%.lua$") then
        out[#out + 1] = path
      end
    end
  end
end

local function find_files(sys, o)
  local files, seen = {}, {}
  for _, p in ipairs(o.paths) do
    local kind, err = sys.kind(p)
    if kind == nil then usage_error("cannot find " .. err) end
    local found = {}
    if kind == "dir" then walk(sys, p, found, 0) else found[1] = p end
    for _, f in ipairs(found) do
      if not seen[f] and (o.filter == nil or f:find(o.filter, 1, true)) then
        seen[f] = true
        files[#files + 1] = f
      end
    end
  end
  return files
end

-- }====

-- {==== reading TAP =========================================================

local function lines(text)
  local t = {}
  if text ~= "" and text:sub(-1) ~= "\n" then text = text .. "\n" end
  for line in text:gmatch("(.-)\n") do t[#t + 1] = line end
  return t
end

-- Split a description at its last "# TODO ..." / "# SKIP ..." directive.
local function directive(desc)
  local at, init = nil, 1
  while true do
    local s, e = desc:find("#", init, true)
    if s == nil then break end
    local word = desc:sub(e + 1):match("^%s*(%a+)")
    if word and (word:upper() == "TODO" or word:upper():sub(1, 4) == "SKIP") then at = s end
    init = e + 1
  end
  if at == nil then return desc end
  local word, why = desc:sub(at + 1):match("^%s*(%a+)%s*(.-)%s*$")
  return (desc:sub(1, at - 1):gsub("%s+$", "")), word:upper():sub(1, 4), why
end

local function parse(text)
  local r = {tests = {}, passed = 0, failed = 0, skipped = 0, todo = 0}
  local cur
  for _, line in ipairs(lines(text)) do
    local plan, rest = line:match("^1%.%.(%d+)(.*)$")
    local status, tail = line:match("^(not ok)(.*)$")
    if status == nil then status, tail = line:match("^(ok)(.*)$") end
    if plan then
      r.plan = tonumber(plan)
      r.skip_reason = rest:match("^%s*#%s*[Ss][Kk][Ii][Pp]%S*%s*(.-)%s*$")
      cur = nil
    elseif status and (tail == "" or tail:match("^%s")) then
      local desc = tail:match("^%s*%d*%s*(.-)%s*$"):gsub("^%-%s*", "")
      local name, dir, why = directive(desc)
      cur = {ok = status == "ok", name = name, dir = dir, why = why, line = line, diag = {}}
      r.tests[#r.tests + 1] = cur
      if dir == "SKIP" then r.skipped = r.skipped + 1
      elseif dir == "TODO" then r.todo = r.todo + 1
      elseif cur.ok then r.passed = r.passed + 1
      else r.failed = r.failed + 1 end
    elseif line:match("^#") and cur then
      cur.diag[#cur.diag + 1] = line
    end
  end
  return r
end

-- What became of a file: "pass" | "fail" | "error" | "skip", with a reason.
local function classify(job)
  local r = parse(job.tap ~= "" and job.tap or job.out)
  job.r = r
  local ntests = #r.tests
  local function plural(n, what) return n .. " " .. what .. (n == 1 and "" or "s") end
  if job.how == "spawn" then return "error", "could not start" end
  if job.how == "signal" then
    return "error", ("killed by signal %d after %s"):format(job.code, plural(ntests, "test"))
  end
  if r.plan == nil then
    if job.code == 2 then return "error", "raised an error after " .. plural(ntests, "test") end
    return "error", ("exit status %d without a plan after %s"):format(job.code, plural(ntests, "test"))
  end
  if r.plan == 0 and ntests == 0 then
    if r.skip_reason and job.code == 0 then return "skip", r.skip_reason ~= "" and r.skip_reason or "skipped" end
    return "error", "ran no tests"
  end
  if r.plan ~= ntests then
    return "error", ("planned %s, ran %d"):format(plural(r.plan, "test"), ntests)
  end
  if job.code ~= 0 and r.failed == 0 then return "error", "exit status " .. job.code end
  if r.failed > 0 then return "fail", ("%d of %s failed"):format(r.failed, plural(ntests, "test")) end
  local extra = ""
  if r.skipped > 0 then extra = extra .. ", " .. r.skipped .. " skipped" end
  if r.todo > 0 then extra = extra .. ", " .. r.todo .. " todo" end
  return "pass", plural(ntests, "test") .. extra
end

-- }====

-- {==== reports =============================================================

local function indent(out, text_lines, prefix, limit)
  local n = #text_lines
  local from = limit and n > limit and n - limit + 1 or 1
  if from > 1 then out(prefix .. "... " .. (from - 1) .. " earlier lines\n") end
  for k = from, n do out(prefix .. text_lines[k] .. "\n") end
end

local LABEL = {pass = "PASS ", fail = "FAIL ", error = "ERROR", skip = "SKIP "}

local function human_file(out, job, verbose)
  local secs = job.status == "skip" and "" or ("; %.2f s"):format(job.secs)
  out(("%s %s (%s%s)\n"):format(LABEL[job.status], job.path, job.reason, secs))
  if verbose then
    indent(out, lines(job.tap), "      ")
  elseif job.status == "fail" or job.status == "error" then
    for _, t in ipairs(job.r.tests) do
      if not t.ok and t.dir == nil then
        out("      " .. t.line .. "\n")
        indent(out, t.diag, "      ")
      end
    end
  end
  for _, stream in ipairs{"out", "err"} do
    local text = job[stream]
    if text ~= "" and (stream == "err" or job.tap ~= "")
       and (verbose or job.status == "fail" or job.status == "error") then
      out("      std" .. stream .. ":\n")
      indent(out, lines(text), "      | ", not verbose and 40 or nil)
    end
  end
end

-- One TAP stream: every file's tests renumbered, named "path: name".
local function tap_file(out, job, state)
  out("# " .. job.path .. "\n")
  local function line(ok, desc, dir, why)
    state.n = state.n + 1
    out(("%s %d - %s%s\n"):format(ok and "ok" or "not ok", state.n, desc,
      dir and (" # " .. dir .. (why ~= "" and (" " .. why) or "")) or ""))
  end
  if job.status == "skip" then
    line(true, job.path, "SKIP", job.reason)
    return
  end
  for _, t in ipairs(job.r.tests) do
    line(t.ok, job.path .. (t.name ~= "" and (": " .. t.name) or ""), t.dir, t.why)
    for _, d in ipairs(t.diag) do out(d .. "\n") end
  end
  if job.status == "error" then line(false, job.path .. ": " .. job.reason) end
  if job.status == "error" or job.status == "fail" then
    for _, stream in ipairs{"out", "err"} do
      if job[stream] ~= "" and (stream == "err" or job.tap ~= "") then
        out("# std" .. stream .. ":\n")
        indent(out, lines(job[stream]), "#   ")
      end
    end
  end
end

local function summary(jobs, nfiles, wall, njobs, interrupted)
  local c = {passed = 0, failed = 0, skipped = 0, todo = 0}
  local files = {pass = 0, fail = 0, error = 0, skip = 0}
  local done = {}
  for _, job in ipairs(jobs) do
    if job.status then
      done[#done + 1] = job
      files[job.status] = files[job.status] + 1
      for k in pairs(c) do c[k] = c[k] + job.r[k] end
    end
  end
  local s = ("%d passed, %d failed"):format(c.passed, c.failed)
  if c.skipped > 0 then s = s .. ", " .. c.skipped .. " skipped" end
  if c.todo > 0 then s = s .. ", " .. c.todo .. " todo" end
  local f = {}
  for _, k in ipairs{"pass", "fail", "error", "skip"} do
    if files[k] > 0 then
      f[#f + 1] = files[k] .. " " .. ({pass = "passed", fail = "failed", error = "errored", skip = "skipped"})[k]
    end
  end
  s = ("%s; %d file%s: %s (%.2f s, %d job%s)"):format(s, #done, #done == 1 and "" or "s",
    table.concat(f, ", "), wall, njobs, njobs == 1 and "" or "s")
  if interrupted then s = s .. "\ninterrupted after " .. #done .. " of " .. nfiles .. " files" end
  table.sort(done, function(a, b) return a.secs > b.secs end)
  local slow = {}
  for k = 1, math.min(3, #done) do slow[k] = ("%.2f s %s"):format(done[k].secs, done[k].path) end
  return s, "slowest: " .. table.concat(slow, ", "), files
end

-- }====

function M.main(args, sys)
  local ncpu = sys.ncpu()
  local o, files
  local ok, err = pcall(function()
    o = parse_args(args)
    if not o.help then files = find_files(sys, o) end
  end)
  if not ok then
    if type(err) ~= "table" or not err.usage then error(err, 0) end
    io.stderr:write("dmech test: ", err.usage, "\n(dmech test --help shows the options)\n")
    return 2
  end
  if o.help then
    io.stdout:write(USAGE:format(ncpu))
    return 0
  end
  if #files == 0 then
    io.stderr:write("dmech test: no *_test.lua files in ", table.concat(o.paths, ", "),
      o.filter and (" whose path contains '" .. o.filter .. "'") or "", "\n")
    return 1
  end

  local exe = sys.exe() or sys.argv0
  local jobs, argvs = {}, {}
  for k, path in ipairs(files) do
    jobs[k] = {path = path}
    argvs[k] = {exe, "-e", ('require("dmech.test")._run_file(%q, 3)'):format(path)}
  end
  local njobs = math.min(o.jobs or ncpu, #files)
  local out = function(s) io.stdout:write(s) end
  local tapstate = {n = 0}
  local printed = 0
  local t0 = sys.clock()
  local interrupted = sys.run(argvs, njobs, function(k, how, code, stdout, stderr, tap, secs)
    local job = jobs[k]
    job.how, job.code, job.out, job.err, job.tap, job.secs = how, code, stdout, stderr, tap, secs
    job.status, job.reason = classify(job)
    -- report in file order, whatever order the files finish in
    while jobs[printed + 1] and jobs[printed + 1].status do
      printed = printed + 1
      if o.tap then tap_file(out, jobs[printed], tapstate) else human_file(out, jobs[printed], o.verbose) end
    end
    io.stdout:flush()
  end)
  local line, slow, files_by = summary(jobs, #files, sys.clock() - t0, njobs, interrupted)
  if o.tap then
    out("1.." .. tapstate.n .. "\n")
    out("# " .. line:gsub("\n", "\n# ") .. "\n")
  else
    out(line .. "\n" .. slow .. "\n")
  end
  io.stdout:flush()
  if interrupted then return 130 end
  return (files_by.fail + files_by.error > 0) and 1 or 0
end

return M
