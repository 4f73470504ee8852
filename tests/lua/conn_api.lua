-- conn_api.lua -- bundles and connections at the Lua surface: dm.bundle
-- (trivial, catalog, sphere frames, particles, from a dm.system), points,
-- dm.connection / dm.mechanical_connection (printing, curvature, transport,
-- holonomy along polygons and traced curves), dm.discrete_connection with
-- every rule, hor / ver / lift / compose / reduce / split / limit, the
-- order test, the trampoline of a user A(x0, x1), and every error message.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"   -- the tape: no compiler runs in this test
local pi = math.pi
local SO2, SO3 = dm.lie.SO2(), dm.lie.SO3()

T.group("the two printed values of the example", function()
  local B  = dm.bundle{shape_dim = 2, group = dm.lie.SO2()}
  local A  = dm.connection{bundle = B, A = function(x) return {{-x[2]/2, x[1]/2}} end}
  local Ad = dm.discrete_connection{from = A, rule = "midpoint"}
  local h = Ad:holonomy({{0,0}, {1,0}, {1,1}, {0,1}, {0,0}}, B:point{x = {0, 0}, g = 0})
  T.is(h.angle, -1, "unit square, midpoint rule: holonomy angle -1 (minus the area)")
  local S  = dm.sphere_frames()
  local LC = dm.discrete_connection{bundle = S, rule = "levi-civita"}
  local q0 = S:point{R = dm.lie.SO3().identity()}
  local s = LC:holonomy({{0,0,1}, {1,0,0}, {0,1,0}, {0,0,1}}, q0)
  T.near(s.angle, pi / 2, 1e-15, "octant triangle on the sphere: pi/2")
  T.like(tostring(s), "^holonomy: angle 1%.570796327; body <SO2 angle 1%.5708>$", "a holonomy prints")
end)

T.group("bundles and points", function()
  local B = dm.bundle{shape_dim = 2, group = SO3, name = "test"}
  T.is(tostring(B), "<Bundle test (trivial): shape dim 2, group SO3>", "tostring(B)")
  T.is(B.shape_dim, 2, "B.shape_dim")
  T.ok(B.group == SO3, "B.group")
  local g = SO3.exp{0.3, -0.2, 1.1}
  local q = B:point{x = {0.5, -1}, g = g}
  T.near(q.x, dm.vec{0.5, -1}, 0, "q.x")
  T.near(q.g:matrix(), g:matrix(), 0, "q.g")
  T.like(tostring(q), "^<point of test: x = %(0%.5, %-1%), g = rotation 1%.1", "tostring(q)")
  local h = SO3.exp{1, 0, 0}
  local hq = B:act(h, q)
  T.near(B:fiber_diff(q, hq):matrix(), h:matrix(), 1e-15, "fiber_diff(q, h q) = h")
  local x, g2 = B:trivialize(hq)
  T.near(x, q.x, 0, "trivialize: x")
  T.near(g2:matrix(), (h * g):matrix(), 1e-15, "trivialize: g")
  T.near(B:section{1, 2}.g:matrix(), SO3.identity():matrix(), 0, "section: (x, e)")
  T.near(B:proj(q), q.x, 0, "proj")
  T.near(q:coords()[3], g:matrix()[1][1], 0, "coords: shape then group")
  T.ok(q:bundle() == B, "q:bundle()")
  local P = dm.bundle{name = "particles", n = 3}
  local pq = P:point{q = {1, 0, 0, 0.3, 2, 0, 0.1, 0.2, 0.7}}
  T.near(P:proj(pq), dm.vec{1, 0, 0, 0.3, 2, 0, 0.1, 0.2, 0.7}, 1e-15, "particles in canonical position")
  T.like(tostring(dm.sphere_frames()), "sphere frames SO3 %-> S2", "sphere frames")
end)

