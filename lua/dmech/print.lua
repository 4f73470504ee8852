-- dmech.print -- the REPL's pretty printer.
--
-- Numbers print as the shortest decimal that reads back exactly (the C
-- formatter dm.format_number, '.' whatever the locale); strings are
-- quoted; objects with __tostring (vec, mat, trajectories, expressions) print
-- through it; tables print to a depth of 3 with at most MAX_ITEMS entries per
-- level, sorted keys and cycle detection.
local M = {}
local format_number = require("dmech.core").format_number

local MAX_ITEMS = 24
local MAX_DEPTH = 3

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

local render

local function render_table(t, depth, seen, indent)
  if seen[t] then return "<cycle>" end
  if depth >= MAX_DEPTH then return "{...}" end
  seen[t] = true
  local n = #t
  local keys = {}
  for k in next, t do
    if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
  end
  table.sort(keys, sortkeys)
  local parts, count, total = {}, 0, n + #keys
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
  if type(mt) == "table" and rawget(mt, "__tostring") then return tostring(x) end
  if tx == "table" then return render_table(x, depth, seen, indent) end
  return tostring(x)
end

--- The string the REPL shows for x.
function M.pretty(x, depth)
  if depth ~= nil and math.type(depth) ~= "integer" then
    error("bad argument #2 to 'pretty' (integer expected, got " .. type(depth) .. ")", 2)
  end
  local saved = MAX_DEPTH
  MAX_DEPTH = depth or MAX_DEPTH
  local ok, s = pcall(render, x, 0, {}, "")
  MAX_DEPTH = saved
  if not ok then error(s, 2) end
  return s
end

--- Print the results of a REPL expression (tab separated, as lua.c does).
function M.results(...)
  local n = select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = M.pretty((select(i, ...))) end
  io.stdout:write(table.concat(parts, "\t"), "\n")
end

return M
