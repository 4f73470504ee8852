-- dmech.convergence -- dm.plot_convergence: a log-log plot of errors
-- against step sizes (or numbers of points) with dashed reference slopes.
-- Used for discrete connections' holonomy errors and order tests; a plot
-- recipe over dm.plot.  The module returns an installer that the C opener
-- calls with the dm table being built.
return function(dm)
  -- errors point at the caller's line: the first frame outside this file
  local here = debug.getinfo(1, "S").source
  local function fail(fmt, ...)
    local msg, level = "dm.plot_convergence: " .. string.format(fmt, ...), 2
    while true do
      local info = debug.getinfo(level, "S")
      if info == nil then error(msg, 0) end
      if info.source ~= here then error(msg, level) end
      level = level + 1
    end
  end

  local function values(x, what)
    if type(x) == "table" then return x end
    if type(x) == "userdata" and x.totable then return x:totable() end
    fail("%s must be a list of numbers or a vec, got %s", what, type(x))
  end

  local KEYS = {h = true, errors = true, orders = true, xlabel = true, ylabel = true, title = true,
                output = true, size = true, panel = true}

  -- The series and options of the plot (a table dm.plot accepts as a panel).
  local function panel(o)
    if type(o) ~= "table" then fail("a table of options expected, got %s", type(o)) end
    for k in pairs(o) do
      if not KEYS[k] then fail("unknown option '%s' (h, errors, orders, xlabel, ylabel, title, output, size, panel)", tostring(k)) end
    end
    local h = values(o.h, "h")
    if #h < 2 then fail("at least two step sizes expected") end
    if type(o.errors) ~= "table" then fail("errors must be a list {{\"label\", values}, ...}") end
    local p = {logscale = "xy", grid = true, xlabel = o.xlabel or "h", ylabel = o.ylabel or "error",
               title = o.title, commands = {"set format y '%.0e'", "set format x '%g'"}}
    local first = {}
    for i, s in ipairs(o.errors) do
      if type(s) ~= "table" or type(s[1]) ~= "string" then
        fail("errors[%d] must be {\"label\", values}", i)
      end
      local e = values(s[2], "errors[" .. i .. "]")
      if #e ~= #h then fail("errors[%d] has %d values for %d step sizes", i, #e, #h) end
      local a = {}
      for k = 1, #e do a[k] = math.abs(e[k]) end
      p[#p + 1] = {h, a, with = "linespoints", legend = s[1]}
      first[i] = a[1]
    end
    for i, q in ipairs(o.orders or {}) do
      if type(q) ~= "number" then fail("orders[%d] must be a number", i) end
      local c = (first[i] or first[1]) / h[1]^q
      local r = {}
      for k = 1, #h do r[k] = c * h[k]^q end
      p[#p + 1] = {h, r, with = "lines dashtype 2", legend = ("slope %g"):format(q)}
    end
    return p
  end

  local function plot_convergence(o)
    local p = panel(o)
    if o.panel then return p end
    p.output, p.size = o.output, o.size or (o.output and {800, 560}) or nil
    return dm.plot(p)
  end

  dm.plot_convergence = plot_convergence
  dm.doc("dm.plot_convergence",
    "dm.plot_convergence{h = {...}, errors = {{\"label\", values}, ...}[, orders = {1, 2}, xlabel, ylabel, title, output, panel = true]}",
    "A log-log plot of |errors| against h with dashed reference slopes (one per series, through its first point); panel = true returns the panel for a dm.plot layout instead of drawing.",
    plot_convergence)
end
