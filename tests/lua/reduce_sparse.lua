-- reduce_sparse.lua -- the reduced integrators' sparse Newton matrices
-- (doc/scale.md §3): a chain of 40 masses carrying a rotor whose angle is
-- cyclic, coupled through a connection that reaches three masses ahead
-- (beta != 0 outside the chain's tridiagonal pattern), reduced by the
-- rotor's angle; RSPRK with linear = "sparse" (KLU on the pattern of the
-- reduced Routhian's second derivatives) gives the states of the dense LU
-- to 1e-12 over 300 steps, also forced (Gauss) and constrained (Lobatto);
-- the step Jacobians and Newton iteration counts agree (a pattern that
-- missed an entry would change both); auto chooses by size; bad values of
-- linear and iteration are named; the classical-Routhian path passes the
-- options to the core engine.
local T = require "dmech.test"
local dm = require "dmech"

local N = 40
local function chain(opts)
  return dm.system{name = "rotor chain", coords = {"theta", dm.coords("x", N)},
    params = {{"eps", 0.37}, {"beta", 0.7}, {"c", 0.05}, {"l", 0.2385}},
    L = function(q, v, p)
      local T2, V, w = 0, 0, v.theta
      for i = 1, N - 3, 2 do w = w + p.eps * q.x[i + 3] * v.x[i] end
      for i = 1, N do T2 = T2 + 0.5 * v.x[i]^2 end
      for i = 1, N + 1 do
        local d = (i <= N and q.x[i] or 0) - (i > 1 and q.x[i - 1] or 0)
        V = V + 0.5 * d^2 + 0.25 * p.beta * d^4
      end
      return T2 + 0.5 * (2.385 + q.x[1]^2) * w^2 - V
    end,
    force = opts.forced and function(q, v, p)
      local f = {0}
      for i = 1, N do f[i + 1] = -p.c * v.x[i] * (1 + q.x[i]^2) end
      return f
    end or nil,
    constraints = opts.constrained and function(q, p)
      return {q.x[N // 2]^2 + q.x[N // 2 + 1]^2 - p.l^2}
    end or nil}
end

local function start(constrained)
  local x0, v0 = {}, {}
  for i = 1, N do x0[i] = 0.1 * math.sin(2.385 * i); v0[i] = 0.05 * math.cos(1.3 * i) end
  if constrained then            -- on the circle of radius l, velocity tangent
    local a, b = N // 2, N // 2 + 1
    local ang = math.atan(x0[b], x0[a])
    local c, s = math.cos(ang), math.sin(ang)
    x0[a], x0[b] = 0.2385 * c, 0.2385 * s
    local r = v0[a] * c + v0[b] * s
    v0[a], v0[b] = v0[a] - r * c, v0[b] - r * s
  end
  return {q = x0, v = v0}
end

local function maxdiff(a, b)
  local w = 0
  for _, nm in ipairs(a:names()) do
    local ca, cb = a:column(nm), b:column(nm)
    for k = 1, #ca do w = math.max(w, math.abs(ca[k] - cb[k])) end
  end
  return w
end

for _, kind in ipairs{"plain", "forced", "constrained"} do
  local con = kind == "constrained"
  local red = dm.routh(chain{forced = kind == "forced", constrained = con}, {cyclic = {"theta"}, mu = 0.9})
  local method = con and "lobatto" or "gauss"
  local tr, I = {}, {}
  for _, lin in ipairs{"dense", "sparse", "auto"} do
    I[lin] = dm.integrator(red, {method = method, h = 0.05, linear = lin})
    tr[lin] = I[lin]:run(start(con), {steps = 300})
  end
  T.is(I.dense.stats.linear, "dense", kind .. ": linear = dense is the dense LU")
  T.is(I.sparse.stats.linear, "sparse", kind .. ": linear = sparse is KLU")
  T.is(I.auto.stats.linear, con and "dense" or "sparse",
       kind .. ": auto chooses " .. (con and "dense (constraints fill the blocks)" or "sparse at 80 unknowns"))
  local d = maxdiff(tr.dense, tr.sparse)
  T.ok(#tr.dense:names() > 2 * N and d <= 1e-12,
       ("%s %s: sparse and dense Newton give the same states over 300 steps (max diff %.2g)"):format(kind, method, d))
  if not con then     -- constrained: the full matrix is gathered, no pattern to miss
    T.is(I.sparse.stats.iters_total, I.dense.stats.iters_total,
         kind .. ": the same Newton iterations (" .. I.dense.stats.iters_total .. ")")
  end
end

-- the pattern: a stage block holds the chain's tridiagonal entries and the
-- connection's (i, i + 3), (i + 3, i); 2 stages x 2 stages of it
do
  local red = dm.routh(chain{}, {cyclic = {"theta"}, mu = 0.9})
  local I = dm.integrator(red, {method = "gauss", h = 0.05, linear = "sparse"})
  T.is(I.stats.nnz, 4 * (N + 2 * (N - 1) + 2 * (N // 2 - 1)),
       "nnz = 4 x (tridiagonal + the connection's off-band pairs)")
end

-- the step Jacobian from the sparse factorisation (forced)
do
  local red = dm.routh(chain{forced = true}, {cyclic = {"theta"}, mu = 0.9})
  local J = {}
  for _, lin in ipairs{"dense", "sparse"} do
    J[lin] = dm.integrator(red, {method = "gauss", h = 0.05, linear = lin}):jacobian(start(false))
  end
  local w = 0
  for i = 1, 2 * N do
    for j = 1, 2 * N do w = math.max(w, math.abs(J.dense[i][j] - J.sparse[i][j])) end
  end
  T.ok(w <= 1e-13, ("the step Jacobians agree (max diff %.2g)"):format(w))
end

-- options
do
  local red = dm.routh(chain{}, {cyclic = {"theta"}, mu = 0.9})
  T.error_like(function() dm.integrator(red, {method = "gauss", h = 0.05, linear = "banded"}) end,
    "option 'linear' must be \"auto\", \"dense\" or \"sparse\", got \"banded\"", "a bad linear value")
  T.error_like(function() dm.integrator(red, {method = "gauss", h = 0.05, iteration = "picard"}) end,
    "option 'iteration' must be \"auto\", \"newton\" or \"fixed\", got \"picard\"", "a bad iteration value")
  T.error_like(function() dm.integrator(red, {method = "gauss", h = 0.05, iteration = "fixed"}) end,
    "iteration = \"fixed\" needs a separable Lagrangian", "the fixed-point iteration is not RSPRK's")
  local a = dm.integrator(red, {method = "gauss", h = 0.05, iteration = "newton"}):run(start(false), {steps = 20})
  local b = dm.integrator(red, {method = "gauss", h = 0.05, iteration = "auto"}):run(start(false), {steps = 20})
  T.is(maxdiff(a, b), 0, "iteration = newton and auto are the same Newton for RSPRK")
end

-- a Lagrangian that is not mechanical is reduced through the classical
-- Routhian, integrated by the core engine: the options pass through
do
  local sys = dm.system{name = "relativistic particle", coords = {"r", "theta"}, params = {k = 0.5},
    L = function(q, v, p) return -dm.sqrt(1 - v.r^2 - q.r^2 * v.theta^2) + p.k / q.r end}
  local red = dm.routh(sys, {cyclic = {"theta"}, mu = 0.3})
  local s0 = {q = {1.2385}, v = {0.1}}
  local a = dm.integrator(red, {method = "gauss", h = 0.01, linear = "dense"})
  local b = dm.integrator(red, {method = "gauss", h = 0.01, linear = "sparse"})
  local d = maxdiff(a:run(s0, {steps = 100}), b:run(s0, {steps = 100}))
  T.ok(a.stats.linear == "dense" and b.stats.linear == "sparse" and d <= 1e-12,
       ("classical Routhian: linear reaches the core engine, same states (max diff %.2g)"):format(d))
  T.error_like(function() dm.integrator(red, {method = "gauss", h = 0.01, linear = "banded"}) end,
    "option 'linear' must be", "classical Routhian: a bad linear value")
end

T.done()
