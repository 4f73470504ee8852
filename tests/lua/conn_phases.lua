-- conn_phases.lua -- geometric phases through the Lua surface: the discrete
-- mechanical connection of the cat and the Heisenberg bundle against the
-- midpoint rule and the shoelace area, free particles (Kabsch), the phase
-- of a sampled run, red:connection and red:phase with connection objects,
-- the Foucault pendulum, Montgomery's rigid-body phase on a Lie group
-- variational integrator run (its geometric part from the Levi-Civita
-- holonomy of the momentum curve), the Levi-Civita connection of meshes.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"
local pi = math.pi
local SO2, SO3 = dm.lie.SO2(), dm.lie.SO3()

T.group("the discrete mechanical connection", function()
  local C = dm.bundles.cat()
  local M = dm.discrete_connection{from = dm.mechanical_connection{bundle = C}, rule = "midpoint"}
  local D = dm.discrete_mechanical_connection{bundle = C, h = 0.1, guess = M}
  local worst = 0
  for _, p in ipairs{{{0.3, -0.2}, {0.5, 0.1}}, {{1.2, 0.4}, {1.0, 0.9}}, {{-0.7, 2.0}, {-0.4, 1.6}}} do
    worst = math.max(worst, math.abs(D:at(p[1], p[2]):coords()[1] - M:at(p[1], p[2]):coords()[1]))
  end
  T.ok(worst < 1e-13, "cat: mechanical = midpoint for the quadratic abelian l (" .. worst .. ")")
  local s, it = D:newton_stats()
  T.ok(s == 3 and it <= 2 * s, ("cat: %d solves, %d Newton iterations"):format(s, it))
  local H = dm.bundles.heisenberg()
  local Dh = dm.discrete_mechanical_connection{bundle = H}
  local hex = {}
  for k = 0, 6 do hex[#hex + 1] = {math.cos(2 * pi * k / 6), math.sin(2 * pi * k / 6)} end
  hex[7] = hex[1]
  T.near(Dh:holonomy(hex, H:point{x = hex[1], g = 0}).angle, -2.5980762113533156, 1e-14,
    "Heisenberg: hexagon -> minus its area")
  local q0, q1 = H:point{x = {0.3, 0.5}, g = 1}, H:point{x = {0.9, -0.1}, g = 0.2}
  local _, h1 = Dh:hor(q0, q1)
  T.near(Dh:momentum(q0, h1)[1], 0, 1e-14, "J_d = 0 on the horizontal part")
  local Dmu = dm.discrete_mechanical_connection{bundle = H, mu = 0.5}
  T.near(Dmu:momentum(q0, Dmu:hlift(q0, {0.9, -0.1}))[1], 0.5, 1e-13, "momentum level mu = 0.5")
  T.error_like(function() dm.discrete_mechanical_connection{bundle = dm.bundles.rotor{}, mu = {0, 1, 0}} end,
    "a nonzero momentum level needs an abelian group")
  -- free particles under SO(3): the Kabsch rotation
  local P = dm.bundle{name = "particles", n = 3}
  local Dp = dm.discrete_mechanical_connection{bundle = P, params = {h = 0.1},
    Ld = function(x, y, p)
      local s = 0
      for i = 1, 9 do s = s + (y[i] - x[i])^2 end
      return s / (2 * p.h)
    end}
  local X = {1, 0.2, -0.3, 0.1, 1.1, 0.4, -0.6, 0.3, 0.9}
  local R = SO3.exp{0.3, -0.5, 0.2}
  local Y = {}
  for i = 0, 2 do
    local y = R * {X[3 * i + 1], X[3 * i + 2], X[3 * i + 3]}
    for a = 1, 3 do Y[3 * i + a] = y[a] end
  end
  T.near(Dp(P:point{q = X}, P:point{q = Y}):matrix(), R:matrix(), 1e-13,
    "particles: A_d(X, R X) = R (splitting; the Kabsch rotation of R X onto X is R^-1)")
  T.error_like(function() Dp(P:point{q = {1, 0, 0, 2, 0, 0, 3, 0, 0}}, P:point{q = Y}) end,
    "first two particles are collinear")
end)

T.group("phases of runs", function()
  local sys = dm.system{name = "platform sys", coords = {"u", "v", "th"}, params = {I = 1, m = 1},
    L = function(q, v, p)
      local a, b = v.u - v.th * q.v, v.v + v.th * q.u
      return 0.5 * p.I * v.th^2 + 0.5 * p.m * (a^2 + b^2)
    end}
  local red = dm.routh(sys, {cyclic = {"th"}, mu = 0})
  local A = red:connection()
  T.like(tostring(A), "^<Connection on platform sys.*A%(x%) = %[%-m%*v/", "red:connection() prints its form")
  local N = 64
  local t, u, v = {}, {}, {}
  for k = 0, N do
    local s = 2 * pi * k / N
    t[#t + 1], u[#u + 1], v[#v + 1] = s, 1 + 0.5 * math.cos(s), 0.5 * math.sin(s)
  end
  u[#u], v[#v] = u[1], v[1]
  local loop = dm.trajectory{t = t, q = {u = u, v = v}}
  local dyn, geo, gap = red:phase(loop)
  local dyn2, hol, gap2 = red:phase(loop, dm.discrete_connection{from = A, rule = "midpoint"})
  T.near(hol.angle, geo, 1e-15, "red:phase with the midpoint connection = the abelian split")
  T.is(dyn2, dyn, "the dynamic part is the reduction's")
  local hc = red:phase(loop, A)
  local _, hc = red:phase(loop, A)
  T.near(hc.angle, geo, 1e-4, "red:phase with the continuous connection (Magnus on the samples)")
  -- a non-abelian phase: the rotor craft's shape run
  local R = dm.bundles.rotor{}
  local Ar = dm.mechanical_connection{bundle = R}
  local hc = Ar:holonomy(function(s) return {dm.cos(2 * pi * s) - 1, dm.sin(2 * pi * s), 0} end,
    R:point{x = {0, 0, 0}, g = SO3.identity()}, {tol = 1e-12})
  local Md = dm.discrete_connection{from = Ar, rule = "midpoint"}
  local err, g = {}
  for i, n in ipairs{40, 80} do
    local ts, p1, p2, p3 = {}, {}, {}, {}
    for k = 0, n do
      local s = k / n
      ts[#ts + 1], p1[#p1 + 1], p2[#p2 + 1], p3[#p3 + 1] = s, math.cos(2 * pi * s) - 1, math.sin(2 * pi * s), 0
    end
    p1[#p1], p2[#p2] = p1[1], p2[1]
    local h
    h, g = Md:phase(dm.trajectory{t = ts, q = {a = p1, b = p2, c = p3}})
    err[i] = SO3.dist(h.body, hc.body)
  end
  T.ok(err[1] < 4e-4 and err[1] / err[2] > 3.9 and err[1] / err[2] < 4.1,
    ("rotor: the phase of a sampled circle (midpoint) -> the continuous holonomy, errors %.2e, %.2e (O(h^2))"):format(err[1], err[2]))
  T.near(hc.body:log()[3], 0.02 * pi, 2e-3, "rotor: about e3 by ~ c1 c2 (area)")
  T.is(g, 0, "closed loop: gap 0")
end)

T.group("the sphere and meshes", function()
  local S = dm.sphere_frames()
  local LC = dm.discrete_connection{bundle = S, rule = "levi-civita"}
  local lat = pi / 6
  local pts = {}
  for k = 0, 64 do
    local t = 2 * pi * k / 64
    pts[#pts + 1] = {math.cos(lat) * math.cos(t), math.cos(lat) * math.sin(t), math.sin(lat)}
  end
  pts[#pts] = pts[1]
  local p0 = dm.vec(pts[1])
  local e1 = dm.vec{0, 1, 0}
  local R0 = SO3.element(dm.mat{{e1[1], p0[2] * e1[3] - p0[3] * e1[2], p0[1]},
                                {e1[2], p0[3] * e1[1] - p0[1] * e1[3], p0[2]},
                                {e1[3], p0[1] * e1[2] - p0[2] * e1[1], p0[3]}})
  T.near(LC:holonomy(pts, S:point{R = R0}).angle % (2 * pi), 3.139699, 1e-6,
    "Foucault, latitude 30, 64 edges: 3.139699 (-> pi)")
  local O = dm.discrete_connection{mesh = dm.mesh.new{
    vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
    simplices = {{1, 3, 5}, {1, 6, 3}, {1, 5, 4}, {1, 4, 6}, {2, 5, 3}, {2, 3, 6}, {2, 4, 5}, {2, 6, 4}}}}
  local hs = O:holonomies()
  local sum = 0
  for v = 1, 6 do sum = sum + hs[v] end
  T.near(hs, dm.vec{2 * pi / 3, 2 * pi / 3, 2 * pi / 3, 2 * pi / 3, 2 * pi / 3, 2 * pi / 3}, 1e-14,
    "octahedron: every vertex 2 pi/3")
  T.near(sum, 4 * pi, 1e-13, "octahedron: Gauss-Bonnet 4 pi")
  T.near(O:defects(), hs, 1e-14, "holonomy = angle defect")
  T.like(tostring(O), "^<Levi%-Civita connection of a triangle mesh: 8 triangles, 6 vertices>", "tostring")
  local I = dm.discrete_connection{mesh = dm.mesh.sphere{level = 2}}
  local s2 = 0
  for _, a in ipairs(I:holonomies():totable()) do s2 = s2 + a end
  T.near(s2, 4 * pi, 1e-12, "icosphere level 2: sum 4 pi")
  local d = O:transition(1, 3)
  T.ok(math.abs(d) > 0 and math.abs(d) < pi, "a transition across edge 1-5: " .. d)
  T.near(O:transport({1, 3, 7}, 0.25), 0.25 + d + O:transition(3, 7), 1e-15, "transport = sum of transitions")
  T.error_like(function() O:transition(1, 8) end, "share no edge")
  T.error_like(function() O:holonomy(7) end, "vertex 7 does not exist")
  T.error_like(function() dm.discrete_connection{mesh = dm.mesh.box{n = 1}} end, "needs a triangle mesh")
end)

T.group("Montgomery's rigid-body phase", function()
  local sys = dm.system{space = SO3, params = {J1 = 1, J2 = 1, J3 = 2}, name = "symmetric top",
    L = function(R, Om, p) return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) end}
  local beta = 0.6
  local Tp = 4 * pi / math.cos(beta)
  local a = {math.sin(beta), 0, math.cos(beta)}
  local H = 0.5 * (a[1]^2 + a[3]^2 / 2)
  local LC = dm.discrete_connection{bundle = dm.sphere_frames(), rule = "levi-civita"}
  local errs = {}
  for i, N in ipairs{100, 200} do
    local tr = dm.integrator(sys, {method = "lgvi", h = Tp / N}):run({g = SO3.identity(), mu = a}, {steps = N})
    -- the rotation about the spatial momentum after one period (twist of R_N)
    local m = tr:group(#tr):matrix()
    local w = math.sqrt(1 + m[1][1] + m[2][2] + m[3][3]) / 2
    local v = {(m[3][2] - m[2][3]) / (4 * w), (m[1][3] - m[3][1]) / (4 * w), (m[2][1] - m[1][2]) / (4 * w)}
    local th = (2 * math.atan(v[1] * a[1] + v[2] * a[2] + v[3] * a[3], w)) % (2 * pi)
    errs[i] = th - 2.6593998
    local dJ = 0
    for c = 1, 3 do
      local col = tr:column("momentum_" .. c)
      for k = 1, #col do dJ = math.max(dJ, math.abs(col[k] - col[1])) end
    end
    T.ok(dJ < 3e-14, ("N = %d: spatial momentum R Pi constant to %.1e"):format(N, dJ))
    if N == 200 then
      -- Lambda: the Levi-Civita holonomy of the body momentum curve (closed)
      local pts = {}
      for k = 1, #tr do
        local p = dm.vec{tr:column("mu1")[k], tr:column("mu2")[k], tr:column("mu3")[k]}
        pts[#pts + 1] = p / p:norm()
      end
      pts[#pts + 1] = pts[1]
      local e2 = {0, 1, 0}
      local R0 = SO3.element(dm.mat{{a[3], 0, a[1]}, {0, 1, 0}, {-a[1], 0, a[3]}})
      local Lam = LC:holonomy(pts, dm.sphere_frames():point{R = R0}).angle
      T.near(Lam, 2 * pi * (1 - math.cos(beta)), 2e-4, "Lambda = solid angle 2 pi (1 - cos beta) from the holonomy")
      T.near((-Lam + 2 * H * Tp) % (2 * pi), th, 5e-3, "Montgomery: -Lambda + 2 H T = the measured phase")
    end
  end
  T.near(errs[1], 1.58e-2, 2e-4, ("N = 100: phase error %.3e"):format(errs[1]))
  T.near(errs[2], 3.95e-3, 5e-5, ("N = 200: phase error %.3e (second order)"):format(errs[2]))
end)

T.done()