T.group("the catalog", function()
  local P = dm.bundle{name = "platform", I = 2.385, m = 0.7}
  local A = dm.mechanical_connection{bundle = P}
  T.is(tostring(A), "<Connection on platform: A(x) = [-m*x2/(I + m*x1^2 + m*x2^2), m*x1/(I + m*x1^2 + m*x2^2)]>",
       "the mechanical connection prints its local form")
  local D = 2.385 + 0.7 * (0.8^2 + 0.3^2)
  T.near(A:at{0.8, 0.3}, dm.mat{{-0.7 * 0.3 / D, 0.7 * 0.8 / D}}, 1e-15, "A = m(-v, u)/(I + m rho^2)")
  T.near(A:curvature({0.8, 0.3}, 1, 2)[1], 2 * 0.7 * 2.385 / D^2, 1e-15, "curvature 2 m I/(I + m rho^2)^2")
  local C = dm.mechanical_connection{bundle = dm.bundles.cat()}
  T.near(C:at{0, 0}, dm.mat{{7/27, 7/27}}, 1e-15, "cat: A(0, 0) = (7/27, 7/27)")
  local R = dm.mechanical_connection{bundle = dm.bundle{name = "rotor"}}
  T.near(R:curvature({0.3, 1, 2}, 1, 2), dm.vec{0, 0, -0.02}, 1e-16, "rotor: B(e1, e2) = -(u1 x u2)")
  T.is(tostring(R), "<Connection on rotor craft: A(x) = [k1/I1, 0, 0; 0, k2/I2, 0; 0, 0, k3/I3]>",
       "rotor: A = diag(k/I)")
  local O = dm.connection{bundle = dm.bundles.orbiter()}
  T.near(O:at{0, 2}, dm.mat{{0.5, 0}}, 1e-16, "orbiter: the bundle's own form")
  T.error_like(function() dm.bundles.platform{J = 1} end, "unknown parameter J %(parameters: I, m%)")
  T.error_like(function() dm.bundle{name = "tricycle"} end, "no built%-in bundle 'tricycle'")
  T.ok(dm.bundles.heisenberg().group == dm.lie.Rn(1), "heisenberg: G = R")
end)

T.group("a bundle from a system", function()
  local sys = dm.system{name = "platform sys", coords = {"u", "v", "th"}, params = {I = 1, m = 1},
    L = function(q, v, p)
      local a, b = v.u - v.th * q.v, v.v + v.th * q.u
      return 0.5 * p.I * v.th^2 + 0.5 * p.m * (a^2 + b^2)
    end}
  local B = dm.bundle{system = sys, acts_on = {"th"}}
  T.is(B.shape_dim, 2, "shape = (u, v)")
  local A = dm.mechanical_connection{bundle = B}
  T.near(A:at{1, 0.5}, dm.mat{{-0.5 / 2.25, 1 / 2.25}}, 1e-15, "mechanical connection from the system's L")
  A:set_params{I = 3, m = 1}
  T.near(A:at{1, 0.5}, dm.mat{{-0.5 / 4.25, 1 / 4.25}}, 1e-15, "set_params")
  T.error_like(function() dm.bundle{system = sys, acts_on = {"u"}} end,
    "the Lagrangian of 'platform sys' depends on u")
  T.error_like(function() dm.bundle{system = sys, acts_on = {"phi"}} end,
    "acts_on%[1%] is not a coordinate of system 'platform sys'")
end)

T.group("continuous transport and holonomy", function()
  local P = dm.bundles.platform{}
  local A = dm.mechanical_connection{bundle = P}
  local sector = {
    function(s) return {1 + s, 0} end,
    function(s) return {2 * dm.cos(pi / 2 * s), 2 * dm.sin(pi / 2 * s)} end,
    function(s) return {0, 2 - s} end,
    function(s) return {dm.cos(pi / 2 * (1 - s)), dm.sin(pi / 2 * (1 - s))} end}
  local q0 = P:point{x = {1, 0}, g = 0.4}
  local h = A:holonomy(sector, q0, {substeps = 64})
  T.near(h.angle, -0.15 * pi, 1e-12, "annular sector: -0.15 pi (traced curves, Magnus 4)")
  T.near(A:holonomy(sector, q0, {tol = 1e-13}).angle, -0.15 * pi, 1e-12, "adaptive rk8pd")
  local H = A:transport({{1, 0}, {2, 0}})
  T.near(H:coords()[1], -(4 / 5 - 1 / 2) * 0, 1e-16, "a radial segment has no phase")
  local R = dm.mechanical_connection{bundle = dm.bundles.rotor{}}
  local hr = R:holonomy({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}},
    dm.bundles.rotor{}:point{x = {0, 0, 0}, g = SO3.identity()})
  T.near(hr.body:log(), dm.vec{-0.00199005466931, 0.00099253561449, 0.0198341672719}, 1e-13,
    "rotor: unit square, log P")
  T.near(hr.axis, hr.body:log() / hr.angle, 1e-15, "SO3 holonomy: axis and angle")
  T.error_like(function() A:holonomy({{1, 0}, {0, 1}}, P:point{x = {1, 0}, g = 0}) end,
    "holonomy: the loop is not closed")
  T.error_like(function() A:holonomy(sector, q0, {tol = -1}) end, "tol must be 0")
  T.error_like(function() A:holonomy(sector, q0, {step = 1}) end, "unknown option 'step'")
  T.error_like(function() A:holonomy(function(s) return {s} end, q0) end,
    "the curve must return 2 shape coordinates, got 1")
  T.error_like(function() A:holonomy(function(s) if s > 0 then return {0, 0} end end, q0) end,
    "branch on a symbolic value")
