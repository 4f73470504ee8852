-- dmech.bundles -- the catalog of principal bundles with their mechanics:
-- dm.bundles.<name>{...}, also reachable as dm.bundle{name = "<name>", ...}.
--
-- Each entry returns a trivial bundle S x G (shape chart, group) carrying a
-- reduced Lagrangian l(x, xdot, xi, p) written below in plain Lua (xi the
-- body velocity g^-1 gdot), so dm.mechanical_connection{bundle = B} derives
-- its mechanical connection A = I^-1 C, and
-- dm.discrete_mechanical_connection{bundle = B} its discrete one; the
-- orbiter carries its connection form instead.  The formulas are those of
-- doc/bundles-connections-holonomy.md §2.  The module returns an installer that
-- the C opener calls with the dm table being built.
return function(dm)
  local Bs = {}

  -- parameters from defaults, overridden by opts (the key "name" is the
  -- catalog's own); unknown keys raise
  local function params(fname, opts, defaults)
    opts = opts or {}
    if type(opts) ~= "table" then
      error(("dm.bundles.%s: table of parameters expected, got %s"):format(fname, type(opts)), 3)
    end
    local known, list = {name = true}, {}
    for _, d in ipairs(defaults) do known[d[1]] = true end
    for k in pairs(opts) do
      if not known[k] then
        local names = {}
        for _, d in ipairs(defaults) do names[#names + 1] = d[1] end
        error(("dm.bundles.%s: unknown parameter %s (parameters: %s)"):format(fname, tostring(k),
          #names > 0 and table.concat(names, ", ") or "none"), 3)
      end
    end
    for _, d in ipairs(defaults) do
      local v = opts[d[1]]
      if v == nil then v = d[2] end
      if type(v) ~= "number" then
        error(("dm.bundles.%s: parameter %s must be a number, got %s"):format(fname, d[1], type(v)), 3)
      end
      list[#list + 1] = {d[1], v}
    end
    return list
  end

  local function def(name, sig, doc, f)
    Bs[name] = f
    dm.doc("dm.bundles." .. name, sig, doc, f)
  end

  def("platform", "dm.bundles.platform{I = 1, m = 1} -> B",
    "A point mass m at body position (u, v) on a platform of inertia I turning about its centre: S = R^2, G = SO(2), A = m(-v, u)/(I + m rho^2).",
    function(o)
      local p = params("platform", o, {{"I", 1}, {"m", 1}})
      return dm.bundle{name = "platform", shape_dim = 2, group = dm.lie.SO2(), params = p,
        L = function(x, xd, xi, p)
          local a, b = xd[1] - xi[1] * x[2], xd[2] + xi[1] * x[1]
          return 0.5 * p.I * xi[1]^2 + 0.5 * p.m * (a^2 + b^2)
        end}
    end)

  def("cat", "dm.bundles.cat{} -> B",
    "The planar three-link falling cat: three uniform rods (mass 1, length 1), the middle one the body, outer rods at joint angles x1, x2; S = T^2, G = SO(2); A(0, 0) = (7/27, 7/27).",
    function(o)
      params("cat", o, {})
      return dm.bundle{name = "three-link cat", shape_dim = 2, group = dm.lie.SO2(),
        L = function(x, xd, xi)
          local c = {{0, 0},
                     {-0.5 - 0.5 * dm.cos(x[1]), -0.5 * dm.sin(x[1])},
                     {0.5 + 0.5 * dm.cos(x[2]), 0.5 * dm.sin(x[2])}}
          local cm = {(c[1][1] + c[2][1] + c[3][1]) / 3, (c[1][2] + c[2][2] + c[3][2]) / 3}
          local T = (xi[1]^2 + (xi[1] + xd[1])^2 + (xi[1] + xd[2])^2) / 24
          for i = 1, 3 do
            local r = {c[i][1] - cm[1], c[i][2] - cm[2]}
            local v = {}
            for a = 1, 2 do
              -- body-frame velocity of the rod's centre plus the frame's turn
              local rd = 0
              if type(r[a]) ~= "number" then
                rd = r[a]:diff(x[1]) * xd[1] + r[a]:diff(x[2]) * xd[2]
              end
              v[a] = rd
            end
            v[1] = v[1] - xi[1] * r[2]
            v[2] = v[2] + xi[1] * r[1]
            T = T + 0.5 * (v[1]^2 + v[2]^2)
          end
          return T
        end}
    end)

  def("heisenberg", "dm.bundles.heisenberg{} -> B",
    "The Heisenberg bundle R^3 -> R^2, G = R moving z: l = (xdot^2 + ydot^2)/2 + (xi + (x ydot - y xdot)/2)^2/2; holonomy = minus the enclosed area.",
    function(o)
      params("heisenberg", o, {})
      return dm.bundle{name = "Heisenberg", shape_dim = 2, group = dm.lie.Rn(1),
        L = function(x, xd, xi)
          return 0.5 * (xd[1]^2 + xd[2]^2) + 0.5 * (xi[1] + 0.5 * (x[1] * xd[2] - x[2] * xd[1]))^2
        end}
    end)

  def("rotor", "dm.bundles.rotor{I1 = 1, I2 = 1, I3 = 1, k1 = 0.1, k2 = 0.2, k3 = 0.3} -> B",
    "A rigid satellite with three rotors on its principal axes: S = T^3 (rotor angles), G = SO(3); locked inertia diag(I), rotor inertias k, A = diag(k/I) constant, curvature B(e1, e2) = -(k1 k2/(I1 I2)) e3.",
    function(o)
      local p = params("rotor", o, {{"I1", 1}, {"I2", 1}, {"I3", 1}, {"k1", 0.1}, {"k2", 0.2}, {"k3", 0.3}})
      return dm.bundle{name = "rotor craft", shape_dim = 3, group = dm.lie.SO3(), params = p,
        L = function(x, xd, xi, p)
          local I, k = {p.I1, p.I2, p.I3}, {p.k1, p.k2, p.k3}
          local T = 0
          for i = 1, 3 do
            T = T + 0.5 * (I[i] - k[i]) * xi[i]^2 + 0.5 * k[i] * (xi[i] + xd[i])^2
          end
          return T
        end}
    end)

  def("orbiter", "dm.bundles.orbiter{} -> B",
    "The planar orbiter SE(2) -> R^2 with G = SO(2) the heading; its connection (heading locked to the polar angle) A = (y, -x)/|p|^2 is dm.connection{bundle = B}.",
    function(o)
      params("orbiter", o, {})
      return dm.bundle{name = "planar orbiter", shape_dim = 2, group = dm.lie.SO2(),
        A = function(x)
          local r2 = x[1]^2 + x[2]^2
          return {{x[2] / r2, -x[1] / r2}}
        end}
    end)

  dm.bundles = Bs
end
