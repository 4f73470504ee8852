-- plot_helpers.lua -- shared by the tests/lua/plot_*.lua scripts (not a test).
--   local H = dofile(os.getenv("DMECH_SRCDIR") .. "/tests/lua/plot_helpers.lua")
local H = {}

-- Skip the whole script only when gnuplot is truly absent.
function H.need_gnuplot(T, dm)
  local ok, terms, version = pcall(dm._gp.terminals)
  if not ok then
    if tostring(terms):find("not found") then T.skip_all("gnuplot not available: " .. tostring(terms)) end
    error(terms, 0)
  end
  return terms, version
end

function H.read(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local s = f:read("a")
  f:close()
  return s
end

function H.exists(path)
  local f = io.open(path, "rb")
  if f then f:close() return true end
  return false
end

-- width, height from the IHDR of a PNG file, or nil and the reason.
function H.png_size(path)
  local s = H.read(path)
  if not s then return nil, "no file " .. path end
  if s:sub(1, 8) ~= "\137PNG\r\n\26\n" then return nil, "no PNG signature" end
  if s:sub(13, 16) ~= "IHDR" then return nil, "first chunk is not IHDR" end
  return string.unpack(">I4", s, 17), string.unpack(">I4", s, 21)
end

-- Check that an SVG document is well formed enough: every tag closed in
-- order, one <svg> root.  Returns info {width=, height=, groups={n_paths...},
-- texts={...}} or nil, reason.
function H.svg(text)
  if not text then return nil, "no file" end
  text = text:gsub("<!%[CDATA%[.-%]%]>", ""):gsub("<!%-%-.-%-%->", "")
  local stack, info, root = {}, {groups = {}, texts = {}}, nil
  local group_of = {}         -- stack depth -> plot group index
  local pos = 1
  while true do
    local s, e, body = text:find("<([^<>]*)>", pos)
    if not s then break end
    local between = text:sub(pos, s - 1)
    if between:find("[<>]") and between:find("<") then return nil, "stray < at " .. pos end
    if #stack > 0 and stack[#stack] == "text" and between:find("%S") then
      info.texts[#info.texts + 1] = between
    end
    pos = e + 1
    local first = body:sub(1, 1)
    if first == "?" or first == "!" then
      -- declaration
    elseif first == "/" then
      local name = body:match("^/([%w:_%-]+)%s*$")
      if not name then return nil, "bad closing tag <" .. body .. ">" end
      if stack[#stack] ~= name then
        return nil, string.format("</%s> closes <%s>", name, tostring(stack[#stack]))
      end
      group_of[#stack] = nil
      stack[#stack] = nil
    else
      local name = body:match("^([%w:_%-]+)")
      if not name then return nil, "bad tag <" .. body .. ">" end
      if not root then
        root = name
        info.width = tonumber(body:match('width="([%d.]+)"'))
        info.height = tonumber(body:match('height="([%d.]+)"'))
      elseif #stack == 0 then
        return nil, "second root element <" .. name .. ">"
      end
      local id = name == "g" and body:match('id="gnuplot_plot_(%d+%a*)"')
      local selfclosing = body:sub(-1) == "/"
      if name == "path" then
        for d = #stack, 1, -1 do
          local g = group_of[d]
          if g then info.groups[g] = info.groups[g] + 1 break end
        end
      end
      if not selfclosing then
        stack[#stack + 1] = name
        if id then
          info.groups[#info.groups + 1] = 0
          group_of[#stack] = #info.groups
        end
      end
    end
  end
  if #stack > 0 then return nil, "unclosed <" .. stack[#stack] .. ">" end
  if root ~= "svg" then return nil, "root element is " .. tostring(root) end
  return info
end

-- The text of a file with trailing blanks of each line removed.
function H.normalized(s)
  return (s:gsub("\f", ""):gsub("[ \t]+\n", "\n"):gsub("\n+$", "\n"))
end

function H.shq(s) return "'" .. s:gsub("'", "'\\''") .. "'" end

-- Wait (up to 5 s) until process pid is a zombie or gone.
function H.wait_dead(pid)
  for _ = 1, 500 do
    local f = io.open("/proc/" .. pid .. "/stat", "r")
    if not f then return true end
    local st = f:read("l") or ""
    f:close()
    if st:match("^%d+ %b() ([ZX])") then return true end
    os.execute("sleep 0.01")
  end
  return false
end

-- Run io.stdout writes of f into a string.
function H.capture(f, ...)
  local buf, real = {}, io.stdout
  io.stdout = setmetatable({}, {__index = {
    write = function(self, ...)
      for i = 1, select("#", ...) do buf[#buf + 1] = tostring((select(i, ...))) end
      return self
    end,
    flush = function(self) return self end}})
  local ok, err = pcall(f, ...)
  io.stdout = real
  if not ok then error(err, 0) end
  return table.concat(buf)
end

return H
