-- dmech.plot -- plot recipes: dm.plot and dm.figure over the gnuplot session.
--
-- The C side (src/lua/l_plot.c, src/plot/) owns the gnuplot process, data
-- transfer, quoting and checkpoints; this file turns a Lua description of a
-- plot into gnuplot commands.  dm.plot / dm.figure (C entry points) load it
-- on first use.
--
-- A series is one of
--   {x, y[, z], with = "lines", legend = "..."}  values: tables of numbers or dm.vec
--   {y}                                          y against 1..n
--   {obj, "cx", "cy"[, "cz"], ...}               any obj with obj:column(name)
--                                                returning a table or a dm.vec
--                                                (trajectories, user objects)
--   {f, range = {a, b}, samples = 500, ...}      f(t) -> y | x, y | x, y, z
-- Three columns make a 3-D plot (splot).  A series' legend (its key entry)
-- is `legend`, or `title` as gnuplot calls it.
--
-- dm.plot{series..., options...} draws them in one panel.  With
-- layout = "rows,cols" every element of the array part is a panel: one
-- series, or a table of series with its own panel options:
--   dm.plot{ {{x, y1}, {x, y2}, title = "left"}, {traj, "x", "y", title = "right"},
--            layout = "1,2", output = "both.png" }
-- (a panel given as a single series: its title is the panel's title, its
-- legend a key entry).
--
-- Options (plot and panel): title, xlabel, ylabel, zlabel (false: none),
-- xrange = {a, b}, yrange, zrange (nil ends autoscale), logscale = "y",
-- grid = true, key = false | "top left" | "outside" ..., aspect = "equal" |
-- ratio | false, view = {rot_x, rot_z}, with = default style, commands =
-- {"raw gnuplot command", ...} (sent as they are, after everything else: the
-- user's own escape hatch).  Plot only: layout = "r,c", output =
-- "file.png|svg|pdf|eps|txt", size = {w, h} (pixels; characters for
-- .txt/dumb; points for pdf/eps), terminal = "pngcairo" | "dumb" | "sixel" |
-- "qt" ..., enhanced = true (gnuplot text markup; by default every string
-- renders literally).  The option names come from the documentation of
-- dm.plot (l_plot.c), so help "dm.plot" lists exactly these.
--
-- Defaults a paper can use (computed in lua/dmech/plotauto.lua): axis labels from the column names of object
-- series; the key in the first corner its box leaves free of data (top
-- right, top left, bottom right, bottom left), else outside; equal aspect
-- when every axis shows a configuration coordinate (trajectory columns of
-- kind "q") and the spans are within a factor of 4; tics thinned where
-- their labels would run into each other; values <= 0 on a log
-- axis sent as NaN (left out, the line broken there), so no offset is
-- needed.  At the prompt (dm.config.interactive) a written file is reported
-- in one line: "wrote orbit.png".
local core = require "dmech.core"
local gp = core._gp
local M = {}

local VEC_MT = getmetatable(core.vec{0})
local function isvec(x) return getmetatable(x) == VEC_MT end

local function fail(what, fmt, ...)
  error(what .. ": " .. string.format(fmt, ...), 0)
end

-- the options are those documented for dm.plot: plot-wide first
local PLOT_ONLY = {layout = true, output = true, size = true, terminal = true, enhanced = true}
local PLOT_KEYS, PANEL_KEYS, PLOT_LIST, PANEL_LIST = {}, {}, {}, {}
for _, k in ipairs(core.docs()["dm.plot"].opts) do
  PLOT_KEYS[k] = true
  PLOT_LIST[#PLOT_LIST + 1] = k
  if not PLOT_ONLY[k] then
    PANEL_KEYS[k] = true
    PANEL_LIST[#PANEL_LIST + 1] = k
  end
end
local SERIES_LIST = {"with", "legend", "title", "range", "samples"}
local SERIES_KEYS = {}
for _, k in ipairs(SERIES_LIST) do SERIES_KEYS[k] = true end
M.options = {plot = PLOT_LIST, panel = PANEL_LIST, series = SERIES_LIST}

-- {==== classifying the pieces of a spec ==================================

local function isvalues(x)
  if isvec(x) then return true end
  return type(x) == "table" and getmetatable(x) == nil
    and (type(x[1]) == "number" or next(x) == nil)
end

local function hascolumn(x)
  local t = type(x)
  if (t ~= "table" and t ~= "userdata") or isvec(x) then return false end
  local ok, f = pcall(function() return x.column end)
  return ok and f ~= nil
end

-- "values" | "object" | "function" | nil
local function series_kind(e)
  if type(e) ~= "table" or isvec(e) or getmetatable(e) ~= nil then return nil end
  local a = e[1]
  if type(a) == "function" then return "function" end
  if isvalues(a) then return "values" end
  if hascolumn(a) and type(e[2]) == "string" then return "object" end
  return nil
end

local function is_panel(e)
  return type(e) == "table" and not isvec(e) and getmetatable(e) == nil
    and series_kind(e[1]) ~= nil
end

local function describe(x)
  if isvec(x) then return "vec" end
  if type(x) == "table" then
    local first = x[1]
    return first == nil and "table" or ("table starting with a " .. (isvec(first) and "vec" or type(first)))
  end
  return type(x)
end

local function check_keys(what, where, t, allowed, list)
  for k in pairs(t) do
    if type(k) == "string" and not allowed[k] then
      fail(what, "%sunknown option '%s' (options: %s)", where, k, table.concat(list, ", "))
    end
  end
end

-- }====

-- {==== series: columns ==================================================

local EMPTY = {}   -- an empty column (a live series before its first point)

local function tovec(what, where, col, name)
  if isvec(col) then return col end
  if type(col) ~= "table" then
    fail(what, "%s%s: table of numbers or vec expected, got %s", where, name, type(col))
  end
  if next(col) == nil then return EMPTY end
  local ok, v = pcall(core.vec, col)
  if not ok then
    fail(what, "%s%s: %s", where, name, (tostring(v):gsub("^bad argument #%d+ to '[^']*' ", "")))
  end
  return v
end

local function sample_function(what, where, s, opts)
  local f, range = s[1], s.range or opts.xrange
  if type(range) ~= "table" or type(range[1]) ~= "number" or type(range[2]) ~= "number"
     or not (range[1] < range[2]) or range[2] - range[1] == math.huge then
    fail(what, "%sa function needs range = {a, b} with a < b (or xrange)", where)
  end
  local n = s.samples or 500
  if math.type(n) ~= "integer" or n < 2 or n > 10000000 then
    fail(what, "%ssamples: integer from 2 to 10^7 expected, got %s", where, tostring(n))
  end
  local a, b = range[1], range[2]
  local cols, k = {{}, {}, {}}, nil
  for i = 0, n - 1 do
    local t = i == n - 1 and b or a + (b - a) * i / (n - 1)
    local r = table.pack(f(t))
    if k == nil then
      k = r.n
      if k < 1 or k > 3 then
        fail(what, "%sthe function must return 1 to 3 numbers, got %d values", where, k)
      end
    end
    for j = 1, k do
      if type(r[j]) ~= "number" then
        fail(what, "%sthe function returned %s (value %d) at %.17g", where,
             r[j] == nil and "nil" or type(r[j]), j, t)
      end
    end
    if k == 1 then
      cols[1][i + 1], cols[2][i + 1] = t, r[1]
    else
      for j = 1, k do cols[j][i + 1] = r[j] end
    end
  end
  local ncol = k == 1 and 2 or k
  local out = {}
  for j = 1, ncol do out[j] = core.vec(cols[j]) end
  return out
end

-- The columns (vecs) of a series now: objects are asked every time (a
-- trajectory may have grown), values and functions are already stored.
local function series_columns(what, where, s)
  local cols = {}
  if s.kind == "object" then
    local obj = s.src[1]
    for j = 2, #s.src do
      local name = s.src[j]
      local ok, c = pcall(obj.column, obj, name)
      if not ok then fail(what, "%scolumn '%s': %s", where, name, tostring(c)) end
      cols[#cols + 1] = tovec(what, where, c, "column '" .. name .. "'")
    end
  else
    for j, c in ipairs(s.cols) do
      cols[j] = tovec(what, where, c, ({"x", "y", "z"})[j] or ("column " .. j))
    end
  end
  if #cols == 1 then
    local n = #cols[1]
    cols = {n > 0 and core.linspace(1, n, n) or EMPTY, cols[1]}
  end
  local n = #cols[1]
  for j = 2, #cols do
    if #cols[j] ~= n then
      fail(what, "%scolumns have different lengths (%d and %d)", where, n, #cols[j])
    end
  end
  return cols, n
end

-- A normalized series record from a user series table.
-- A series in a panel of several (or alone without a layout): its title
-- and legend are the same thing, the key entry.
local function one_key_entry(what, s)
  if s.legend and s.given_title and s.legend ~= s.given_title then
    fail(what, "%slegend and title both given (the same thing here: the key entry)", s.where)
  end
end

local function make_series(what, where, e, opts)
  check_keys(what, where, e, SERIES_KEYS, SERIES_LIST)
  local kind = series_kind(e)
  local s = {kind = kind, src = e, with = e.with or opts.with or "lines"}
  for _, k in ipairs{"legend", "title"} do
    if e[k] ~= nil and type(e[k]) ~= "string" and type(e[k]) ~= "number" then
      fail(what, "%s%s: string expected, got %s", where, k, type(e[k]))
    end
  end
  s.given_title = e.title ~= nil and tostring(e.title) or nil
  s.legend = e.legend ~= nil and tostring(e.legend) or nil
  s.title = s.legend or s.given_title
  s.where = where
  if type(s.with) ~= "string" or not gp.style_ok(s.with) then
    fail(what, "%swith: a plain style expected (words, numbers, quoted colours), got %s",
         where, type(s.with) == "string" and ("'" .. s.with .. "'") or type(s.with))
  end
  if kind == "values" then
    s.cols = {}
    for j = 1, 4 do
      local c = e[j]
      if c == nil then break end
      if j == 4 then fail(what, "%sat most three columns (x, y, z)", where) end
      if not isvalues(c) then
        fail(what, "%scolumn %d: table of numbers or vec expected, got %s", where, j, describe(c))
      end
      s.cols[j] = c
    end
    s.dim = #s.cols == 3 and 3 or 2
  elseif kind == "object" then
    if #e > 4 then fail(what, "%sat most three column names", where) end
    for j = 2, #e do
      if type(e[j]) ~= "string" then
        fail(what, "%scolumn name %d: string expected, got %s", where, j - 1, type(e[j]))
      end
    end
    s.dim = #e == 4 and 3 or 2
  elseif kind == "function" then
    s.cols = sample_function(what, where, e, opts)
    s.dim = #s.cols == 3 and 3 or 2
  else
    fail(what, "%sexpected {x, y[, z]}, {obj, \"col\", ...} or {f, range = {a, b}}, got %s",
         where, describe(e))
  end
  return s
end

-- }====

-- {==== options to commands ==============================================

local function q(s) return gp.quote(tostring(s)) end

local function range_cmd(what, axis, r)
  if r == nil then return "set autoscale " .. axis .. "\n" end
  if type(r) ~= "table" then fail(what, "%srange: {min, max} expected, got %s", axis, type(r)) end
  local function b(x)
    if x == nil or x == "*" then return "*" end
    if type(x) ~= "number" or x ~= x or math.abs(x) == math.huge then
      fail(what, "%srange: finite numbers expected, got %s", axis, tostring(x))
    end
    return gp.fmt(x)
  end
  return string.format("set %srange [%s:%s]\n", axis, b(r[1]), b(r[2]))
end

local function text_cmd(what, name, v)
  if v == nil or v == false then return "unset " .. name .. "\n" end
  if type(v) ~= "string" and type(v) ~= "number" then
    fail(what, "%s: string expected, got %s", name, type(v))
  end
  return "set " .. name .. " " .. q(v) .. "\n"
end

-- Every panel setting is set or unset, so panels of a multiplot never
-- inherit from each other.
local function panel_settings(what, o, dim, notitle, auto)
  local out = {}
  local function add(s) out[#out + 1] = s end
  auto = auto or {}
  add(notitle and "unset title\n" or text_cmd(what, "title", o.title))
  for _, a in ipairs{"xlabel", "ylabel", "zlabel"} do
    local v = o[a]
    if v == nil then v = auto[a] end
    add(text_cmd(what, a, v))
  end
  -- the scale before the ranges: a range is checked against the scale in force
  add("unset logscale\n")
  if o.logscale ~= nil then
    if type(o.logscale) ~= "string" or not o.logscale:match("^[xyz]+$") then
      fail(what, "logscale: axes like \"y\" or \"xy\" expected, got %s", tostring(o.logscale))
    end
    add("set logscale " .. o.logscale .. "\n")
  end
  add(range_cmd(what, "x", o.xrange or auto.xrange))
  add(range_cmd(what, "y", o.yrange or auto.yrange))
  add(range_cmd(what, "z", o.zrange))
  add(o.grid and "set grid\n" or "unset grid\n")
  if o.key == false then
    add("unset key\n")
  elseif o.key == nil and auto.key then
    add("set key default\nset key " .. auto.key .. "\n")
    if auto.headroom then
      add("set offsets 0, 0, graph " .. gp.fmt(auto.headroom) .. ", 0\n")
    end
  elseif o.key == nil or o.key == true then
    add("set key default\n")
  elseif type(o.key) == "string" and o.key:match("^[%a ]+$") then
    add("set key default\nset key " .. o.key .. "\n")
  else
    fail(what, "key: false, true or words like \"top left\" expected, got %s", tostring(o.key))
  end
  for _, a in ipairs{"xtics", "ytics", "ztics"} do
    if auto[a] then add("set " .. a .. " " .. gp.fmt(auto[a]) .. "\n") end
  end
  local aspect = o.aspect
  if aspect == nil then aspect = auto.aspect end
  if aspect == nil or aspect == false then
    add("set size noratio\nset view noequal\n")
  elseif aspect == "equal" then
    add(dim == 3 and "set view equal xyz\n" or "set size ratio -1\n")
  elseif type(aspect) == "number" and aspect > 0 and aspect < math.huge then
    add("set size ratio " .. gp.fmt(aspect) .. "\n")
  else
    fail(what, "aspect: \"equal\", a positive ratio or false expected, got %s", tostring(aspect))
  end
  if o.view ~= nil then
    if type(o.view) ~= "table" or type(o.view[1]) ~= "number" or type(o.view[2]) ~= "number" then
      fail(what, "view: {rot_x, rot_z} expected")
    end
    add("set view " .. gp.fmt(o.view[1]) .. "," .. gp.fmt(o.view[2]) .. "\n")
  elseif dim == 3 then
    add("set view 60,30\n")
  end
  if o.commands ~= nil then
    if type(o.commands) ~= "table" then fail(what, "commands: table of strings expected") end
    for i, c in ipairs(o.commands) do
      if type(c) ~= "string" then fail(what, "commands[%d]: string expected", i) end
      add(c .. "\n")
    end
  end
  return table.concat(out)
end

local function merged(base, over)
  local o = {}
  for k, v in pairs(base) do if PANEL_KEYS[k] then o[k] = v end end
  for k, v in pairs(over or {}) do if type(k) == "string" then o[k] = v end end
  return o
end

-- }====

-- {==== plans: panels of series ==========================================

local function parse_layout(what, layout, npanels)
  if layout == nil then return nil end
  local r, c = tostring(layout):match("^%s*(%d+)%s*[,x]%s*(%d+)%s*$")
  r, c = tonumber(r), tonumber(c)
  if not r or r < 1 or c < 1 or r > 20 or c > 20 then
    fail(what, "layout: \"rows,cols\" expected, got %s", tostring(layout))
  end
  if npanels > r * c then
    fail(what, "layout %d,%d has room for %d panels, got %d", r, c, r * c, npanels)
  end
  return {r, c}
end

-- Split a spec (dm.plot argument or figure spec) into panels of series.
local function build_panels(what, spec, opts, layout)
  local panels = {}
  local n = #spec
  for i = 1, n do
    local e = spec[i]
    if series_kind(e) then
      local where = n > 1 and string.format("series %d: ", i) or "series: "
      local sr = make_series(what, where, e, opts)
      local p = {opts = {}, series = {sr}, single = true}
      if layout then
        -- a panel given as one series: its title heads the panel, its
        -- legend (if any) is the key entry
        p.opts.title, sr.title = sr.given_title, sr.legend
      else
        one_key_entry(what, sr)
      end
      panels[#panels + 1] = p
    elseif is_panel(e) then
      if not layout then
        fail(what, "element %d is a list of series (a panel); give layout = \"rows,cols\"", i)
      end
      check_keys(what, string.format("panel %d: ", i), e, PANEL_KEYS, PANEL_LIST)
      local p = {opts = {}, series = {}}
      for k, v in pairs(e) do if type(k) == "string" then p.opts[k] = v end end
      local popts = merged(opts, p.opts)
      for j = 1, #e do
        if not series_kind(e[j]) then
          fail(what, "panel %d, series %d: expected a series table, got %s", i, j, describe(e[j]))
        end
        p.series[j] = make_series(what, string.format("panel %d, series %d: ", i, j), e[j], popts)
        one_key_entry(what, p.series[j])
      end
      panels[#panels + 1] = p
    else
      fail(what, "element %d: expected a series ({x, y}, {obj, \"col\", ...} or {f, range = ...}), got %s",
           i, describe(e))
    end
  end
  if not layout and #panels > 1 then
    -- without a layout every series goes into one panel
    local one = {opts = {}, series = {}}
    for _, p in ipairs(panels) do one.series[#one.series + 1] = p.series[1] end
    panels = {one}
  elseif not layout and #panels == 1 then
    panels[1].single = nil
  end
  return panels
end

local function check_dims(what, panels, want3d)
  for i, p in ipairs(panels) do
    local dim
    for j, s in ipairs(p.series) do
      if want3d and s.dim ~= 3 then
        fail(what, "series %d has %d columns; splot needs three (x, y, z)", j, s.dim)
      end
      if dim and s.dim ~= dim then
        fail(what, "%sseries %d is %d-D but series 1 is %d-D; 2-D and 3-D series cannot share a panel",
             #panels > 1 and ("panel " .. i .. ": ") or "", j, s.dim, dim)
      end
      dim = s.dim
    end
    p.dim = dim or 2
  end
end

-- }====

local A = require "dmech.plotauto"
local panel_defaults, log_safe = A.panel_defaults, A.log_safe

-- {==== drawing ===========================================================

M.garbage = {}          -- datablock names to undefine at the next transaction
local plot_blocks = 0   -- how many $dmp_<k> dm.plot defined last time

-- Send one plan: panels + plot-level options to a target
-- {file=, terminal=, size=, window=, prefix=}.
local function draw(what, opts, panels, layout, target)
  -- columns first: they may call user code (obj:column) and raise
  local blocks, k = {}, 0
  for pi, p in ipairs(panels) do
    for si, s in ipairs(p.series) do
      local where = (#panels > 1 and ("panel " .. pi .. ", ") or "") .. "series " .. si .. ": "
      local cols, n = series_columns(what, where, s)
      k = k + 1
      blocks[k] = {name = target.prefix .. k, cols = cols, n = n, s = s}
    end
  end
  -- every setting is checked before anything is sent
  local settings, items = {}, {}
  local bi = 0
  for pi, p in ipairs(panels) do
    local o = merged(opts, p.opts)
    local pb = {}
    for j = 1, #p.series do
      local b = blocks[bi + j]
      b.cols = log_safe(b.cols, o.logscale)
      pb[j] = b
    end
    local auto = panel_defaults(p, pb, o, target, layout)
    items[pi] = {}
    for _, s in ipairs(p.series) do
      bi = bi + 1
      local b = blocks[bi]
      if b.n > 0 then
        items[pi][#items[pi] + 1] = string.format("$%s using %s with %s %s", b.name,
          s.dim == 3 and "1:2:3" or "1:2", s.with,
          s.title and ("title " .. q(s.title)) or "notitle")
      end
    end
    settings[pi] = panel_settings(what, o, p.dim, layout ~= nil and p.opts.title == nil, auto)
  end
  local total = 0
  for _, b in ipairs(blocks) do total = total + b.n end
  if total == 0 then
    if target.need_points then fail(what, "nothing to plot (every series is empty)") end
    return nil, 0
  end
  gp.begin(what)
  if #M.garbage > 0 then
    local names = {}
    for i, name in ipairs(M.garbage) do names[i] = "$" .. name end
    gp.send("undefine " .. table.concat(names, " ") .. "\n")
    M.garbage = {}
  end
  gp.send("reset\n")
  local term = gp.terminal{terminal = target.terminal, file = target.file, size = target.size,
                           window = target.window, enhanced = opts.enhanced}
  for _, b in ipairs(blocks) do
    if b.n > 0 then gp.data(b.name, table.unpack(b.cols)) end
  end
  if target.after then target.after(#blocks) end
  if layout then
    gp.send(string.format("set multiplot layout %d,%d%s\n", layout[1], layout[2],
      opts.title ~= nil and (" title " .. q(opts.title)) or ""))
  end
  for pi, p in ipairs(panels) do
    -- inside a multiplot `reset` keeps the layout but clears what the
    -- previous panel set, including its raw `commands`
    if pi > 1 then gp.send("reset\n") end
    gp.send(settings[pi])
    if #items[pi] > 0 then
      gp.send((p.dim == 3 and "splot " or "plot ") .. table.concat(items[pi], ", ") .. "\n")
    elseif layout then
      gp.send("set multiplot next\n")
    end
  end
  if layout then gp.send("unset multiplot\n") end
  local msgs, out = gp.checkpoint(what)
  if out ~= "" then
    io.stdout:write(out)
    io.stdout:flush()
  end
  for line in msgs:gmatch("[^\n]+") do        -- warnings, not errors
    line = line:gsub("^%s*line %d+: ", ""):gsub("^warning: ", "")
    if line:find("%S") then io.stderr:write(what, ": gnuplot: ", line, "\n") end
  end
  if target.file and type(core.config) == "table" and core.config.interactive then
    io.stdout:write("wrote ", target.file, "\n")
    io.stdout:flush()
  end
  return term, total
end

local function check_output_opts(what, o)
  if o.output ~= nil and type(o.output) ~= "string" then
    fail(what, "output: file name expected, got %s", type(o.output))
  end
  if o.output ~= nil and o.output:find("\0", 1, true) then
    fail(what, "output: file name without NUL bytes expected, got a NUL byte at position %d",
         o.output:find("\0", 1, true))
  end
  if o.terminal ~= nil and type(o.terminal) ~= "string" then
    fail(what, "terminal: string expected, got %s", type(o.terminal))
  end
  if o.size ~= nil and (type(o.size) ~= "table" or type(o.size[1]) ~= "number"
                        or type(o.size[2]) ~= "number" or o.size[1] <= 0 or o.size[2] <= 0) then
    fail(what, "size: {width, height} with positive numbers expected")
  end
end

function M.plot(spec)
  local what = "dm.plot"
  if type(spec) ~= "table" or isvec(spec) then
    fail(what, "a table {series..., options...} expected, got %s", isvec(spec) and "vec" or type(spec))
  end
  -- dm.plot{x, y[, z], ...}: the spec itself is one series
  if isvalues(spec[1]) and spec[1] ~= nil and (spec[2] == nil or isvalues(spec[2])) then
    local s = {spec[1], spec[2], spec[3], with = spec.with}
    local o = {}
    for k, v in pairs(spec) do if type(k) == "string" and k ~= "with" then o[k] = v end end
    o[1] = s
    spec = o
  end
  check_keys(what, "", spec, PLOT_KEYS, PLOT_LIST)
  check_output_opts(what, spec)
  if #spec == 0 then fail(what, "nothing to plot (no series given)") end
  local layout = spec.layout and parse_layout(what, spec.layout, #spec)
  local panels = build_panels(what, spec, spec, layout)
  check_dims(what, panels, false)
  local nblocks = 0
  for _, p in ipairs(panels) do nblocks = nblocks + #p.series end
  draw(what, spec, panels, layout, {file = spec.output, terminal = spec.terminal,
    size = spec.size, window = 0, prefix = "dmp_", need_points = true,
    after = function(n)
      -- forget the blocks of a bigger previous plot
      if plot_blocks > n then
        local names = {}
        for i = n + 1, plot_blocks do names[#names + 1] = "$dmp_" .. i end
        gp.send("undefine " .. table.concat(names, " ") .. "\n")
      end
      plot_blocks = n
    end})
end

-- }====

-- {==== figures ============================================================

-- dm.figure and its methods (figure.lua) build on the recipes above.
require "dmech.figure"(M, {
  fail = fail, isvec = isvec, PLOT_KEYS = PLOT_KEYS, PLOT_LIST = PLOT_LIST,
  series_kind = series_kind, describe = describe, check_keys = check_keys,
  make_series = make_series, one_key_entry = one_key_entry, merged = merged,
  parse_layout = parse_layout, build_panels = build_panels, check_dims = check_dims,
  draw = draw, check_output_opts = check_output_opts,
})

-- }====

return M
