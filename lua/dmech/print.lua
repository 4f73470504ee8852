-- dmech.print -- the REPL's pretty printer.
--
-- Numbers print as the shortest decimal that reads back exactly (the C
-- formatter dm.format_number, '.' whatever the locale); strings are
-- quoted; tables print to a depth of 3 with at most MAX_ITEMS entries per
-- level, sorted keys and cycle detection.  Bulk numbers -- a vec, a mat, a
-- long list of numbers -- print head ... tail with `digits` significant
-- digits (dm.config.digits, default 6; 0 for every digit) and at most
-- `items` entries (dm.config.items, default 10); dm.show(x) prints one value
-- in full.  Other objects with __tostring (trajectories, expressions, ...)
-- print through it.
local M = {}
local core = require "dmech.core"
local format_number = core.format_number

local MAX_ITEMS = 24
local MAX_DEPTH = 3
local DIGITS = 6
local ITEMS = 10

local VEC_MT = getmetatable(core.vec{0})
local MAT_MT = getmetatable(core.mat{{0}})

local function fmtnum(x)
  if math.type(x) == "integer" then return tostring(x) end
  local s = format_number(x)
  if not s:find("[%.eEni]") then s = s .. ".0" end      -- a float: 2.0, not 2
  return s
end
M.fmtnum = fmtnum

local function is_ident(s)
  return type(s) == "string" and s:match("^[%a_][%w_]*$") ~= nil
end

local keyorder = { number = 1, string = 2 }
local function sortkeys(a, b)
  local ta, tb = type(a), type(b)
  if ta ~= tb then return (keyorder[ta] or 3) < (keyorder[tb] or 3) end
  if ta == "number" or ta == "string" then return a < b end
  return tostring(a) < tostring(b)
end

-- The settings of one rendering: depth, digits, items.
local opt

local function bulknum(x)
  if math.type(x) == "integer" then return tostring(x) end
  return format_number(x, opt.digits)
end

