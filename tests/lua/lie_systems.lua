-- lie_systems.lua -- systems on Lie groups at the Lua surface:
-- dm.system{space = G, L = function(R, Om, p) ... end}, dm.integrator with
-- lgvi, lie:gauss and lie:gauss:cayley, runs into trajectories (mu, xi,
-- energy, spatial momentum columns, traj:group(k), CSV round trip),
-- dm.euler_poincare, products with tori (a rigid body with rotors), SE(3),
-- forcing, the diagnostics, and every error message.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"   -- the tape: no compiler runs in this test

local SO3 = dm.lie.SO3()
local function rigid(params, potential)
  return dm.system{space = SO3, params = params, name = potential and "heavy top" or "free body",
    L = function(R, Om, p)
      local T = 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2)
      if potential then return T - p.m * p.g * p.rz * R[3][3] end
      return T
    end}
end

local top = rigid({J1 = 1.3, J2 = 2.1, J3 = 3.4, m = 1, g = 9.81, rz = 0.3}, true)
local free = rigid({J1 = 1, J2 = 2, J3 = 3})
local s0 = {g = SO3.exp{0.5, 0, 0}, mu = {0.5, 0.2, 1.0}}

T.group("the heavy top with lgvi", function()
  T.is(tostring(top), "<System 'heavy top' on SO3: dim 3>", "tostring(sys)")
  local I = dm.integrator(top, {method = "lgvi", h = 0.01})
  T.is(tostring(I), "<Integrator lgvi (order 2) h=0.01 on 'heavy top'>", "tostring(integ)")
  local tr = I:run(s0, {t = 10})
  T.is(#tr, 1001, "1001 samples")
  T.ok(tostring(tr:group(#tr)):find("^<SO3 rotation"), "tr:group(#tr) is an SO3 element")
  T.near(tr:group(1):matrix(), SO3.exp{0.5, 0, 0}:matrix(), 0, "tr:group(1) = g0")
  T.near(tr:group(-1):matrix(), tr:group(#tr):matrix(), 0, "tr:group(-1) = the last")
  local E = tr:energy()
  local dE = 0
  for k = 1, #E do dE = math.max(dE, math.abs(E[k] - E[1])) end
  T.ok(dE < 1e-3 and dE > 0, "energy error bounded: " .. dE)
  local J3 = tr:momentum("3")
  local dJ = 0
  for k = 1, #J3 do dJ = math.max(dJ, math.abs(J3[k] - J3[1])) end
  T.ok(dJ <= 1e-13, "momentum_3 (vertical) conserved to " .. dJ)
  local names = table.concat(tr:names(), ",")
  T.ok(names:find("^t,R11,R12,R13,R21,R22,R23,R31,R32,R33,mu1,mu2,mu3,xi1,xi2,xi3,energy,momentum_1,momentum_2,momentum_3"),
       "columns: " .. names)
  T.near(tr:column("xi1")[1], 0.5 / 1.3, 1e-15, "xi = J^-1 mu")
  T.is(tr:meta("space"), "SO3", "space metadata")
  T.near(I:energy(s0), E[1], 0, "integ:energy(state)")
  T.near(I:momentum(s0), SO3.exp{0.5, 0, 0} * {0.5, 0.2, 1.0}, 1e-15, "integ:momentum = R mu")
  local s1 = I:step(s0)
  T.near(s1.t, 0.01, 0, "step: t + h")
  T.near(s1.mu, dm.vec{tr:column("mu1")[2], tr:column("mu2")[2], tr:column("mu3")[2]}, 0,
         "step = the run's first step")
  T.ok(I:symplecticity_defect(s0) < 1e-8, "symplecticity defect " .. I:symplecticity_defect(s0))
  T.ok(I:reversal(s0, 50) < 1e-12, "reversal " .. I:reversal(s0, 50))
end)

T.group("orders and conservation", function()
  local o2 = dm.integrator(top, {method = "lgvi"}):order_estimate{state = s0, t = 1,
    h = {0.1, 0.05, 0.025}}
  T.near(o2, 2, 0.05, "lgvi order " .. o2)
  local o4 = dm.integrator(top, {method = "lie:gauss", stages = 2}):order_estimate{state = s0,
    t = 1, h = {0.2, 0.1, 0.05}}
  T.near(o4, 4, 0.15, "lie:gauss s=2 order " .. o4)
  local oc = dm.integrator(top, {method = "lie:gauss:cayley", stages = 1}):order_estimate{
    state = s0, t = 1, h = {0.1, 0.05, 0.025}}
  T.near(oc, 2, 0.05, "lie:gauss:cayley s=1 order " .. oc)
  -- any s: order 2s (exp and Cayley charts)
  for _, c in ipairs{{"lie:gauss", 1, {0.1, 0.05, 0.025}, 0.05},
                     {"lie:gauss", 3, {0.2, 0.1, 0.05}, 0.15},
                     {"lie:gauss", 4, {0.4, 0.2, 0.1}, 0.25},
                     {"lie:gauss:cayley", 3, {0.2, 0.1, 0.05}, 0.15}} do
    local o = dm.integrator(top, {method = c[1], stages = c[2]}):order_estimate{state = s0,
      t = 2, h = c[3]}
    T.near(o, 2 * c[2], c[4], ("%s s=%d order %.3f"):format(c[1], c[2], o))
  end
  -- 1e4 steps of the free body, no normalization
  for _, m in ipairs{{"lgvi", 0}, {"lie:gauss", 1}, {"lie:gauss", 2}} do
    local opts = {method = m[1], h = 0.5}
    if m[2] > 0 then opts.stages = m[2] end
    local tr = dm.integrator(free, opts):run({g = SO3.identity(), mu = {1, 0.2, -0.5}},
                                            {steps = 10000, every = 100})
    local dn, dJ = 0, 0
    local n0 = math.sqrt(1 + 0.04 + 0.25)
    local J0 = {tr:column("momentum_1")[1], tr:column("momentum_2")[1], tr:column("momentum_3")[1]}
    for k = 1, #tr do
      local m1, m2, m3 = tr:column("mu1")[k], tr:column("mu2")[k], tr:column("mu3")[k]
      dn = math.max(dn, math.abs(math.sqrt(m1^2 + m2^2 + m3^2) - n0))
      for c = 1, 3 do dJ = math.max(dJ, math.abs(tr:column("momentum_" .. c)[k] - J0[c])) end
    end
    T.ok(dn <= 1e-13 and dJ <= 1e-13, ("%s s=%d: 1e4 steps, ||Pi| - |Pi0|| %.2g, |R Pi - R0 Pi0| %.2g")
         :format(m[1], m[2], dn, dJ))
    local R = tr:group(#tr):matrix()
    T.near(R:t() * R, dm.mat{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 1e-13, m[1] .. ": R^T R = I")
  end
end)

T.group("Euler-Poincare", function()
  local ep = dm.euler_poincare(free)
  T.ok(ep:is_reduced() and not free:is_reduced(), "the reduced system")
  T.is(tostring(ep), "<System 'free body' on SO3 (reduced, Euler-Poincare): dim 3>", "tostring")
  for _, m in ipairs{"lgvi", "lie:gauss"} do
    local st = {g = SO3.exp{0.2, -0.7, 1.1}, mu = {0.5, 1.2, 0.3}}
    local a = dm.integrator(free, {method = m, h = 0.05}):run(st, {steps = 500})
    local b = dm.integrator(ep, {method = m, h = 0.05}):run(st, {steps = 500})
    local d = 0
    for c = 1, 3 do d = math.max(d, math.abs(a:column("mu" .. c)[501] - b:column("mu" .. c)[501])) end
    T.ok(d <= 1e-13, m .. ": reduced mu = unreduced mu (" .. d .. ")")
    T.ok(a:group(501):dist(b:group(501)) <= 1e-13, m .. ": reconstructed g = unreduced g")
  end
  T.error_like(function() dm.euler_poincare(top) end,
    "euler_poincare: the Lagrangian is not invariant under left translations in SO3: d/de L%(exp%(e e_%d%) g, xi%) = ",
    "a potential is refused")
end)

T.group("CSV round trip", function()
  local tr = dm.integrator(top, {method = "lie:gauss", stages = 2, h = 0.05}):run(s0, {t = 2})
  local f = os.getenv("DMECH_TESTTMP") .. "/lie_top.csv"
  T.ok(tr:save(f), "save")
  local t2 = dm.load_trajectory(f)
  T.is(#t2, #tr, "same length")
  T.ok(t2:group(#t2):dist(tr:group(#tr)) == 0, "traj:group after loading: bit for bit")
  T.near(t2:column("mu2"), tr:column("mu2"), 0, "mu columns")
  T.near(t2:energy(), tr:energy(), 0, "energy")
  T.is(t2:meta("space"), "SO3", "space")
end)

T.group("products: a rigid body with rotors", function()
  local P = dm.lie.product(SO3, dm.lie.T(3))
  local craft = dm.system{space = P, params = {J1 = 1, J2 = 2, J3 = 3, k = 0.1},
    L = function(g, xi, p)
      local J = {p.J1, p.J2, p.J3}
      local s = 0
      for i = 1, 3 do s = s + 0.5 * J[i] * xi[i]^2 + 0.5 * p.k * (xi[i] + xi[3 + i])^2 end
      return s
    end}
  T.error_like(function() dm.integrator(craft, {method = "lgvi"}) end,
    "lgvi: the kinetic energy couples factor 1 %(SO3%) of SO3xT3 with another factor",
    "lgvi refuses a coupled kinetic energy")
  local I = dm.integrator(craft, {method = "lie:gauss", stages = 2, h = 0.05})
  local tr = I:run({g = P.identity(), xi = {0.3, 0.8, -0.2, 2, 0, -1}}, {steps = 400})
  local dJ, dr = 0, 0
  for k = 1, #tr do
    for c = 1, 3 do dJ = math.max(dJ, math.abs(tr:column("momentum_" .. c)[k] - tr:column("momentum_" .. c)[1])) end
    for c = 4, 6 do dr = math.max(dr, math.abs(tr:column("mu" .. c)[k] - tr:column("mu" .. c)[1])) end
  end
  T.ok(dJ <= 1e-13, "total angular momentum conserved to " .. dJ)
  T.ok(dr <= 1e-13, "rotor momenta conserved to " .. dr)
  T.ok(tostring(tr:group(#tr)):find("^<SO3xT3 rotation .* | angles"), "product elements")
  T.ok(table.concat(tr:names(), ","):find("R33,theta1,theta2,theta3,mu1"), "product columns")
end)

T.group("SE3", function()
  local SE3 = dm.lie.SE3()
  local body = dm.system{space = SE3, params = {m = 2, k = 1.5},
    L = function(g, xi, p)
      local q = g.p
      return 0.5 * (1.3 * xi[1]^2 + 2.1 * xi[2]^2 + 3.4 * xi[3]^2)
           + 0.5 * p.m * (xi[4]^2 + xi[5]^2 + xi[6]^2) - 0.5 * p.k * (q[1]^2 + q[2]^2 + q[3]^2)
    end}
  for _, m in ipairs{"lgvi", "lie:gauss"} do
    local tr = dm.integrator(body, {method = m, h = 0.05}):run(
      {g = SE3.exp{0.2, 0.1, -0.3, 1, 0.5, 0.2}, mu = {0.3, -0.2, 0.5, 0.4, 1.0, -0.3}}, {steps = 400})
    local dJ = 0
    for k = 1, #tr do
      for c = 1, 3 do dJ = math.max(dJ, math.abs(tr:column("momentum_" .. c)[k] - tr:column("momentum_" .. c)[1])) end
    end
    T.ok(dJ <= 1e-12, m .. ": angular momentum about the origin conserved to " .. dJ)
  end
end)

T.group("the non-symplectic reference", function()
  local I = dm.integrator(top, {method = "gsl:rk4", h = 0.01})
  local tr = I:run(s0, {t = 10})
  local J3 = tr:momentum("3")
  T.ok(math.abs(J3[#J3] - J3[1]) > 1e-11, "gsl:rk4 on quaternions does not conserve the vertical momentum: " .. math.abs(J3[#J3] - J3[1]))
  T.ok(I:symplecticity_defect(s0, 0.3) > 1e-6, "nor the symplectic form")
end)

T.group("forcing", function()
  local damped = dm.system{space = SO3, params = {c = 0.3},
    L = function(R, Om, p) return 0.5 * (Om[1]^2 + 2 * Om[2]^2 + 3 * Om[3]^2) end,
    force = function(R, Om, p) return {-p.c * Om[1], -p.c * Om[2], -p.c * Om[3]} end}
  local tr = dm.integrator(damped, {method = "lgvi", h = 0.01}):run(
    {g = SO3.identity(), mu = {1, 0.2, -0.5}}, {t = 5})
  local E = tr:energy()
  local mono = true
  for k = 2, #E do mono = mono and E[k] < E[k - 1] end
  T.ok(mono and E[#E] < 0.5 * E[1], ("damping: energy decreases %.4f -> %.4f"):format(E[1], E[#E]))
end)

T.group("errors", function()
  local I = dm.integrator(top, {method = "lgvi", h = 0.01})
  local bad = SO3.element({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}})
  local c = bad:coords()
  c[5] = 1.001
  T.error_like(function() I:run({g = SO3.element(c, {tol = 1}), mu = {1, 2, 3}}, {t = 1}) end,
    "run: state%.g: SO3 element: max |R%^T R %- I| = 0%.002 %(> tol 1e%-10%): not a rotation",
    "a state that is not a rotation")
  T.error_like(function() dm.integrator(top, {method = "lgvi", h = 0}) end,
    "dm%.integrator: h must be a finite number > 0, got 0", "h = 0")
  T.error_like(function() dm.integrator(top, {method = "lgvi", h = -0.1}) end,
    "dm%.integrator: h must be a finite number > 0, got %-0%.1", "h < 0")
  T.error_like(function() I:run(s0, {t = 1, h = -1}) end,
    "run: the final time t = 1 cannot be reached from t0 = 0 with h = %-1", "run with h < 0 to t > 0")
  T.error_like(function() I:step(s0, 0) end, "step: h must be a finite number > 0", "step h = 0")
  T.error_like(function() dm.integrator(top, {method = "gauss"}) end,
    "dm%.integrator: method 'gauss' does not apply to system 'heavy top' %(a lie system%); it integrates .- systems %(methods here: lgvi, lie:gauss, lie:gauss:cayley, gsl:<stepper>%)",
    "a vector-space method on a group lists the methods for groups")
  T.error_like(function() dm.integrator(top, {method = "lgvi", stages = 2}) end,
    "dm%.integrator: option 'stages' does not apply to method 'lgvi'", "option for another method")
  T.error_like(function() dm.integrator(top, {method = "lgvi", hh = 2}) end,
    "dm%.integrator: unknown option hh", "unknown option")
  T.error_like(function() I:run({g = SO3.identity()}, {t = 1}) end,
    "run: the state needs mu %(body momentum%) or xi %(body velocity%)", "no momentum")
  T.error_like(function() I:run({g = dm.lie.SE3().identity(), mu = {1, 2, 3}}, {t = 1}) end,
    "run: state%.g must be an element of SO3, got an element of SE3", "wrong group")
  T.error_like(function() I:run({mu = {1, 2, 3}}, {t = 1}) end,
    "run: state%.g must be an element of SO3 %(G%.exp{%.%.%.}, G%.element%(%.%.%.%)%), got nil", "no g")
  T.error_like(function() I:run(s0, {}) end,
    "run: give exactly one of steps = %(a number of steps%) or t = %(the final time%)", "run options")
  T.error_like(function()
    dm.system{space = SO3, L = function(R, Om, p) return Om[1]^2 end,
              force = function(R, Om, p) return {Om[1]} end}
  end, "dm%.system: force of system 'system' must return a list of 3 expressions", "force size")
  T.error_like(function() dm.system{space = 3, L = function() return 0 end} end,
    "dm%.system: field 'space' must be a Lie group", "space not a group")
  T.error_like(function() dm.system{space = SO3, L = function() return 0 end, coords = {"x"}} end,
    "dm%.system: unknown field coords for a system on a Lie group", "unknown field")
  local kep = dm.systems.kepler()
  local kt = dm.integrator(kep, {method = "midpoint", h = 0.1}):run({q = {1, 0}, p = {0, 1}}, {steps = 2})
  T.error_like(function() kt:group(1) end,
    "traj:group: the trajectory is not of a system on a Lie group %(no 'space' in its metadata%)",
    "traj:group on another trajectory")
end)

T.group("parameters: the same rules as systems in coordinates", function()
  local SO3 = dm.lie.SO3()
  local function body(P)
    return dm.system{space = SO3, params = P,
      L = function(R, W, p) return 0.5 * (p.a * W[1]^2 + p.b * W[2]^2 + 3.4 * W[3]^2) - p.b * R[3][3] end}
  end
  for _, c in ipairs{{{a = 0/0, b = 1}, "parameter 'a' must be a finite number, got nan"},
                     {{a = 1, b = -math.huge}, "parameter 'b' must be a finite number, got %-inf"},
                     {{["a b"] = 1}, "parameter name 'a b' must be letters, digits and _"},
                     {{{"a", 1}, {"a", 2}}, "parameter 'a' is listed twice"}} do
    T.error_like(function() body(c[1]) end, "dm%.system: " .. c[2], "dm.system params: " .. c[2])
    T.error_like(function()
      dm.system{space = dm.lie.sphere(2), params = c[1], L = function(x, v, p) return v[1]^2 end}
    end, "dm%.system: " .. c[2], "sphere params: " .. c[2])
  end
  local s = body{a = 2.385, b = 1.5}
  T.error_like(function() s:set{a = 0/0} end, "set: parameter 'a' must be a finite number, got nan", "set NaN")
  T.error_like(function() s:set{a = 3, c = 1} end, "set: no parameter 'c' in system 'system'", "set unknown")
  T.error_like(function() s:set{b = "x"} end, "set: parameter 'b' needs a number, got string", "set string")
  T.error_like(function() s:param("a", 1/0) end, "sys:param: parameter 'a' must be a finite number, got inf",
    "param inf")
  T.is(s:param("a"), 2.385, "a failed set changes nothing")
  s:set{a = 3.125, b = 0.75}
  local st = {g = SO3.exp{0.5, 0.1, 0}, mu = {0.5, 0.2, 1.0}}
  local t1 = dm.integrator(s, {method = "lgvi", h = 0.01}):run(st, {steps = 200})
  local t2 = dm.integrator(body{a = 3.125, b = 0.75}, {method = "lgvi", h = 0.01}):run(st, {steps = 200})
  T.is(t1:column("mu1")[#t1], t2:column("mu1")[#t2], "set{} = a system made with those values (mu1)")
  T.is(t1:column("R33")[#t1], t2:column("R33")[#t2], "set{} = a system made with those values (R33)")
end)

T.done()
