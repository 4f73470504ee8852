-- dmech.help -- help() and apropos() over the documentation registry that
-- every binding module fills (dm.docs()), and the hints the prompt adds to
-- error messages (did-you-mean and friends).
--
-- Names in the registry follow one scheme: "dm.f" for functions,
-- "<class>:<method>" for methods and "<class>.<field>" for fields
-- ("integrator:run", "routh.routhian").  help also accepts the prefixes the
-- signatures use ("tr:column", "sys.coords", "I:run"), '.' for ':' and the
-- bare member name ("run").  Text is wrapped to the terminal's width.
local M = {}
local dm = require "dmech.core"

local function out(...) io.stdout:write(...) end

-- {==== wrapping ===========================================================

local function width()
  local w = dm._termwidth and dm._termwidth()
  if type(w) ~= "number" then w = 80 end
  return math.max(w, 30)
end

-- Words of `text` wrapped to lines of at most `w` columns, the first
-- starting after `first` (a prefix already written), the others indented by
-- `indent` spaces.  A word longer than a line stands alone on its line.
local function wrap(text, w, first, indent)
  local lines, line = {}, first or ""
  local pad = string.rep(" ", indent or 0)
  local fresh = true
  for word in text:gmatch("%S+") do
    local len = utf8.len(line) or #line
    local wl = utf8.len(word) or #word
    if not fresh and len + 1 + wl > w then
      lines[#lines + 1] = line
      line, fresh = pad, true
      len = #pad
    end
    line = line .. (fresh and "" or " ") .. word
    fresh = false
  end
  lines[#lines + 1] = line
  return table.concat(lines, "\n")
end
M.wrap = wrap

-- }====

-- {==== the registry =======================================================

local function sorted_names(docs, pred)
  local names = {}
  for name, rec in pairs(docs) do
    if pred(name, rec) then names[#names + 1] = name end
  end
  table.sort(names)
  return names
end

local function show(rec)
  local w = width()
  out(wrap(rec.sig, w, "", 4), "\n")
  out(wrap(rec.doc, w, "  ", 2), "\n")
  if type(rec.opts) == "table" and #rec.opts > 0 then
    out(wrap(table.concat(rec.opts, ", "), w, "  Options: ", 11), "\n")
  end
end

-- One line (or a few) per entry: the signature, then the sentence beside it
-- when there is room, else below it.
local function show_entry(rec, w)
  local sig = rec.sig
  local col = w >= 100 and 46 or 40
  if #sig <= col - 4 and w - col >= 30 then
    out(wrap(rec.doc, w, "  " .. sig .. string.rep(" ", col - 2 - #sig), col), "\n")
  else
    out(wrap(sig, w, "  ", 6), "\n")
    out(wrap(rec.doc, w, "      ", 6), "\n")
  end
end

-- The entries whose names start with one of the prefixes, under a heading.
local function show_group(docs, prefix, heading)
  -- internal entries (dm._gp.send) only when asked for by their prefix
  local internal = prefix:find("[:.]_") ~= nil
  local names = sorted_names(docs, function(name)
    return name:sub(1, #prefix) == prefix and (internal or not name:find("[:.]_"))
  end)
  if #names > 0 and heading then out(heading, "\n") end
  local w = width()
  for _, name in ipairs(names) do show_entry(docs[name], w) end
  return #names
end

local function overview(docs)
  local w = width()
  out(wrap("dmech -- computational geometric mechanics at a Lua prompt.  help(f) or "
        .. "help \"name\" describes a function, method or field (help \"dm.plot\", "
        .. "help \"integrator:run\", help \"routh.routhian\"), help(obj) or help \"vec\" "
        .. "a whole class, apropos \"word\" searches every description; "
        .. "dm.traceback() shows the whole traceback of the last error.  "
        .. "Modules and classes:", w), "\n")
  local groups = {}
  for name in pairs(docs) do
    local g = name:match("^(.-)[:.][^:.]*$") or name
    if g:sub(1, 1) ~= "_" and not g:find("%._") then groups[g] = (groups[g] or 0) + 1 end
  end
  local gs = {}
  for g, n in pairs(groups) do gs[#gs + 1] = string.format("  %-16s %d entries", g, n) end
  table.sort(gs)
  out(table.concat(gs, "\n"), "\n")
end

local function classname(x)
  local mt = getmetatable(x)
  if type(mt) == "table" then
    local name = rawget(mt, "__name")
    if type(name) == "string" then return name end
  end
end

-- The kinds of the classes with documented methods or fields.
local function classes(docs)
  local k = {}
  for name in pairs(docs) do
    local c = name:match("^([%w_]+)[:.]")
    if c and c ~= "dm" then k[c] = true end
  end
  return k
end

local function show_class(docs, cls)
  local n = show_group(docs, cls .. ":", cls .. " methods:")
  return n + show_group(docs, cls .. ".", cls .. " fields:")
end

-- {==== did you mean =======================================================

-- Optimal string alignment distance (Damerau-Levenshtein with adjacent
-- transpositions), case-insensitive.
local function distance(a, b)
  a, b = a:lower(), b:lower()
  local la, lb = #a, #b
  if math.abs(la - lb) > 3 then return 99 end
  local d = {}
  for i = 0, la do d[i] = {[0] = i} end
  for j = 0, lb do d[0][j] = j end
  for i = 1, la do
    for j = 1, lb do
      local cost = a:byte(i) == b:byte(j) and 0 or 1
      local v = math.min(d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost)
      if i > 1 and j > 1 and a:byte(i) == b:byte(j - 1) and a:byte(i - 1) == b:byte(j) then
        v = math.min(v, d[i - 2][j - 2] + 1)
      end
      d[i][j] = v
    end
  end
  return d[la][lb]
end
M.distance = distance

-- The candidates closest to word (at most 3), or an empty list.
local function nearest(word, candidates)
  local limit = #word <= 1 and 0 or (#word <= 4 and 1 or (#word <= 8 and 2 or 3))
  local best, seen = {}, {}
  for _, c in ipairs(candidates) do
    if type(c) == "string" and c ~= word and not seen[c] then
      seen[c] = true
      local dd = distance(word, c)
      if dd <= limit then best[#best + 1] = {c, dd} end
    end
  end
  table.sort(best, function(x, y)
    if x[2] ~= y[2] then return x[2] < y[2] end
    return x[1] < y[1]
  end)
  local r = {}
  for i = 1, math.min(3, #best) do
    if best[i][2] == best[1][2] then r[#r + 1] = best[i][1] end
  end
  return r
end
M.nearest = nearest

local function quoted(list, fmt)
  local q = {}
  for i, s in ipairs(list) do q[i] = string.format(fmt or "'%s'", s) end
  if #q == 1 then return q[1] end
  return table.concat(q, ", ", 1, #q - 1) .. " or " .. q[#q]
end

local function split_list(s)
  local t = {}
  for w in s:gmatch("[^,%s]+") do t[#t + 1] = (w:gsub(":<.*>$", "")) end
  return t
end

-- }====

function M.help(x)
  local docs, byval = dm.docs()
  if x == nil then return overview(docs) end
  if type(x) ~= "string" then
    local rec = byval[x]
    if rec then
      show(rec)
      if type(x) == "table" then show_group(docs, rec.name .. ".") end  -- a module: its members
      return
    end
    local cls = classname(x)
    if cls and show_class(docs, cls) > 0 then return end
    out("no help for this ", type(x), " value\n")
    return
  end
  local name = x
  local rec = docs[name] or docs["dm." .. name]
  local kinds = classes(docs)
  if rec then
    show(rec)
    show_group(docs, rec.name .. ".")      -- a module (dm.test): its members
    if kinds[name] then show_class(docs, name) end   -- dm.mat and the class mat
    return
  end
  if kinds[name] and show_class(docs, name) > 0 then return end
  if show_group(docs, name .. ".") > 0 then return end
  local prefix, sep, member = name:match("^(.-)([:.])([%w_]+)$")
  if member then
    -- a class with the other separator: "integrator.run", "routh:routhian"
    local other = prefix .. (sep == ":" and "." or ":") .. member
    if kinds[prefix] and docs[other] then return show(docs[other]) end
    -- the prefix a signature uses: "tr:column", "sys.coords", "I:run"
    local hits = sorted_names(docs, function(n, r)
      local s = r.sig:match("^[%w_%.:]+")
      return s == name or s == other
    end)
    if #hits == 0 then
      hits = sorted_names(docs, function(n)
        return n:match("^[%w_]+[:.]" .. member .. "$") and not n:match("^dm%.")
      end)
    end
    if #hits > 0 then
      for _, n in ipairs(hits) do show(docs[n]) end
      return
    end
  end
  -- a bare method or function name: every entry ending in it
  local hits = sorted_names(docs, function(n) return n:match("[:.]" .. name:gsub("%p", "%%%0") .. "$") end)
  if #hits > 0 then
    for _, n in ipairs(hits) do show(docs[n]) end
    return
  end
  local all = {}
  for n in pairs(docs) do all[#all + 1] = n end
  local near = nearest(name, all)
  if #near == 0 then
    local tail = {}
    for n in pairs(docs) do tail[#tail + 1] = n:match("[:.]([%w_]+)$") end
    near = nearest(name:match("[%w_]+$") or name, tail)
  end
  out("no help for '", name, "'", #near > 0 and ("; did you mean " .. quoted(near, "\"%s\"") .. "?") or "",
      "; try apropos \"", name, "\"\n")
end

function M.apropos(word)
  if type(word) ~= "string" then
    error("bad argument #1 to 'apropos' (string expected, got " .. type(word) .. ")", 2)
  end
  local docs = dm.docs()
  local w = word:lower()
  local names = sorted_names(docs, function(name, rec)
    return name:lower():find(w, 1, true) or rec.doc:lower():find(w, 1, true)
  end)
  if #names == 0 then
    out("nothing about '", word, "'\n")
    return
  end
  local tw = width()
  for _, name in ipairs(names) do show_entry(docs[name], tw) end
end

-- {==== hints for error messages ===========================================

-- The identifier keys of a table (raw), and of the tables in it one level
-- down when `deep`.
local function keys_of(t, acc, deep, seen)
  acc, seen = acc or {}, seen or {}
  if type(t) ~= "table" or seen[t] then return acc end
  seen[t] = true
  for k, v in next, t do
    if type(k) == "string" and k:match("^[%a_][%w_]*$") then
      acc[#acc + 1] = k
      if deep and type(v) == "table" and k ~= "_G" and k ~= "package" then keys_of(v, acc, false, seen) end
    end
  end
  return acc
end

-- The option keys documented for the function named in a message ("dm.routh",
-- "run" for integrator:run).
local function documented_opts(fname)
  local docs = dm.docs()
  local rec = docs[fname]
  if not rec then
    for n, r in pairs(docs) do
      if r.opts and n:match("[:.]" .. fname:gsub("%p", "%%%0") .. "$") then rec = r break end
    end
  end
  return rec and rec.opts
end

local function mean(near, fmt)
  if near and #near > 0 then return "did you mean " .. quoted(near, fmt) .. "?" end
end

-- The text of line n of a chunk's source ("@file" or the REPL's chunk).
local function source_line(info)
  if not info.source or not info.line then return nil end
  if info.source:sub(1, 1) == "@" then
    local f = io.open(info.source:sub(2), "r")
    if not f then return nil end
    local i = 0
    for l in f:lines() do
      i = i + 1
      if i == info.line then f:close() return l end
    end
    f:close()
  elseif type(info.chunk) == "string" then
    local i = 0
    for l in (info.chunk .. "\n"):gmatch("([^\n]*)\n") do
      i = i + 1
      if i == info.line then return l end
    end
  end
end

local MATH_IN_DM = {}
for _, f in ipairs{"abs", "acos", "asin", "atan", "cos", "exp", "log", "sin", "sqrt", "tan",
                   "cosh", "sinh", "tanh"} do MATH_IN_DM[f] = true end

-- A hint for an error message, or "" (msg: the message; info: what the
-- prompt's handler saw -- name/namewhat/what of the function that raised,
-- source/line of the innermost Lua frame, traceback, chunk).  Never raises
-- on odd input.
function M.hint(msg, info)
  info = info or {}
  local h = M._hint(tostring(msg), info)
  if h then return "\nhint: " .. h end
  return ""
end

function M._hint(msg, info)
  local docs = dm.docs()
  -- unknown option X (options: a, b, c) | unknown option 'X'
  local fname, key = msg:match("([%w_%.:]+): unknown option '?([%w_]+)'?")
  if key then
    local list = msg:match("%(options: ([^)]*)%)")
    return mean(nearest(key, list and split_list(list) or documented_opts(fname) or {}))
  end
  local word, list = msg:match("unknown integration method '([^']+)' %(known: ([^)]*)%)")
  if word then return mean(nearest(word, split_list(list)), "\"%s\"") end
  word, list = msg:match("no column '([^']+)' %(available: ([^)]*)%)")
  if word then return mean(nearest(word, split_list(list)), "\"%s\"") end
  word, list = msg:match("unknown coordinate '?([%w_]+)'? %(coordinates: ([^)]*)%)")
  if word then return mean(nearest(word, split_list(list))) end
  -- p.m, v.y in L: a parameter not declared, a coordinate misspelt
  local vec
  word, vec, list = msg:match("no element '([%w_]+)' in ([%w_]+) %(elements: ([^)]*)%)")
  if word then
    local cands = {}
    for _, e in ipairs(split_list(list)) do cands[#cands + 1] = (e:gsub("^v_", "")) end
    local near = nearest(word, cands)
    if vec == "p" then
      local s = string.format("parameters are declared in dm.system{params = {%s = ...}} and read as p.%s",
                              word, word)
      if #near > 0 then s = mean(near) .. "; " .. s end
      return s
    end
    return mean(near)
  end
  local cls
  cls, word, list = msg:match("([%w_]+) has no field or method '([^']+)' %(fields: ([^)]*)%)")
  if word then
    local cands = split_list(list)
    for n in pairs(docs) do
      local m = n:match("^" .. cls .. ":([%w_]+)$")
      if m then cands[#cands + 1] = m end
    end
    return mean(nearest(word, cands))
  end
  -- math.cos(q.x) in L: math functions take numbers only
  local f = msg:match("bad argument #%d+ to '([%w_]+)' %(number expected, got expr%)")
  if f and MATH_IN_DM[f] then
    return string.format("math.%s takes numbers only; use dm.%s for a symbolic value (in L, "
      .. "force or constraints)", f, f)
  end
  -- I.run(...): a method called with '.'
  local m = msg:match("bad argument #1 to '([%w_%.]+)' %([%w_%.]+ expected, got ")
  if m then
    m = m:match("([%w_]+)$")
    local cls_of
    for n in pairs(docs) do
      local c = n:match("^([%w_]+):" .. m .. "$")
      if c then cls_of = c break end
    end
    if cls_of and info.namewhat ~= "method" then
      local line = source_line(info) or ""
      local recv = line:match("([%w_%.%[%]]+)%s*%.%s*" .. m .. "%s*%(")
      if recv then return string.format("call a method with ':', as in %s:%s(...)", recv, m) end
      return string.format("call a method with ':', as in obj:%s(...) (%s:%s)", m, cls_of, m)
    end
  end
  -- attempt to call a nil value (method 'nrom')
  word = msg:match("attempt to call a nil value %(method '([%w_]+)'%)")
  if word then
    local cands = {}
    for n in pairs(docs) do cands[#cands + 1] = n:match("^[%w_]+:([%w_]+)$") end
    return mean(nearest(word, cands), ":%s")
  end
  -- a nil global: undefined (inside L: a parameter?) or misspelt
  word = msg:match("%(global '([%w_]+)'%)")
  if word and msg:find("nil value", 1, true) and rawget(_G, word) == nil then
    local dmt = rawget(_G, "dm")
    if type(dmt) == "table" and rawget(dmt, word) ~= nil then
      return string.format("'%s' is not a global; did you mean dm.%s?", word, word)
    end
    local near = nearest(word, keys_of(_G))
    local inL = type(info.traceback) == "string" and info.traceback:find("'dmech%.system'")
    if not inL and #near == 0 then return nil end
    local s = string.format("'%s' is not defined (a nil global)", word)
    if inL then
      s = s .. string.format("; in L, a parameter is declared in params = {%s = ...} and read as p.%s",
                             word, word)
    end
    if #near > 0 then s = s .. "; " .. mean(near) end
    return s
  end
  -- a nil field: misspelt member of a module
  word = msg:match("%(field '([%w_]+)'%)")
  if word and msg:find("nil value", 1, true) then
    local cands = keys_of(_G, nil, true)
    local dmt = rawget(_G, "dm")
    if type(dmt) == "table" then keys_of(rawget(dmt, "systems"), cands) end
    return mean(nearest(word, cands))
  end
  return nil
end

-- }====

return M