-- "first, second, ..., last" of n entries: all of them when n <= items,
-- else the first and last items/2.
local function head_tail(n, get)
  local parts, items = {}, opt.items
  if n <= items then
    for i = 1, n do parts[#parts + 1] = get(i) end
  else
    local h = math.max(1, items // 2)
    for i = 1, h do parts[#parts + 1] = get(i) end
    parts[#parts + 1] = "..."
    for i = n - (items - h) + 1, n do parts[#parts + 1] = get(i) end
  end
  return parts
end

local function render_vec(v)
  local n = #v
  local s = "vec{" .. table.concat(head_tail(n, function(i) return bulknum(v[i]) end), ", ") .. "}"
  if n > opt.items then s = s .. string.format(" (%d elements)", n) end
  return s
end

-- Rows on lines of their own, columns right-aligned; head ... tail in both
-- directions.
local function render_mat(m)
  local r, c = m:rows(), m:cols()
  local rows = head_tail(r, function(i) return i end)
  local cells, w = {}, 1
  for k, i in ipairs(rows) do
    if i == "..." then
      cells[k] = false
    else
      cells[k] = head_tail(c, function(j)
        local s = bulknum(m:get(i, j))
        w = math.max(w, #s)
        return s
      end)
    end
  end
  local lines = {}
  for k, row in ipairs(cells) do
    if row then
      local padded = {}
      for j, s in ipairs(row) do padded[j] = s == "..." and string.format("%" .. w .. "s", "...")
        or string.format("%" .. w .. "s", s) end
      lines[#lines + 1] = "{" .. table.concat(padded, ", ") .. "}"
    else
      lines[#lines + 1] = " ..."
    end
  end
  local s = "mat{" .. table.concat(lines, ",\n    ") .. "}"
  if r > opt.items or c > opt.items then s = s .. string.format(" (%dx%d)", r, c) end
  return s
end

local render

local function render_table(t, depth, seen, indent)
  if seen[t] then return "<cycle>" end
  if depth >= opt.depth then return "{...}" end
  seen[t] = true
  local n = #t
  local keys = {}
  for k in next, t do
    if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
  end
  table.sort(keys, sortkeys)
  local parts, count, total = {}, 0, n + #keys
  -- a long list of numbers: head ... tail, like a vec
  local numeric = n > MAX_ITEMS and #keys == 0
  for i = 1, n do
    if not numeric then break end
    numeric = type(rawget(t, i)) == "number"
  end
  if numeric then
    seen[t] = nil
    local s = "{" .. table.concat(head_tail(n, function(i) return fmtnum(rawget(t, i)) end), ", ") .. "}"
    return s .. string.format(" (%d items)", n)
  end
  for i = 1, n do
    if count >= MAX_ITEMS then break end
    count = count + 1
    parts[#parts + 1] = render(rawget(t, i), depth + 1, seen, indent .. "  ")
  end
  for _, k in ipairs(keys) do
    if count >= MAX_ITEMS then break end
    count = count + 1
    local ks = is_ident(k) and k or ("[" .. render(k, depth + 1, seen, indent) .. "]")
    parts[#parts + 1] = ks .. " = " .. render(rawget(t, k), depth + 1, seen, indent .. "  ")
  end
  if total > count then parts[#parts + 1] = string.format("... (%d more)", total - count) end
  seen[t] = nil
  if #parts == 0 then return "{}" end
  local flat = "{" .. table.concat(parts, ", ") .. "}"
  if #flat <= 78 and not flat:find("\n") then return flat end
  return "{\n" .. indent .. "  " .. table.concat(parts, ",\n" .. indent .. "  ") .. "\n" .. indent .. "}"
end

function render(x, depth, seen, indent)
  local tx = type(x)
  if tx == "number" then return fmtnum(x) end
  if tx == "string" then return string.format("%q", x) end
  local mt = getmetatable(x)
  if mt == VEC_MT then return render_vec(x) end
  if mt == MAT_MT then return render_mat(x) end
  if type(mt) == "table" and rawget(mt, "__tostring") then return tostring(x) end
  if tx == "table" then return render_table(x, depth, seen, indent) end
  return tostring(x)
end

-- The settings from dm.config (digits, items), overridden by o.
local function settings(o)
  local cfg = type(core.config) == "table" and core.config or {}
  local s = {depth = MAX_DEPTH, digits = DIGITS, items = ITEMS}
  if math.type(cfg.digits) == "integer" and cfg.digits >= 0 and cfg.digits <= 17 then
    s.digits = cfg.digits
  end
  if type(cfg.items) == "number" and cfg.items >= 2 then s.items = cfg.items end
  for k, v in pairs(o or {}) do s[k] = v end
  return s
end

local function check_opts(o, fname)
  if math.type(o) == "integer" then return {depth = o} end
  if o == nil then return {} end
  if type(o) ~= "table" then
    error("bad argument #2 to '" .. fname .. "' (integer depth or {depth=, digits=, items=} expected, got "
          .. type(o) .. ")", 3)
  end
  for k, v in pairs(o) do
    if k == "depth" or k == "items" then
      if not ((math.type(v) == "integer" or v == math.huge) and v >= 1) then
        error("bad argument #2 to '" .. fname .. "' (" .. k .. ": positive integer expected)", 3)
      end
    elseif k == "digits" then
      if math.type(v) ~= "integer" or v < 0 or v > 17 then
        error("bad argument #2 to '" .. fname .. "' (digits: integer 0..17 expected, 0 for every digit)", 3)
      end
    else
      error("bad argument #2 to '" .. fname .. "' (unknown option '" .. tostring(k)
            .. "'; options: depth, digits, items)", 3)
    end
  end
  return o
end

--- The string the REPL shows for x.
function M.pretty(x, o)
  o = check_opts(o, "pretty")
  local saved = opt
  opt = settings(o)
  local ok, s = pcall(render, x, 0, {}, "")
  opt = saved
  if not ok then error(s, 2) end
  return s
end

--- Print x in full: every digit (shortest round trip) and every element.
function M.show(x, o)
  o = check_opts(o, "show")
  local full = {digits = 0, items = math.huge, depth = MAX_DEPTH}
  for k, v in pairs(o) do full[k] = v end
  io.stdout:write(M.pretty(x, full), "\n")
end

--- Print the results of a REPL expression (tab separated, as lua.c does).
function M.results(...)
  local n = select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = M.pretty((select(i, ...))) end
  io.stdout:write(table.concat(parts, "\t"), "\n")
end

return M
