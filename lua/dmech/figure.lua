-- dmech.figure -- dm.figure: a figure that keeps its series and redraws
-- (fig:add, fig:append, fig:refresh, fig:save, fig:close ...).
--
-- Installed by dmech.plot (plot.lua), which hands it M (the module: M.figure
-- and M.Figure are set here, M.garbage is shared) and P, the recipe
-- functions a figure draws with: series and panels are built and drawn
-- exactly as dm.plot builds and draws them.
local core = require "dmech.core"
local gp = core._gp

return function(M, P)
  local fail, isvec, check_keys, describe = P.fail, P.isvec, P.check_keys, P.describe
  local PLOT_KEYS, PLOT_LIST = P.PLOT_KEYS, P.PLOT_LIST
  local series_kind, make_series, one_key_entry, merged = P.series_kind, P.make_series,
    P.one_key_entry, P.merged
  local parse_layout, build_panels, check_dims, draw = P.parse_layout, P.build_panels,
    P.check_dims, P.draw
  local check_output_opts = P.check_output_opts

  local Figure = {}
  Figure.__index = Figure
  local next_id = 0

  local function checkfig(f, method)
    if getmetatable(f) ~= Figure then
      error(string.format("figure:%s: called on %s (use fig:%s, not fig.%s)", method,
        type(f), method, method), 0)
    end
    if f.closed then error(string.format("figure:%s: the figure is closed", method), 0) end
    return "figure:" .. method
  end

  local function fig_blocks(f)
    local names, k = {}, 0
    for _, p in ipairs(f.panels) do
      for _ in ipairs(p.series) do k = k + 1; names[k] = "dmf" .. f.id .. "_" .. k end
    end
    return names
  end

  local function fig_draw(f, what, target)
    local any = false
    for _, p in ipairs(f.panels) do if #p.series > 0 then any = true end end
    if not any then return end
    check_dims(what, f.panels, f.want3d)
    local t = target or {file = f.opts.output, terminal = f.opts.terminal, size = f.opts.size,
                         window = f.id}
    t.prefix = "dmf" .. f.id .. "_"
    local term = draw(what, f.opts, f.panels, f.layout, t)
    if target == nil and term then f.term = term end
  end

  -- Set options and series from a spec table (used by dm.figure and :plot).
  local function fig_set(f, what, spec)
    if type(spec) ~= "table" or isvec(spec) then
      fail(what, "a table {series..., options...} expected, got %s", type(spec))
    end
    check_keys(what, "", spec, PLOT_KEYS, PLOT_LIST)
    check_output_opts(what, spec)
    local opts = {}
    for k, v in pairs(f.opts or {}) do opts[k] = v end
    for k, v in pairs(spec) do if type(k) == "string" then opts[k] = v end end
    local layout = opts.layout and parse_layout(what, opts.layout, math.max(#spec, 1))
    local panels = build_panels(what, spec, opts, layout)
    if layout then
      for _ = #panels + 1, layout[1] * layout[2] do panels[#panels + 1] = {opts = {}, series = {}} end
    elseif #panels == 0 then
      panels = {{opts = {}, series = {}}}
    end
    -- keep datablocks of series that disappear from being orphaned
    if f.panels then
      local old = fig_blocks(f)
      for _, name in ipairs(old) do M.garbage[#M.garbage + 1] = name end
    end
    f.opts, f.layout, f.panels = opts, layout, panels
    f.list = {}
    for _, p in ipairs(panels) do
      for _, s in ipairs(p.series) do f.list[#f.list + 1] = s end
    end
  end

  function M.figure(spec)
    local what = "dm.figure"
    spec = spec or {}
    next_id = next_id + 1
    local f = setmetatable({id = next_id}, Figure)
    fig_set(f, what, spec)
    if #f.list > 0 then fig_draw(f, what) end
    return f
  end

  function Figure:plot(spec)
    local what = checkfig(self, "plot")
    self.want3d = false
    fig_set(self, what, spec)
    fig_draw(self, what)
    return self
  end

  function Figure:splot(spec)
    local what = checkfig(self, "splot")
    fig_set(self, what, spec)
    self.want3d = true
    fig_draw(self, what)
    return self
  end

  function Figure:add(series, panel)
    local what = checkfig(self, "add")
    panel = panel or 1
    local p = self.panels[panel]
    if math.type(panel) ~= "integer" or p == nil then
      fail(what, "panel: 1..%d expected, got %s", #self.panels, tostring(panel))
    end
    if not series_kind(series) then
      fail(what, "expected a series ({x, y}, {obj, \"col\", ...} or {f, range = ...}), got %s",
           describe(series))
    end
    local s = make_series(what, "", series, merged(self.opts, p.opts))
    one_key_entry(what, s)
    p.series[#p.series + 1] = s
    self.list = {}
    for _, pp in ipairs(self.panels) do
      for _, ss in ipairs(pp.series) do self.list[#self.list + 1] = ss end
    end
    local id
    for i, ss in ipairs(self.list) do if ss == s then id = i end end
    fig_draw(self, what)
    return id
  end

  -- Append numbers, or tables / vecs of numbers, to a data series.
  function Figure:append(id, x, y, z)
    local what = checkfig(self, "append")
    local s = self.list[id]
    if s == nil then fail(what, "no series %s (the figure has %d)", tostring(id), #self.list) end
    if s.kind ~= "values" then
      fail(what, "series %d is a%s series; append works on data series", id,
           s.kind == "object" and "n object" or " function")
    end
    local want = #s.cols == 1 and 2 or #s.cols
    local args = {x, y, z}
    if (want == 3) ~= (z ~= nil) then
      fail(what, "series %d has %d columns; give %s", id, want, want == 3 and "x, y, z" or "x, y")
    end
    if #s.cols == 1 then   -- {y} against its index: make the index explicit
      local n = #s.cols[1]
      local t = {}
      for i = 1, n do t[i] = i end
      s.cols = {t, s.cols[1]}
    end
    for j = 1, want do
      if isvec(s.cols[j]) then s.cols[j] = s.cols[j]:totable() end
    end
    local count
    for j = 1, want do
      local a = args[j]
      local c = type(a) == "number" and 1 or ((isvec(a) or type(a) == "table") and #a or nil)
      if c == nil then
        fail(what, "argument %d: number, table or vec expected, got %s", j + 1, type(a))
      end
      if count and c ~= count then fail(what, "arguments have different lengths (%d and %d)", count, c) end
      count = c
    end
    for j = 1, want do
      local col, a = s.cols[j], args[j]
      local n = #col
      if type(a) == "number" then
        col[n + 1] = a
      else
        for i = 1, count do
          local v = a[i]
          if type(v) ~= "number" then
            fail(what, "argument %d: number expected at index %d, got %s", j + 1, i, type(v))
          end
          col[n + i] = v
        end
      end
    end
    return self
  end

  function Figure:refresh()
    local what = checkfig(self, "refresh")
    fig_draw(self, what)
    return self
  end

  function Figure:save(file, opts)
    local what = checkfig(self, "save")
    if type(file) ~= "string" then fail(what, "file name expected, got %s", type(file)) end
    opts = opts or {}
    if type(opts) ~= "table" then fail(what, "options table expected, got %s", type(opts)) end
    check_keys(what, "", opts, {size = true, terminal = true}, {"size", "terminal"})
    check_output_opts(what, opts)
    local any = false
    for _, p in ipairs(self.panels) do if #p.series > 0 then any = true end end
    if not any then fail(what, "the figure has no series to save") end
    fig_draw(self, what, {file = file, terminal = opts.terminal, size = opts.size or self.opts.size,
                          window = self.id})
    return self
  end

  function Figure:series(id)
    checkfig(self, "series")
    return self.list[id]
  end

  -- Closing talks to gnuplot (undefine the data, close a window); a figure
  -- that is merely garbage collected only queues its datablocks for undefine
  -- (a finalizer must never run a transaction: it may fire inside one).
  function Figure:close()
    if getmetatable(self) ~= Figure or self.closed then return end
    self.closed = true
    local names = fig_blocks(self)
    local term = self.term and self.term:match("^set terminal (%S+)")
    local ok, err = pcall(function()
      if #names == 0 and not term then return end
      gp.begin("figure:close")
      local undef = {}
      for i, name in ipairs(names) do undef[i] = "$" .. name end
      if #undef > 0 then gp.send("undefine " .. table.concat(undef, " ") .. "\n") end
      if term == "qt" or term == "wxt" or term == "x11" then
        gp.send(string.format("set terminal %s %d close\n", term, self.id))
      end
      gp.checkpoint("figure:close")
    end)
    if not ok and not tostring(err):find("not found") then error(err, 0) end
  end

  Figure.__close = Figure.close
  Figure.__gc = function(self)
    if not self.closed and self.panels then
      for _, name in ipairs(fig_blocks(self)) do M.garbage[#M.garbage + 1] = name end
    end
  end

  function Figure:__tostring()
    local n, p = 0, 0
    for _, pp in ipairs(self.panels or {}) do n = n + #pp.series; p = p + 1 end
    local dest = self.opts and self.opts.output or (self.term and self.term:match("^set terminal (%S+)")) or "screen"
    return string.format("figure %d: %d series in %d panel%s -> %s%s", self.id, n, p,
      p == 1 and "" or "s", dest, self.closed and " (closed)" or "")
  end

  -- Attach the method values to the docs registered by l_plot.c, so
  -- help(fig.add) works by value.
  do
    local byname = core.docs()
    for _, m in ipairs{"plot", "splot", "add", "append", "refresh", "save", "close", "series"} do
      local rec = byname["figure:" .. m]
      if rec then core.doc("figure:" .. m, rec.sig, rec.doc, Figure[m]) end
    end
  end
  M.Figure = Figure
end
