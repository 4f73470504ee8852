-- dmech.systems -- the catalog of example systems: dm.systems.<name>{...}.
--
-- Each entry is a function of an optional table of parameters (and a few
-- options) returning a dm.system whose Lagrangian is written below in plain
-- Lua, so every one is also an example of dm.system.  Several entries also
-- exist as hand-written C (the speed references): impl = "c" gives that
-- implementation of the same system -- same Lagrangian, coordinates and
-- parameters, no expressions.  The module returns an installer that the C
-- opener calls with the dm table being built and the table of C
-- constructors; the functions use dm only when called.
return function(dm, C)
  local S = {}

  -- Errors point at the caller's line, however deep in this file they
  -- are raised (the helpers nest): the first frame outside this file (a C
  -- caller such as pcall gets none).  A fixed level put "systems.lua:289:"
  -- in front of messages when an entry went through two helpers.
  local here = debug.getinfo(1, "S").source
  local function raise(msg)
    local level = 2
    while true do
      local info = debug.getinfo(level, "S")
      if info == nil then error(msg, 0) end
      if info.source ~= here then error(msg, level) end
      level = level + 1
    end
  end
  C = C or {}

  -- Parameters in a fixed order from defaults, overridden by opts; the
  -- option names in `extra` (and impl, which every entry takes) are
  -- returned separately.  Unknown keys raise.
  local function params(fname, opts, defaults, extra)
    opts = opts or {}
    if type(opts) ~= "table" then
      raise(("dm.systems.%s: table of parameters expected, got %s"):format(fname, type(opts)))
    end
    extra = extra or {}
    if opts.impl ~= nil and opts.impl ~= "traced" and not C[fname] then
      local have = {}
      for k in pairs(C) do have[#have + 1] = k end
      table.sort(have)
      raise(("dm.systems.%s: no C implementation (impl = \"c\" exists for %s)"):format(fname,
        table.concat(have, ", ")))
    end
    local known, list, ex = {impl = true}, {}, {}
    for _, d in ipairs(defaults) do known[d[1]] = true end
    for _, k in ipairs(extra) do known[k] = true end
    for k in pairs(opts) do
      if not known[k] then
        local names = {}
        for _, d in ipairs(defaults) do names[#names + 1] = d[1] end
        for _, e in ipairs(extra) do names[#names + 1] = e end
        names[#names + 1] = "impl"
        raise(("dm.systems.%s: unknown parameter %s (parameters: %s)"):format(fname, tostring(k),
          table.concat(names, ", ")))
      end
    end
    for _, d in ipairs(defaults) do
      local v = opts[d[1]]
      if v == nil then v = d[2] end
      if type(v) ~= "number" then
        raise(("dm.systems.%s: parameter %s must be a number, got %s"):format(fname, d[1], type(v)))
      end
      if v ~= v or v == math.huge or v == -math.huge then
        raise(("dm.systems.%s: parameter %s must be finite, got %s"):format(fname, d[1],
          v ~= v and "nan" or v > 0 and "inf" or "-inf"))
      end
      list[#list + 1] = {d[1], v}
    end
    for _, k in ipairs(extra) do ex[k] = opts[k] end
    ex.impl = opts.impl
    return list, ex
  end

  -- The C implementation when opts.impl == "c" (nil for the traced one).
  local function impl(fname, ex, list)
    local which = ex.impl or "traced"
    if which == "traced" then return nil end
    if which ~= "c" then
      raise(("dm.systems.%s: impl must be \"traced\" or \"c\", got %s"):format(fname, tostring(which)))
    end
    local t = {}
    for _, d in ipairs(list) do t[d[1]] = d[2] end
    for k, v in pairs(ex) do if k ~= "impl" then t[k] = v end end
    return C[fname](t)
  end

  local function def(name, sig, doc, f)
    S[name] = f
    dm.doc("dm.systems." .. name, sig, doc, f)
  end

  local function sq(x) return x * x end

  def("harmonic", "dm.systems.harmonic{omega=1, m=1, impl=\"traced\"|\"c\"} -> system",
    "Harmonic oscillator L = m v^2/2 - m omega^2 x^2/2 (coordinate x): Gauss methods rotate (omega x, p/m) exactly by a modified angle, Stormer-Verlet is stable for h omega < 2.",
    function(o)
      local p, ex = params("harmonic", o, {{"m", 1}, {"omega", 1}})
      return impl("harmonic", ex, p) or dm.system{name = "harmonic oscillator", coords = {"x"}, params = p,
        L = function(q, v, p) return 0.5 * p.m * (v.x^2 - p.omega^2 * q.x^2) end}
    end)

  def("damped", "dm.systems.damped{omega=1, c=0.1, m=1, impl=\"traced\"|\"c\"} -> system",
    "Damped oscillator: L = m v^2/2 - m omega^2 x^2/2 with the Lagrange-d'Alembert force F = -c v; for light damping the energy decays like E0 exp(-c t/m).",
    function(o)
      local p, ex = params("damped", o, {{"m", 1}, {"omega", 1}, {"c", 0.1}})
      return impl("damped", ex, p) or dm.system{name = "damped oscillator", coords = {"x"}, params = p,
        L = function(q, v, p) return 0.5 * p.m * (v.x^2 - p.omega^2 * q.x^2) end,
        force = function(q, v, p) return {-p.c * v.x} end}
    end)

  def("pendulum", "dm.systems.pendulum{g=9.81, l=1, m=1, impl=\"traced\"|\"c\"} -> system",
    "Planar pendulum, angle theta from the downward vertical: L = m l^2 thetadot^2/2 + m g l cos(theta).",
    function(o)
      local p, ex = params("pendulum", o, {{"g", 9.81}, {"l", 1}, {"m", 1}})
      return impl("pendulum", ex, p) or dm.system{name = "pendulum", coords = {"theta"}, params = p,
        L = function(q, v, p)
          return 0.5 * p.m * p.l^2 * v.theta^2 + p.m * p.g * p.l * dm.cos(q.theta)
        end}
    end)

  def("kepler", "dm.systems.kepler{mu=1, dim=2, impl=\"traced\"|\"c\"} -> system",
    "Kepler problem in Cartesian coordinates (x, y[, z]): L = |v|^2/2 + mu/|q|; energy, angular momentum and the Runge-Lenz vector are conserved (e = 0.6: q = (0.4, 0), p = (0, 2), period 2 pi).",
    function(o)
      local p, ex = params("kepler", o, {{"mu", 1}}, {"dim"})
      local dim = ex.dim or 2
      if dim ~= 2 and dim ~= 3 then raise("dm.systems.kepler: dim must be 2 or 3") end
      local c = impl("kepler", ex, p)
      if c then return c end
      local coords = dim == 2 and {"x", "y"} or {"x", "y", "z"}
      return dm.system{name = "Kepler (Cartesian)", coords = coords, params = p,
        L = function(q, v, p)
          local T, r2 = 0, 0
          for i = 1, dim do T = T + v[i]^2; r2 = r2 + q[i]^2 end
          return 0.5 * T + p.mu / dm.sqrt(r2)
        end}
    end)

  def("kepler_polar", "dm.systems.kepler_polar{mu=1} -> system",
    "Kepler problem in polar coordinates (r, theta): L = (rdot^2 + r^2 thetadot^2)/2 + mu/r; theta is cyclic, its momentum r^2 thetadot is the angular momentum.",
    function(o)
      local p = params("kepler_polar", o, {{"mu", 1}})
      return dm.system{name = "Kepler (polar)", coords = {"r", "theta"}, params = p,
        L = function(q, v, p)
          return 0.5 * (v.r^2 + q.r^2 * v.theta^2) + p.mu / q.r
        end}
    end)

  -- the J2 potential of thesis §2.9 with the sign of its Kepler term corrected
  -- (doc/reduce.md §13)
  local function j2_potential(R2, z, J2)
    local R = dm.sqrt(R2)
    return -1 / R + J2 / R^3 * (1.5 * z^2 / R2 - 0.5)
  end

  def("j2", "dm.systems.j2{J2=0.05, impl=\"traced\"|\"c\"} -> system",
    "J2 satellite in Cartesian (x, y, z), non-dimensional (Earth radius 1): L = |v|^2/2 - V, V = -1/|q| + (J2/|q|^3)(3 z^2/(2|q|^2) - 1/2) (thesis §2.9, with the sign of the printed Kepler term corrected); the z angular momentum is conserved.",
    function(o)
      local p, ex = params("j2", o, {{"J2", 0.05}})
      return impl("j2", ex, p) or dm.system{name = "J2 satellite (Cartesian)", coords = {"x", "y", "z"}, params = p,
        L = function(q, v, p)
          return 0.5 * (v.x^2 + v.y^2 + v.z^2) - j2_potential(q.x^2 + q.y^2 + q.z^2, q.z, p.J2)
        end}
    end)

  def("j2_cylindrical", "dm.systems.j2_cylindrical{J2=0.05} -> system",
    "J2 satellite in cylindrical (r, theta, z): L = (rdot^2 + r^2 thetadot^2 + zdot^2)/2 - V(r, z) with the corrected potential; theta is cyclic (J = r^2 thetadot), the reduced Routhian is (rdot^2 + zdot^2)/2 - V - mu^2/(2 r^2).",
    function(o)
      local p = params("j2_cylindrical", o, {{"J2", 0.05}})
      return dm.system{name = "J2 satellite (cylindrical)", coords = {"r", "theta", "z"}, params = p,
        L = function(q, v, p)
          return 0.5 * (v.r^2 + q.r^2 * v.theta^2 + v.z^2) - j2_potential(q.r^2 + q.z^2, q.z, p.J2)
        end}
    end)

  def("henon_heiles", "dm.systems.henon_heiles{lambda=1} -> system",
    "Henon-Heiles system: L = (xdot^2 + ydot^2)/2 - (x^2 + y^2)/2 - lambda (x^2 y - y^3/3); bounded motion below the escape energy 1/(6 lambda^2), chaotic near it.",
    function(o)
      local p = params("henon_heiles", o, {{"lambda", 1}})
      return dm.system{name = "Henon-Heiles", coords = {"x", "y"}, params = p,
        L = function(q, v, p)
          local x, y = q.x, q.y
          return 0.5 * (v.x^2 + v.y^2) - 0.5 * (x^2 + y^2) - p.lambda * (x^2 * y - y^3 / 3)
        end}
    end)

  def("spherical_pendulum", "dm.systems.spherical_pendulum{g=9.81, l=1, m=1, impl=\"traced\"|\"c\"} -> system",
    "Spherical pendulum in spherical coordinates (theta from the downward vertical, phi azimuth): L = m l^2 (thetadot^2 + sin^2(theta) phidot^2)/2 + m g l cos(theta); phi is cyclic (the vertical angular momentum m l^2 sin^2(theta) phidot).",
    function(o)
      local p, ex = params("spherical_pendulum", o, {{"g", 9.81}, {"l", 1}, {"m", 1}})
      return impl("spherical_pendulum", ex, p) or dm.system{name = "spherical pendulum", coords = {"theta", "phi"}, params = p,
        L = function(q, v, p)
          return 0.5 * p.m * p.l^2 * (v.theta^2 + dm.sin(q.theta)^2 * v.phi^2)
            + p.m * p.g * p.l * dm.cos(q.theta)
        end}
    end)

  def("spherical_pendulum_r3", "dm.systems.spherical_pendulum_r3{g=9.81, l=1, m=1, form=\"squared\", impl=\"traced\"|\"c\"} -> system",
    "Spherical pendulum in R^3 (x, y, z) with the holonomic constraint |q|^2 - l^2 = 0 (form=\"norm\": |q| - l = 0): L = m |v|^2/2 - m g z; integrated with Lagrange multipliers (RATTLE, or multipliers at every stage).",
    function(o)
      local p, ex = params("spherical_pendulum_r3", o, {{"g", 9.81}, {"l", 1}, {"m", 1}}, {"form"})
      local form = ex.form or "squared"
      if form ~= "squared" and form ~= "norm" then
        raise("dm.systems.spherical_pendulum_r3: form must be \"squared\" or \"norm\"")
      end
      local c = impl("spherical_pendulum_r3", ex, p)
      if c then return c end
      return dm.system{name = "spherical pendulum (R3)", coords = {"x", "y", "z"}, params = p,
        L = function(q, v, p)
          return 0.5 * p.m * (v.x^2 + v.y^2 + v.z^2) - p.m * p.g * q.z
        end,
        constraints = function(q, p)
          local r2 = q.x^2 + q.y^2 + q.z^2
          if form == "norm" then return dm.sqrt(r2) - p.l end
          return r2 - p.l^2
        end}
    end)

  local dsp_params = {{"g", 9.81}, {"l1", 1}, {"l2", 1}, {"m1", 1}, {"m2", 1}}

  def("double_spherical_pendulum",
    "dm.systems.double_spherical_pendulum{g=9.81, l1=1, l2=1, m1=1, m2=1, form=\"cylindrical\"|\"shape\"} -> system",
    "Double spherical pendulum (thesis §2.10) in cylindrical coordinates of each bob relative to its pivot, hanging below (z_i = -sqrt(l_i^2 - r_i^2)): coords r1, theta1, r2, theta2, or with form=\"shape\" theta, r1, r2, phi (theta1 = theta, theta2 = theta + phi; theta cyclic for the simultaneous rotation). L = m1|q1dot|^2/2 + m2|q1dot + q2dot|^2/2 - m1 g z1 - m2 g (z1 + z2), written through phi = theta2 - theta1 only.",
    function(o)
      local p, ex = params("double_spherical_pendulum", o, dsp_params, {"form"})
      local shape = (ex.form or "cylindrical") == "shape"
      if ex.form and ex.form ~= "shape" and ex.form ~= "cylindrical" then
        raise("dm.systems.double_spherical_pendulum: form must be \"cylindrical\" or \"shape\"")
      end
      return dm.system{name = "double spherical pendulum", params = p,
        coords = shape and {"theta", "r1", "r2", "phi"} or {"r1", "theta1", "r2", "theta2"},
        L = function(q, v, p)
          local r1, r2, rd1, rd2 = q.r1, q.r2, v.r1, v.r2
          local phi, w1, w2               -- relative angle, angular velocities
          if shape then
            phi, w1, w2 = q.phi, v.theta, v.theta + v.phi
          else
            phi, w1, w2 = q.theta2 - q.theta1, v.theta1, v.theta2
          end
          local s1, s2 = dm.sqrt(p.l1^2 - r1^2), dm.sqrt(p.l2^2 - r2^2)
          local zd1, zd2 = r1 * rd1 / s1, r2 * rd2 / s2        -- z_i = -s_i
          local v1sq = rd1^2 + r1^2 * w1^2 + zd1^2
          local v2sq = rd2^2 + r2^2 * w2^2 + zd2^2
          -- q1dot . q2dot: horizontal parts rotated by phi, plus the vertical parts
          local dot = (rd1 * rd2 + r1 * r2 * w1 * w2) * dm.cos(phi)
            + (r1 * w1 * rd2 - rd1 * r2 * w2) * dm.sin(phi) + zd1 * zd2
          local T = 0.5 * p.m1 * v1sq + 0.5 * p.m2 * (v1sq + v2sq + 2 * dot)
          return T + p.m1 * p.g * s1 + p.m2 * p.g * (s1 + s2)
        end}
    end)

  def("double_spherical_pendulum_r3",
    "dm.systems.double_spherical_pendulum_r3{g=9.81, l1=1, l2=1, m1=1, m2=1} -> system",
    "Double spherical pendulum in R^3 x R^3 (coords x1, y1, z1 of the first bob from the pivot, x2, y2, z2 of the second from the first) with the constraints |q1| - l1 = 0, |q2| - l2 = 0 (thesis §2.10.4).",
    function(o)
      local p = params("double_spherical_pendulum_r3", o, dsp_params)
      return dm.system{name = "double spherical pendulum (R3xR3)", params = p,
        coords = {"x1", "y1", "z1", "x2", "y2", "z2"},
        L = function(q, v, p)
          local T1 = v.x1^2 + v.y1^2 + v.z1^2
          local T2 = sq(v.x1 + v.x2) + sq(v.y1 + v.y2) + sq(v.z1 + v.z2)
          return 0.5 * p.m1 * T1 + 0.5 * p.m2 * T2 - p.m1 * p.g * q.z1 - p.m2 * p.g * (q.z1 + q.z2)
        end,
        constraints = function(q, p)
          return {dm.sqrt(q.x1^2 + q.y1^2 + q.z1^2) - p.l1, dm.sqrt(q.x2^2 + q.y2^2 + q.z2^2) - p.l2}
        end}
    end)

  -- {==== large systems: lattices, N bodies, a string ========================
  -- Coordinates are arrays (dm.coords): q.x[i] in L, traj.q.x[i] after a run.

  -- the chain's size and its ends from the options
  local function chain_opts(fname, o, defaults)
    local p, ex = params(fname, o, defaults, {"n", "ends"})
    local n = ex.n or 32
    if math.type(n) ~= "integer" or n < 2 then
      raise(("dm.systems.%s: n must be an integer >= 2, got %s"):format(fname, tostring(ex.n)))
    elseif n > 1000000 then
      raise(("dm.systems.%s: n = %d is too many (at most 1000000)"):format(fname, n))
    end
    local ends = ex.ends or "fixed"
    if ends ~= "fixed" and ends ~= "periodic" then
      raise(("dm.systems.%s: ends must be \"fixed\" or \"periodic\", got %s"):format(fname, tostring(ends)))
    end
    return p, n, ends
  end

  -- the bond stretches r_0 .. r_n (fixed ends: x_0 = x_{n+1} = 0) or r_1 .. r_n (periodic)
  local function bonds(x, n, ends)
    local r = {}
    if ends == "fixed" then
      r[#r + 1] = x[1]
      for i = 1, n - 1 do r[#r + 1] = x[i + 1] - x[i] end
      r[#r + 1] = -x[n]
    else
      for i = 1, n - 1 do r[#r + 1] = x[i + 1] - x[i] end
      r[#r + 1] = x[1] - x[n]
    end
    return r
  end

  def("fpu", "dm.systems.fpu{n=32, alpha=0, beta=1, k=1, m=1, ends=\"fixed\"|\"periodic\"} -> system",
    "Fermi-Pasta-Ulam-Tsingou chain of n masses (coordinates x[1..n], displacements): L = sum m v_i^2/2 - sum_bonds (k r^2/2 + alpha r^3/3 + beta r^4/4), r the stretch of each bond, ends fixed (x_0 = x_{n+1} = 0) or periodic; beta > 0 is the FPU-beta chain, whose energy put in the lowest mode comes back (recurrence) instead of equipartitioning on short times.",
    function(o)
      local p, n, ends = chain_opts("fpu", o, {{"alpha", 0}, {"beta", 1}, {"k", 1}, {"m", 1}})
      return dm.system{name = "FPU chain", coords = dm.coords("x", n), params = p,
        L = function(q, v, p)
          local T, V = 0, 0
          for i = 1, n do T = T + v.x[i]^2 end
          for _, r in ipairs(bonds(q.x, n, ends)) do
            V = V + 0.5 * p.k * r^2 + p.alpha / 3 * r^3 + 0.25 * p.beta * r^4
          end
          return 0.5 * p.m * T - V
        end}
    end)

  def("toda", "dm.systems.toda{n=32, a=1, b=1, m=1, ends=\"periodic\"|\"fixed\"} -> system",
    "Toda lattice of n particles (coordinates x[1..n]): L = sum m v_i^2/2 - sum_bonds (a/b) exp(-b r), r = x_{i+1} - x_i (periodic: the bond x_1 - x_n closes the ring, where the lattice is completely integrable: the traces of the powers of its Lax matrix are conserved, see dm.systems.toda_integrals); with fixed ends x_0 = x_{n+1} = 0.",
    function(o)
      local p, n, ends = chain_opts("toda", o, {{"a", 1}, {"b", 1}, {"m", 1}})
      if type(o) ~= "table" or o.ends == nil then ends = "periodic" end
      return dm.system{name = "Toda lattice", coords = dm.coords("x", n), params = p,
        L = function(q, v, p)
          local T, V = 0, 0
          for i = 1, n do T = T + v.x[i]^2 end
          for _, r in ipairs(bonds(q.x, n, ends)) do V = V + p.a / p.b * dm.exp(-p.b * r) end
          return 0.5 * p.m * T - V
        end}
    end)

  -- tr L^k, k = 1 .. kmax, of the periodic Toda lattice's Lax matrix in
  -- Flaschka's variables: L symmetric tridiagonal and periodic, diagonal
  -- beta_i = -p_i sqrt(b/(4 m a)), off-diagonal alpha_i = exp(-b r_i/2)/2
  -- between i and i+1 (and n and 1), r_i = x_{i+1} - x_i; with these
  -- scalings dL/dt = sqrt(a b/m) [B, L] for the lattice of dm.systems.toda.
  -- (L^k)_jj from k products with the unit vector e_j, whose support stays
  -- within k sites of j: O(n k^2) in all.
  function S.toda_integrals(q, p, kmax, o)
    local function numbers(x, what)
      if type(x) ~= "table" or #x < 2 then
        raise(("dm.systems.toda_integrals: %s must be a list of at least 2 numbers, got %s")
          :format(what, type(x)))
      end
      for i = 1, #x do
        if type(x[i]) ~= "number" then
          raise(("dm.systems.toda_integrals: %s[%d] must be a number, got %s"):format(what, i, type(x[i])))
        end
      end
    end
    numbers(q, "q")
    numbers(p, "p")
    if #p ~= #q then
      raise(("dm.systems.toda_integrals: q and p must have the same length, got %d and %d"):format(#q, #p))
    end
    if kmax ~= nil and (math.type(kmax) ~= "integer" or kmax < 1 or kmax > 64) then
      raise(("dm.systems.toda_integrals: kmax must be an integer from 1 to 64, got %s"):format(tostring(kmax)))
    end
    if o ~= nil and type(o) ~= "table" then
      raise(("dm.systems.toda_integrals: parameters {a=, b=, m=} expected, got %s"):format(type(o)))
    end
    o = o or {}
    for _, k in ipairs{"a", "b", "m"} do
      if o[k] ~= nil and (type(o[k]) ~= "number" or not (o[k] > 0) or o[k] == math.huge) then
        raise(("dm.systems.toda_integrals: %s must be a positive finite number"):format(k))
      end
    end
    local n, a, b, m = #q, o.a or 1, o.b or 1, o.m or 1
    kmax = kmax or 4
    local kappa = -math.sqrt(b / (4 * m * a))
    local beta, alpha = {}, {}
    for i = 1, n do
      beta[i] = kappa * p[i]
      alpha[i] = 0.5 * math.exp(-0.5 * b * ((i < n and q[i + 1] or q[1]) - q[i]))
    end
    local tr = {}
    for k = 1, kmax do tr[k] = 0 end
    for j = 1, n do
      local cur = {[j] = 1.0}
      for k = 1, kmax do
        local nxt = {}
        for i, c in pairs(cur) do
          local ip, im = i % n + 1, (i - 2) % n + 1
          nxt[i] = (nxt[i] or 0) + beta[i] * c
          nxt[ip] = (nxt[ip] or 0) + alpha[i] * c
          nxt[im] = (nxt[im] or 0) + alpha[im] * c
        end
        cur = nxt
        tr[k] = tr[k] + (cur[j] or 0)
      end
    end
    return tr
  end
  dm.doc("dm.systems.toda_integrals", "dm.systems.toda_integrals(q, p[, kmax=4][, {a=1, b=1, m=1}]) -> {tr L, tr L^2, ...}",
    "The first kmax conserved quantities tr L^k of the periodic Toda lattice (dm.systems.toda with these parameters) at positions q and momenta p (lists of n numbers): L is the Lax matrix in Flaschka's variables, diagonal -p_i sqrt(b/(4 m a)), off-diagonal exp(-b (x_{i+1} - x_i)/2)/2, periodic (tr L^2 = H b/(2a)); O(n kmax^2) operations.",
    S.toda_integrals)

  def("nbody", "dm.systems.nbody{n=3, dim=2, G=1, masses={...}, soft=0} -> system",
    "Newtonian N-body problem, n bodies in the plane (dim = 2: coordinates x[1..n], y[1..n]) or in space (dim = 3: and z[1..n]): L = sum m_i |v_i|^2/2 + sum_{i<j} G m_i m_j / sqrt(|q_i - q_j|^2 + soft^2); masses m_i (default 1) are parameters m1 .. mn; momentum and angular momentum are conserved.",
    function(o)
      o = o or {}
      if type(o) ~= "table" then
        raise(("dm.systems.nbody: table of parameters expected, got %s"):format(type(o)))
      end
      local n, dim, masses = o.n or 3, o.dim or 2, o.masses
      local rest = {}
      for k, v in pairs(o) do if k ~= "n" and k ~= "dim" and k ~= "masses" then rest[k] = v end end
      local p = params("nbody", rest, {{"G", 1}, {"soft", 0}})
      if math.type(n) ~= "integer" or n < 2 then
        raise(("dm.systems.nbody: n must be an integer >= 2, got %s"):format(tostring(o.n)))
      elseif n > 100000 then
        raise(("dm.systems.nbody: n = %d is too many (at most 100000)"):format(n))
      end
      if dim ~= 2 and dim ~= 3 then
        raise(("dm.systems.nbody: dim must be 2 or 3, got %s"):format(tostring(dim)))
      end
      if masses ~= nil and (type(masses) ~= "table" or #masses ~= n) then
        raise(("dm.systems.nbody: masses must be a list of %d numbers"):format(n))
      end
      for i = 1, masses and n or 0 do
        if type(masses[i]) ~= "number" then
          raise(("dm.systems.nbody: masses[%d] must be a number, got %s"):format(i, type(masses[i])))
        end
      end
      for i = 1, n do p[#p + 1] = {"m" .. i, masses and masses[i] or 1} end
      local axes = dim == 2 and {"x", "y"} or {"x", "y", "z"}
      local coords = {}
      for _, a in ipairs(axes) do coords[#coords + 1] = dm.coords(a, n) end
      return dm.system{name = ("%d-body problem (%d-D)"):format(n, dim), coords = coords, params = p,
        L = function(q, v, p)
          local T, U = 0, 0
          for i = 1, n do
            local s = 0
            for _, a in ipairs(axes) do s = s + v[a][i]^2 end
            T = T + p["m" .. i] * s
          end
          for i = 1, n do
            for j = i + 1, n do
              local d2 = p.soft^2
              for _, a in ipairs(axes) do d2 = d2 + (q[a][i] - q[a][j])^2 end
              U = U + p["m" .. i] * p["m" .. j] / dm.sqrt(d2)
            end
          end
          return 0.5 * T + p.G * U
        end}
    end)

  def("string", "dm.systems.string{n=64, length=1, tension=1, density=1} -> system",
    "A string of the given length and tension, fixed at both ends, discretized by n interior nodes (coordinates u[1..n], transverse displacements, spacing dx = length/(n+1)): L = sum density dx v_i^2/2 - sum_bonds tension dx (sqrt(1 + ((u_{i+1} - u_i)/dx)^2) - 1), the exact stretching energy of each segment -- the nonlinear string; for small slopes the wave equation with speed sqrt(tension/density).",
    function(o)
      local p, ex = params("string", o, {{"density", 1}, {"length", 1}, {"tension", 1}}, {"n"})
      local n = ex.n or 64
      if math.type(n) ~= "integer" or n < 1 then
        raise(("dm.systems.string: n must be an integer >= 1, got %s"):format(tostring(ex.n)))
      elseif n > 1000000 then
        raise(("dm.systems.string: n = %d is too many (at most 1000000)"):format(n))
      end
      return dm.system{name = "nonlinear string", coords = dm.coords("u", n), params = p,
        L = function(q, v, p)
          local dx = p.length / (n + 1)
          local T, V = 0, 0
          for i = 1, n do T = T + v.u[i]^2 end
          local prev = 0
          for i = 1, n + 1 do
            local cur = i <= n and q.u[i] or 0
            local s = (cur - prev) / dx
            V = V + (dm.sqrt(1 + s^2) - 1)
            prev = cur
          end
          return 0.5 * p.density * dx * T - p.tension * dx * V
        end}
    end)

  dm.systems = S
end