end)

T.group("discrete connections: rules and maps", function()
  local B = dm.bundle{shape_dim = 2, group = SO3}
  local A = dm.connection{bundle = B, A = function(x)
    return {{0.3 + 0.2 * dm.sin(x[2]), 0.1 * x[1]}, {0.2 * dm.cos(x[1]), -0.4 + 0.1 * x[2]^2},
            {0.15 * x[1] * x[2], 0.25 + 0.05 * x[1]}} end}
  local q0 = B:point{x = {0.3, -0.2}, g = SO3.exp{0.4, 0.1, -0.9}}
  local q1 = B:point{x = {0.5, 0.1}, g = SO3.exp{-0.2, 0.8, 0.3}}
  for _, r in ipairs{"euler", "midpoint", "cayley", "transport", "exact"} do
    local Ad = dm.discrete_connection{from = A, rule = r}
    T.is(Ad.rule, r, "rule " .. r)
    local g = SO3.exp{0.2, -0.5, 0.7}
    T.near(Ad(q0, B:act(g, q0)):matrix(), g:matrix(), 1e-14, r .. ": A_d(q, g q) = g")
  end
  local Ad = dm.discrete_connection{from = A, rule = "midpoint"}
  local _, h1 = Ad:hor(q0, q1)
  local _, v1 = Ad:ver(q0, q1)
  T.near(Ad(q0, h1):matrix(), SO3.identity():matrix(), 1e-15, "A_d(hor) = e")
  T.near(B:fiber_diff(q0, v1):matrix(), Ad(q0, q1):matrix(), 1e-15, "ver = i_q0(A_d)")
  local x0, x1, z = Ad:reduce(q0, q1)
  T.near(Ad:unreduce(x0, x1, z, q0):coords(), q1:coords(), 1e-15, "unreduce(reduce) = q1")
  local s0, s1, g = Ad:split(q0, q1)
  T.near(g:matrix(), Ad(q0, q1):matrix(), 0, "split: the relative element")
  T.near(s1, q1.x, 0, "split: shapes")
  local qs = Ad:lift({{0.3, -0.2}, {0.5, 0.1}, {0.2, 0.6}}, q0)
  T.is(#qs, 3, "lift: one point per shape point")
  T.near(Ad(qs[2], qs[3]):matrix(), SO3.identity():matrix(), 1e-15, "lift: horizontal pairs")
  T.near(Ad:hlift(q0, {0.5, 0.1}):coords(), qs[2]:coords(), 0, "hlift = lift's first edge")
  local c = Ad:compose({q0, q1}, {B:act(SO3.exp{1, 0, 0}, q1), q0})
  T.near(c[1]:coords(), q0:coords(), 0, "compose keeps the first point")
  local lim = Ad:limit(q0, {0.7, -0.3}, {0.2, 0.9, -0.5}, 1e-3)
  T.near(lim, A:form(q0, {0.7, -0.3}, {0.2, 0.9, -0.5}), 1e-6, "continuous limit = A(v)")
  local d, slope = dm.order_test(dm.discrete_connection{from = A, rule = "euler"},
    {q = q0, v = {0.6, 0.8}, h = {0.1, 0.05, 0.025}})
  T.near(slope, 2, 0.05, "order test: euler, slope 2 (first order)")
  d, slope = dm.order_test(Ad, {q = q0, v = {0.6, 0.8}, h = {0.1, 0.05, 0.025}})
  T.near(slope, 3, 0.05, "order test: midpoint, slope 3 (second order)")
  T.like(tostring(Ad), "^<Discrete connection 'midpoint' on R2 x SO3, from <Connection", "tostring(Ad)")
  T.error_like(function() Ad:compose({q0, q1}, {q0, q1}) end, "compose: the pairs do not meet")
  T.error_like(function() dm.discrete_connection{from = A, rule = "simpson"} end,
    "unknown rule 'simpson'")
  T.error_like(function() dm.discrete_connection{bundle = B, rule = "midpoint"} end,
    "rule 'midpoint' is built from a continuous connection")
  T.error_like(function() dm.discrete_connection{from = A, rule = "levi-civita"} end,
    "rule 'levi%-civita' is defined on the sphere%-frame bundle")
  T.error_like(function() Ad:holonomy({{0, 0}, {1, 0}, {0, 0}}, q0) end, "q0 is not over")
end)

T.group("a user local representation", function()
  local B = dm.bundle{shape_dim = 2, group = SO2}
  local Ak = dm.discrete_connection{bundle = B, A = function(x0, x1)
    return 0.5 * (x0[1] * x1[2] - x1[1] * x0[2]) end}
  T.is(Ak.rule, "local", "rule local")
  local h = Ak:holonomy({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}}, B:point{x = {0, 0}, g = 0})
  T.near(h.angle, -1, 1e-15, "A(x0, x1) = exp((x0 x x1)/2): minus the area")
  local bad = dm.discrete_connection{bundle = B, A = function(x0, x1) error("boom") end}
  T.error_like(function() bad:holonomy({{0, 0}, {1, 0}, {0, 0}}, B:point{x = {0, 0}, g = 0}) end,
    "holonomy: edge 1 %-> 2: .*boom")
  local wrong = dm.discrete_connection{bundle = B, A = function() return SO3.identity() end}
  T.error_like(function() wrong:at({0, 0}, {1, 0}) end,
    "the value of A%(x0, x1%) must be an element of SO2, got an element of SO3")
  local tr = dm.discrete_connection{bundle = B, rule = "trivial"}
  T.near(tr(B:point{x = {0, 0}, g = 0.1}, B:point{x = {1, 0}, g = 0.4}):coords()[1], 0.3, 1e-16,
    "trivial connection: A_d = g1 g0^-1")
end)

