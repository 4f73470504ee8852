-- dmech.plotauto -- the defaults dm.plot chooses where the user gave none:
-- axis labels from column names, the key's place, equal aspect for
-- configuration-space orbits, tics that do not crowd, log axes without
-- values <= 0.  Used by lua/dmech/plot.lua; pure computation on the
-- columns of a plan, nothing is sent to gnuplot here.
--
--   local A = require "dmech.plotauto"
--   auto = A.panel_defaults(panel, blocks, opts, target, layout)
--   cols = A.log_safe(cols, logscale)
local M = {}


local function finite(x) return x == x and x > -math.huge and x < math.huge end

-- Up to `max` points of a block as lists (x, y[, z]), log10 on log axes
-- (NaN for values <= 0), the last point always included.
local function sample_block(b, logs, max)
  local n, pts = b.n, {{}, {}, {}}
  local stride = math.max(1, math.ceil(n / max))
  local dims = #b.cols
  local function add(i)
    for j = 1, dims do
      local v = b.cols[j][i]
      if logs[j] then v = v > 0 and math.log(v, 10) or 0 / 0 end
      pts[j][#pts[j] + 1] = v
    end
  end
  for i = 1, n, stride do add(i) end
  if n > 0 and (n - 1) % stride ~= 0 then add(n) end
  return pts
end

-- The bounds of every axis over the sampled points of a panel.
local function bounds(samples, dims)
  local lo, hi = {}, {}
  for j = 1, dims do lo[j], hi[j] = math.huge, -math.huge end
  for _, pts in ipairs(samples) do
    for j = 1, dims do
      for _, v in ipairs(pts[j]) do
        if finite(v) then
          if v < lo[j] then lo[j] = v end
          if v > hi[j] then hi[j] = v end
        end
      end
    end
  end
  return lo, hi
end

-- gnuplot's tic step for a range (quantize_normal_tics, guide 20).
local function tic_step(range)
  local power = 10 ^ math.floor(math.log(range, 10))
  local xnorm = range / power
  local posns = 20 / xnorm
  local t
  if posns > 40 then t = 0.05 elseif posns > 20 then t = 0.1 elseif posns > 10 then t = 0.2
  elseif posns > 4 then t = 0.5 elseif posns > 2 then t = 1 elseif posns > 0.5 then t = 2
  else t = math.ceil(xnorm) end
  return t * power
end

-- The axis range gnuplot will draw: the user's, else the data's extended
-- to whole tics (whole decades on a log axis, values already log10).
local function drawn_range(lo, hi, user, log)
  if type(user) == "table" and type(user[1]) == "number" and type(user[2]) == "number" then
    local a, b = user[1], user[2]
    if log then a, b = math.log(a, 10), math.log(b, 10) end
    return math.min(a, b), math.max(a, b)
  end
  if not (lo < hi) then return lo, hi end
  if log then return math.floor(lo), math.ceil(hi) end
  local t = tic_step(hi - lo)
  return math.floor(lo / t + 1e-9) * t, math.ceil(hi / t - 1e-9) * t, t
end

-- Does the segment (x0,y0)-(x1,y1) meet the box [bx0,bx1]x[by0,by1]?
-- (Liang-Barsky clipping.)
local function segment_meets(x0, y0, x1, y1, bx0, by0, bx1, by1)
  local t0, t1 = 0, 1
  local dx, dy = x1 - x0, y1 - y0
  local ps = {-dx, dx, -dy, dy}
  local qs = {x0 - bx0, bx1 - x0, y0 - by0, by1 - y0}
  for i = 1, 4 do
    local pp, qq = ps[i], qs[i]
    if pp == 0 then
      if qq < 0 then return false end
    else
      local r = qq / pp
      if pp < 0 then
        if r > t1 then return false elseif r > t0 then t0 = r end
      else
        if r < t0 then return false elseif r < t1 then t1 = r end
      end
    end
  end
  return true
end

local CORNERS = {
  {"top right", 1, 1}, {"top left", 0, 1}, {"bottom right", 1, 0}, {"bottom left", 0, 0},
  {"top center", 0.5, 1}, {"bottom center", 0.5, 0},
}

local CORNERS = {
  {"top right", 1, 1}, {"top left", 0, 1}, {"bottom right", 1, 0}, {"bottom left", 0, 0},
  {"top center", 0.5, 1}, {"bottom center", 0.5, 0},
}

-- The plot area of one panel and the font's metrics: pngcairo's default
-- font is about 8 pixels a character and 19 a key line, the margins about
-- 110 x 100 pixels (characters for text terminals).
local function panel_area(target, layout)
  local text = target.terminal == "dumb" or (target.file or ""):match("%.txt$")
  local W = target.size and target.size[1] or (text and 79 or 640)
  local H = target.size and target.size[2] or (text and 24 or 480)
  if layout then W, H = W / layout[2], H / layout[1] end
  local cw, lh, mw, mh = 8, 19, 110, 100
  if text then cw, lh, mw, mh = 1, 1, 12, 6 end
  return math.max(W - mw, 4 * cw), math.max(H - mh, 2 * lh), cw, lh
end

-- The size of the key box as fractions of the frame (fw x fh; cw, lh: the
-- character width and line height).
local function key_size(titles, fw, fh, cw, lh)
  local maxlen = 0
  for _, t in ipairs(titles) do maxlen = math.max(maxlen, utf8.len(t) or #t) end
  -- key text runs a little wider than tic labels (about 9 pixels a
  -- character), plus the sample line and the gaps
  local kc = cw > 1 and cw + 1 or cw
  return (maxlen * kc + 10 * kc) / fw, (#titles * lh + lh / 2) / fh
end

-- A tic step for [a, b] whose labels fit in `avail` (pixels) at `size`
-- per label: gnuplot's own step when they fit, else the next nice one
-- (1, 2, 5 x 10^k); nil when gnuplot's own is fine.
local function thin_tics(a, b, step, avail, label_size)
  if not (a < b) or not finite(a) or not finite(b) then return nil end
  step = step or tic_step(b - a)
  local function count(st) return math.floor((b - a) / st + 1e-9) + 1 end
  local function width(st)
    local m = 0
    for x = a, b + st / 2, st do
      local v = math.abs(x) < st * 1e-9 and 0 or x
      m = math.max(m, #string.format("%g", v))
    end
    return m
  end
  local fits = math.floor(avail / label_size(width(step))) + 1
  if count(step) <= fits then return nil end
  local power = 10 ^ math.floor(math.log(step, 10))
  for _ = 1, 6 do
    for _, f in ipairs{1, 2, 2.5, 5} do
      local st = f * power
      if st > step and count(st) <= math.floor(avail / label_size(width(st))) + 1 then
        return st
      end
    end
    power = power * 10
  end
  return nil
end

-- Where the key of a 2-D panel goes: the first corner whose box no point
-- or segment of the data enters (in the ranges gnuplot will draw: rx, ry),
-- else room made above the data (a headroom fraction is returned too),
-- else below the plot.
local function place_key(samples, styles, kw, kh, rx, ry, o)
  local lo, hi = {rx[1], ry[1]}, {rx[2], ry[2]}
  if not (lo[1] < hi[1]) or not (lo[2] < hi[2]) or kw > 0.8 or kh > 0.8 then
    return "below"
  end
  local m = 0.02
  for _, c in ipairs(CORNERS) do
    local bx0 = c[2] == 1 and 1 - kw - m or (c[2] == 0 and 0 or 0.5 - kw / 2 - m)
    local bx1 = bx0 + kw + m
    if c[2] == 0 then bx0, bx1 = -1, kw + m end
    if c[2] == 1 then bx1 = 2 end
    local by0 = c[3] == 1 and 1 - kh - m or -1
    local by1 = c[3] == 1 and 2 or kh + m
    local free = true
    for si, pts in ipairs(samples) do
      local X, Y = pts[1], pts[2]
      local sx, sy = hi[1] - lo[1], hi[2] - lo[2]
      local lines = styles[si]:find("line") or styles[si]:find("step") or styles[si]:find("imp")
      local px, py
      for i = 1, #X do
        local x, y = (X[i] - lo[1]) / sx, (Y[i] - lo[2]) / sy
        if finite(x) and finite(y) then
          if x >= bx0 and x <= bx1 and y >= by0 and y <= by1 then free = false break end
          if lines and px and segment_meets(px, py, x, y, bx0, by0, bx1, by1) then free = false break end
          px, py = x, y
        else
          px, py = nil, nil
        end
      end
      if not free then break end
    end
    if free then return c[1] end
  end
  -- room above the data for a key of a few lines, when y is autoscaled
  if o.yrange == nil and kh <= 0.3 then
    return "top right", (kh + m) / (1 - kh - m)
  end
  return "below"
end

-- The column names a series plots (object series), or nil.
local function series_names(s)
  if s.kind ~= "object" then return nil end
  local names = {}
  for j = 2, #s.src do names[#names + 1] = s.src[j] end
  if #names == 1 then return {nil, names[1]} end
  return names
end

-- Do all the series plot coordinate columns (kind "q") on every axis?
local function all_positions(p)
  for _, s in ipairs(p.series) do
    if s.kind ~= "object" or #s.src < 3 then return false end
    local obj = s.src[1]
    local ok, kinds = pcall(function() return obj:kinds() end)
    if not ok or type(kinds) ~= "table" then return false end
    for j = 2, #s.src do
      if kinds[s.src[j]] ~= "q" then return false end
    end
  end
  return #p.series > 0
end

-- Labels, key place and aspect for panel p whose blocks are `pb`, where the
-- user gave none (o: the panel's merged options).
local function panel_defaults(p, pb, o, target, layout)
  local auto = {}
  local dims = p.dim == 3 and 3 or 2
  -- labels: the column name every series shows on that axis
  for j, a in ipairs{"xlabel", "ylabel", "zlabel"} do
    if j <= dims then
      local name
      for si, s in ipairs(p.series) do
        local names = series_names(s)
        local nj = names and names[j]
        if nj == nil or (si > 1 and nj ~= name) then name = nil break end
        name = nj
      end
      auto[a] = name
    end
  end
  local logs = {}
  local lg = type(o.logscale) == "string" and o.logscale or ""
  for j, a in ipairs{"x", "y", "z"} do logs[j] = lg:find(a, 1, true) ~= nil end
  local samples, styles, titles = {}, {}, {}
  for i, b in ipairs(pb) do
    if b.n > 0 then
      samples[#samples + 1] = sample_block(b, logs, 4000)
      styles[#styles + 1] = p.series[i].with
    end
    if p.series[i].title and p.series[i].title ~= "" then titles[#titles + 1] = p.series[i].title end
  end
  if #samples == 0 then return auto end
  local pw, ph, cw, lh = panel_area(target, layout)
  local lo, hi = bounds(samples, dims)
  local rng, step = {}, {}
  for j, a in ipairs{"x", "y", "z"} do
    if j <= dims then
      local ra, rb, st = drawn_range(lo[j], hi[j], o[a .. "range"], logs[j])
      rng[j], step[j] = {ra, rb}, st
    end
  end
  -- equal aspect for configuration-space pictures whose frame would still
  -- fill half the panel (2-D) or whose spans are within a factor 4 (3-D)
  if o.aspect == nil and lg == "" and all_positions(p) then
    if dims == 2 then
      local xs, ys = rng[1][2] - rng[1][1], rng[2][2] - rng[2][1]
      if xs > 0 and ys > 0 then
        local r = ys / xs
        local fw, fh = pw, ph
        if ph / pw > r then fh = pw * r else fw = ph / r end
        if fw * fh >= 0.5 * pw * ph then auto.aspect = "equal" end
      end
    else
      local smin, smax = math.huge, 0
      for j = 1, 3 do
        local sp = hi[j] - lo[j]
        smin, smax = math.min(smin, sp), math.max(smax, sp)
      end
      if smin > 0 and smax / smin <= 4 then auto.aspect = "equal" end
    end
  end
  local aspect = o.aspect
  if aspect == nil then aspect = auto.aspect end
  -- the frame gnuplot will draw (2-D)
  local fw, fh = pw, ph
  if dims == 2 then
    local r
    if aspect == "equal" and rng[1][2] > rng[1][1] and rng[2][2] > rng[2][1] then
      r = (rng[2][2] - rng[2][1]) / (rng[1][2] - rng[1][1])
    elseif type(aspect) == "number" and aspect > 0 then
      r = aspect                               -- "set size ratio r": height / width
    end
    if r then
      if ph / pw > r then fh = pw * r else fw = ph / r end
    end
  end
  if o.key == nil and dims == 2 and #titles > 0 then
    local kw, kh = key_size(titles, fw, fh, cw, lh)
    auto.key, auto.headroom = place_key(samples, styles, kw, kh, rng[1], rng[2], o)
  end
  local function xlabel_size(chars) return chars * (cw - 1) + 1.5 * cw end
  if dims == 3 then
    -- the horizontal axes of a 3-D view are about half the panel wide; with
    -- equal units every axis gets the same tic step
    local steps, big = {}, 0
    for j = 1, 3 do
      steps[j] = step[j] or 0
      if j < 3 and not logs[j] then
        local thin = thin_tics(rng[j][1], rng[j][2], step[j], 0.5 * pw, xlabel_size)
        if thin then steps[j], auto[({"xtics", "ytics"})[j]] = thin, thin end
      end
      big = math.max(big, steps[j])
    end
    if aspect == "equal" then
      for j, a in ipairs{"xtics", "ytics", "ztics"} do
        if big > 0 and steps[j] > 0 and steps[j] < big and not logs[j] then auto[a] = big end
      end
    end
  else
    -- tic labels that would run into each other in the frame: fewer labels,
    -- the range kept as gnuplot would have drawn it
    if not logs[1] then
      auto.xtics = thin_tics(rng[1][1], rng[1][2], step[1], fw, xlabel_size)
      if auto.xtics and o.xrange == nil then auto.xrange = rng[1] end
    end
    if not logs[2] then
      auto.ytics = thin_tics(rng[2][1], rng[2][2], step[2], fh, function() return lh + lh / 4 end)
      if auto.ytics and o.yrange == nil then auto.yrange = rng[2] end
    end
  end
  return auto
end

-- A copy of the columns with values <= 0 on log axes replaced by NaN
-- (gnuplot leaves them out and breaks the line there).
local function log_safe(cols, logscale)
  if type(logscale) ~= "string" then return cols end
  local out = {}
  for j, c in ipairs(cols) do
    out[j] = c
    local axis = ({"x", "y", "z"})[j]
    if axis and logscale:find(axis, 1, true) and #c > 0 then
      local bad = false
      for i = 1, #c do
        local v = c[i]
        if not (v > 0) and v == v then bad = true break end
      end
      if bad then out[j] = c:map(function(v) if v > 0 then return v end return 0 / 0 end) end
    end
  end
  return out
end

M.panel_defaults = panel_defaults
M.log_safe = log_safe
M.tic_step = tic_step

return M
