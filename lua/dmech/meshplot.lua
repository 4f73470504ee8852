-- dmech.meshplot -- pictures of meshes and their cochains: dm.plot_mesh.
--
--   dm.plot_mesh{M, values = c0, arrows = a1 | mat, output = "f.png", ...}
--
-- values: a primal 0-cochain (or a table of vertex values): triangles
--   coloured by the mean of their vertex values (gnuplot pm3d), flat in the
--   plane (seen from above, equal axes) or as a surface in R^3;
--   a primal 2-cochain on a triangle mesh colours each triangle by its
--   value divided by its area (a density).
-- arrows: a primal 1-cochain (drawn through M:sharp) or a mat of vectors,
--   one row per vertex; every = k keeps every k-th vertex, scale = s
--   multiplies the lengths (default: the longest arrow = 0.9 sqrt(every)
--   mean edges).
-- Options: title, cblabel, view = {rot_x, rot_z}, size = {w, h}, edges =
--   true (draw the triangle edges), output (png, svg, pdf), terminal,
--   palette (a gnuplot palette definition).  In R^3 the triangles are sent
--   back to front and only arrows at vertices facing the viewer are drawn
--   (outward normals: consistently oriented surfaces).
-- The triangles go to gnuplot as a datablock of pm3d quadrilaterals
-- (each triangle a degenerate quad: two scans of two points).
local core = require "dmech.core"
local gp = core._gp
local M = {}

local function fail(fmt, ...) error("dm.plot_mesh: " .. string.format(fmt, ...), 0) end

local KEYS = {values = true, arrows = true, every = true, scale = true, title = true,
  cblabel = true, view = true, size = true, edges = true, output = true, terminal = true,
  palette = true}

local function ismesh(x)
  local mt = getmetatable(x)
  return type(x) == "userdata" and type(mt) == "table" and rawget(mt, "__name") == "mesh"
end