T.group("native code", function()
  dm.config.native = "always"
  local ok, A = pcall(dm.mechanical_connection, {bundle = dm.bundles.cat()})
  dm.config.native = "never"
  if not ok and tostring(A):find("compiler") then
    T.skip("no C compiler: " .. tostring(A), 1)
  else
    T.ok(ok, "native code compiled: " .. tostring(ok and "yes" or A))
    local Ad = dm.discrete_connection{from = A, rule = "midpoint"}
    local At = dm.discrete_connection{from = dm.mechanical_connection{bundle = dm.bundles.cat()},
      rule = "midpoint"}
    local loop = {}
    for k = 0, 32 do loop[#loop + 1] = {1 + 0.5 * math.cos(2 * pi * k / 32), 0.5 + 0.5 * math.sin(2 * pi * k / 32)} end
    loop[#loop] = loop[1]
    local q0 = dm.bundles.cat():point{x = loop[1], g = 0}
    T.near(Ad:holonomy(loop, q0).angle, At:holonomy(loop, q0).angle, 1e-15,
      "native and tape give the same holonomy")
  end
end)

T.group("errors", function()
  local B = dm.bundle{shape_dim = 2, group = SO2}
  T.error_like(function() dm.bundle{shape_dim = 2} end, "group must be a Lie group")
  T.error_like(function() dm.bundle{shape_dim = -1, group = SO2} end, "shape_dim must be 0..64")
  T.error_like(function() dm.bundle{shape_dim = 1, group = SO2, colour = 1} end,
    "dm.bundle: unknown option 'colour'")
  T.error_like(function() B:point{x = {1}, g = 0} end, "point.x must have 2 entries, got 1")
  T.error_like(function() B:point{x = {1, 2}, g = SO3.identity()} end,
    "point.g must be an element of SO2, got an element of SO3")
  T.error_like(function() dm.connection{bundle = B, A = function(x) return {x[1]} end} end,
    "must return a 1x2 matrix")
  T.error_like(function() dm.connection{bundle = dm.sphere_frames(), A = function() end} end,
    "needs a trivial bundle")
  T.error_like(function() dm.connection{bundle = B} end, "A must be a function A%(x, p%)")
  T.error_like(function() dm.mechanical_connection{bundle = B} end, "give I and C, or L")
  T.error_like(function() dm.mechanical_connection{bundle = B,
    L = function(x, xd, xi) return xi[1]^4 end} end, "not quadratic in the velocities")
  local S = dm.sphere_frames()
  T.error_like(function() S:point{R = 2} end, "a frame {R = <SO3 element>} expected")
  T.error_like(function() S:point{R = dm.mat{{1, 0, 0}, {0, 1, 0}, {0, 0, 2}}} end, "not a rotation")
  local LC = dm.discrete_connection{bundle = S, rule = "levi-civita"}
  T.error_like(function() LC:holonomy({{0, 0, 1}, {0, 0, -1}, {0, 0, 1}}, S:point{R = SO3.identity()}) end,
    "p1 = %-p0 %(antipodal points")
  T.error_like(function() LC:hlift(S:point{R = SO3.identity()}, {0, 0, 2}) end, "unit sphere")
  T.error_like(function() LC:reduce(S:point{R = SO3.identity()}, S:point{R = SO3.identity()}) end,
    "no global trivialization")
end)

T.done()