local fmt = gp.fmt
local function row(buf, x, y, z, c)
  buf[#buf + 1] = fmt(x) .. " " .. fmt(y) .. " " .. fmt(z) .. " " .. fmt(c) .. "\n"
end

-- Unit vector from the scene towards the viewer for gnuplot's `set view
-- rx, rz`, in object coordinates.
local function towards_viewer(view)
  local rx, rz = math.rad(view[1]), math.rad(view[2])
  return {math.sin(rz) * math.sin(rx), -math.cos(rz) * math.sin(rx), math.cos(rx)}
end

-- Triangle normals (not normalised; outward for consistently oriented
-- surfaces) and their sums at the vertices.
local function normals(T, X)
  local tn, vn = {}, {}
  for i = 1, #X do vn[i] = {0, 0, 0} end
  for t = 1, #T do
    local a, b, c = X[T[t][1]], X[T[t][2]], X[T[t][3]]
    local u = {b[1] - a[1], b[2] - a[2], b[3] - a[3]}
    local w = {c[1] - a[1], c[2] - a[2], c[3] - a[3]}
    local nrm = {u[2] * w[3] - u[3] * w[2], u[3] * w[1] - u[1] * w[3], u[1] * w[2] - u[2] * w[1]}
    tn[t] = nrm
    for j = 1, 3 do
      local s = vn[T[t][j]]
      s[1], s[2], s[3] = s[1] + nrm[1], s[2] + nrm[2], s[3] + nrm[3]
    end
  end
  return tn, vn
end

-- The triangle datablock text; in R^3 the triangles go back to front
-- (painter's order), so that gnuplot needs no depth sorting and arrows
-- drawn afterwards stay visible.
local function triangles(mesh, X, N, vals, density, eye)
  local T = mesh:simplices(2)
  local area = density and mesh:volumes(2)
  local buf = {"$dm_mesh << EOD\n"}
  local order = {}
  for t = 1, #T do order[t] = t end
  if N == 3 then
    local depth = {}
    for t = 1, #T do
      local d = 0
      for j = 1, 3 do
        local p = X[T[t][j]]
        d = d + p[1] * eye[1] + p[2] * eye[2] + p[3] * eye[3]
      end
      depth[t] = d
    end
    table.sort(order, function(i, j) return depth[i] < depth[j] end)
  end
  for _, t in ipairs(order) do
    local a, b, c = T[t][1], T[t][2], T[t][3]
    local v = density and vals[t] / area[t] or (vals[a] + vals[b] + vals[c]) / 3
    local pa, pb, pc = X[a], X[b], X[c]
    row(buf, pa[1], pa[2], N == 3 and pa[3] or 0, v)
    row(buf, pb[1], pb[2], N == 3 and pb[3] or 0, v)
    buf[#buf + 1] = "\n"
    row(buf, pc[1], pc[2], N == 3 and pc[3] or 0, v)
    row(buf, pc[1], pc[2], N == 3 and pc[3] or 0, v)
    buf[#buf + 1] = "\n\n"
  end
  buf[#buf + 1] = "EOD\n"
  return table.concat(buf)
end

function M.plot(spec)
  if type(spec) ~= "table" then fail("a table {mesh, values =, arrows =, ...} expected, got %s", type(spec)) end
  local mesh = spec[1]
  if not ismesh(mesh) then fail("argument 1: mesh expected, got %s", type(mesh)) end
  for k in pairs(spec) do
    if type(k) == "string" and not KEYS[k] then fail("unknown option '%s'", k) end
  end
  local n, N = mesh:dim()
  if n ~= 2 or (N ~= 2 and N ~= 3) then fail("triangle meshes in R^2 or R^3 only (this one: %d-dimensional in R^%d)", n, N) end
  if spec.values == nil and spec.arrows == nil then fail("nothing to plot: give values = or arrows =") end
  local X = mesh:vertices()
  local view = spec.view or {60, 30}
  local eye = towards_viewer(view)
  local cmds = {}
  local function add(s) cmds[#cmds + 1] = s end
  local data = {}
  -- values
  local vals, density
  if spec.values ~= nil then
    local v = spec.values
    if type(v) == "userdata" and v.degree then
      local k = v:degree()
      if k == 2 then density = true elseif k ~= 0 then fail("values: primal 0- or 2-cochain expected, got degree %d", k) end
      if v:mesh() ~= mesh then fail("values: the cochain lives on another mesh") end
    elseif type(v) ~= "table" or #v ~= #X then
      fail("values: a cochain or a table of %d vertex values expected", #X)
    end
    vals = v
    data[#data + 1] = triangles(mesh, X, N, vals, density, eye)
  end
  -- arrows
  local narrows = 0
  if spec.arrows ~= nil then
    local V = spec.arrows
    if type(V) == "userdata" and V.degree then
      if V:degree() ~= 1 then fail("arrows: primal 1-cochain or mat expected") end
      V = mesh:sharp(V)
    end
    local every = spec.every or math.max(1, #X // 600)
    local len, edges = 0, mesh:volumes(1)
    for i = 1, #edges do len = len + edges[i] end
    len = len / #edges
    local vmax = 0
    for i = 1, #X do
      local s = 0
      for c = 1, N do s = s + V[i][c] ^ 2 end
      vmax = math.max(vmax, math.sqrt(s))
    end
    local scale = spec.scale or (vmax > 0 and 0.9 * len * every ^ 0.5 / vmax or 1)
    local buf = {"$dm_arrows << EOD\n"}
    local vn = N == 3 and select(2, normals(mesh:simplices(2), X))
    for i = 1, #X, every do
      local p, w = X[i], V[i]
      if vn and vn[i][1] * eye[1] + vn[i][2] * eye[2] + vn[i][3] * eye[3] <= 0 then goto continue end
      buf[#buf + 1] = fmt(p[1]) .. " " .. fmt(p[2]) .. " " .. fmt(N == 3 and p[3] or 0) .. " " ..
        fmt(scale * w[1]) .. " " .. fmt(scale * w[2]) .. " " .. fmt(N == 3 and scale * w[3] or 0) .. "\n"
      narrows = narrows + 1
      ::continue::
    end
    buf[#buf + 1] = "EOD\n"
    data[#data + 1] = table.concat(buf)
  end
  gp.begin("dm.plot_mesh")
  gp.send("reset\n")
  gp.terminal{terminal = spec.terminal, file = spec.output, size = spec.size, window = 0}
  for _, d in ipairs(data) do gp.send(d) end
  if spec.title then add("set title " .. gp.quote(tostring(spec.title))) end
  if spec.cblabel then add("set cblabel " .. gp.quote(tostring(spec.cblabel))) end
  add("unset key")
  add(spec.palette and ("set palette " .. spec.palette) or "set palette defined (0 '#313695', 1 '#74add1', 2 '#e0f3f8', 3 '#fee090', 4 '#f46d43', 5 '#a50026')")
  if N == 2 then
    add("set view map")
    add("set size ratio -1")
    add("set xlabel 'x'")
    add("set ylabel 'y'")
    add("unset ztics")
  else
    add(string.format("set view %s, %s, 1.2, 1", fmt(view[1]), fmt(view[2])))
    add("set colorbox user origin screen 0.85, screen 0.2 size screen 0.025, screen 0.6")
    local zmin, zmax = math.huge, -math.huge
    for i = 1, #X do zmin, zmax = math.min(zmin, X[i][3]), math.max(zmax, X[i][3]) end
    if zmax > zmin then     -- two or three tics: the z axis is short at equal scales
      local step = 10 ^ math.floor(math.log(zmax - zmin, 10))
      while (zmax - zmin) / step > 3 do step = step * 2 end
      add("set ztics " .. fmt(step))
    end
    add("set view equal xyz")
    add("set xlabel 'x'")
    add("set ylabel 'y'")
    add("set zlabel 'z'")
    add("set xyplane relative 0")
  end
  add("set pm3d" .. (spec.edges and " border lc rgb '#303030' lw 0.4" or " noborder"))
  add("set pm3d corners2color c1")
  if vals then
    local lo, hi = math.huge, -math.huge
    local area = density and mesh:volumes(2)
    for i = 1, (density and #area or #X) do
      local v = density and vals[i] / area[i] or vals[i]
      lo, hi = math.min(lo, v), math.max(hi, v)
    end
    if hi > lo then add("set cbrange [" .. fmt(lo) .. ":" .. fmt(hi) .. "]") end
  end
  local items = {}
  if vals then items[#items + 1] = "$dm_mesh using 1:2:3:4 with pm3d" end
  if narrows > 0 then
    items[#items + 1] = "$dm_arrows using 1:2:3:4:5:6 with vectors head size screen 0.008,25,40 filled lc rgb '#202020' lw 1"
  end
  if not vals then add("unset colorbox") end
  add("splot " .. table.concat(items, ", "))
  gp.send(table.concat(cmds, "\n") .. "\n")
  local msgs = gp.checkpoint("dm.plot_mesh")
  for line in (msgs or ""):gmatch("[^\n]+") do
    line = line:gsub("^%s*line %d+: ", ""):gsub("^warning: ", "")
    if line:find("%S") then io.stderr:write("dm.plot_mesh: gnuplot: ", line, "\n") end
  end
end

return M
