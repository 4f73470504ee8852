-- lie_groups.lua -- dm.lie at the Lua surface: group objects and the
-- functions bound to them (G.exp{...} and G:exp{...}), elements (g * h,
-- g * x, g:inv(), g:log(), g:matrix(), g[i], g.R, g.p, g.theta), products,
-- symbolic elements that trace into the expression engine, compact
-- printing, help texts, spheres, and every error message.
local T = require "dmech.test"
local dm = require "dmech"
local pi = math.pi

local SO3, SE3, SE2, SO2 = dm.lie.SO3(), dm.lie.SE3(), dm.lie.SE2(), dm.lie.SO2()

T.group("groups", function()
  T.is(tostring(SO3), "<Lie group SO3, dim 3>", "tostring(G)")
  T.is(SO3.name .. " " .. SO3.dim .. " " .. SO3.nq, "SO3 3 9", "G.name, G.dim, G.nq")
  local P = dm.lie.product(SE3, dm.lie.T(3))
  T.is(P.name, "SE3xT3", "product name")
  T.is(P.dim, 9, "product dim")
  T.is(#P.factors, 2, "product factors")
  T.ok(dm.lie.group("SE3xT3") == P, "dm.lie.group parses the name back (G == H)")
  T.ok(dm.lie.Rn(2) ~= dm.lie.Rn(3), "R2 ~= R3")
  T.ok(SO3.exp == SO3.exp, "bound functions are cached")
end)

T.group("SO3", function()
  local R = SO3.exp{0, 0, pi / 2}
  T.near(R:matrix(), dm.mat{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}, 1e-15, "exp(0,0,pi/2) = Rz(90)")
  T.near(R:log(), dm.vec{0, 0, pi / 2}, 1e-15, "R:log()")
  T.near(SO3:exp{0, 0, pi / 2}:matrix(), R:matrix(), 0, "G:exp (colon call) = G.exp")
  T.is(tostring(R), "<SO3 rotation 1.5708 about (0, 0, 1) [0 -1 0; 1 0 0; 0 0 1]>",
       "compact printing: axis-angle and matrix")
  T.near(SO3.Ad(R), R:matrix(), 0, "Ad_R = R")
  T.near(SO3.hat{1, 2, 3}, dm.mat{{0, -3, 2}, {3, 0, -1}, {-2, 1, 0}}, 0, "hat")
  T.near(SO3.vee(SO3.hat{2.385, -1, 0.5}), dm.vec{2.385, -1, 0.5}, 0, "vee(hat)")
  T.near(SO3.cay{0, 0, 2}:matrix(), R:matrix(), 1e-16, "cay(0,0,2) = Rz(90)")
  T.near(SO3.icay(SO3.cay{0.3, -0.2, 2.385}), dm.vec{0.3, -0.2, 2.385}, 1e-14, "icay(cay)")
  T.near(SO3.dexpinv{0.3, 0.2, -0.4} * SO3.dexp{0.3, 0.2, -0.4}, dm.mat{{1,0,0},{0,1,0},{0,0,1}},
         1e-15, "dexpinv dexp = I")
  T.near(SO3.dexp({0.3, 0.2, -0.4}, "left"), SO3.dexp{-0.3, -0.2, 0.4}, 0, "left = right at -xi")
  T.near(SO3.bracket({1, 0, 0}, {0, 1, 0}), dm.vec{0, 0, 1}, 0, "bracket = cross product")
  T.near(SO3.ad{1, 2, 3}, SO3.hat{1, 2, 3}, 0, "ad = hat on so(3)")
  T.near(R * {1, 0, 0}, dm.vec{0, 1, 0}, 1e-16, "R * x rotates")
  T.near(R:act{1, 0, 0}, dm.vec{0, 1, 0}, 1e-16, "R:act(x)")
  T.near((R * R):matrix(), dm.mat{{-1, 0, 0}, {0, -1, 0}, {0, 0, 1}}, 1e-15, "R * R")
  T.near((R * R:inv()):log(), dm.vec{0, 0, 0}, 1e-16, "R R^-1 = I")
  T.is(R[2][1], 1.0, "R[i][j]: row i of the matrix")
  T.near(SO3.dist(R, SO3.identity()), pi / 2, 1e-15, "dist")
  T.near(R:dist(SO3.identity()), pi / 2, 1e-15, "g:dist")
  -- near pi: the log of a rotation by pi - 1e-9 comes back to 1e-15
  local w = {0.48, -0.6, 0.64}
  local s = (pi - 1e-9)
  local Q = SO3.exp{s * w[1], s * w[2], s * w[3]}
  T.near(Q:log(), dm.vec{s * w[1], s * w[2], s * w[3]}, 1e-14, "log near pi")
  local F = SO3.element{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}
  T.near(F:log(), dm.vec{pi, 0, 0}, 0, "log of diag(1,-1,-1)")
  T.near(SO3.element{1, 0, 0, 0, 1, 0, 0, 0, 1}:log(), dm.vec{0, 0, 0}, 0, "element from 9 numbers")
  local A = SO3.element({{1, 0, 0}, {0, 1.001, 0}, {0, 0, 1}}, {normalize = true})
  T.ok(A:dist(SO3.identity()) < 1e-15, "normalize = true projects onto SO3")
end)

T.group("SE3, SE2, SO2, R^n, T^n, products", function()
  local g = SE3.exp{0, 0, pi / 2, 1, 0, 0}
  T.near(g.p, dm.vec{2 / pi, 2 / pi, 0}, 1e-15, "SE3 screw: p = (2/pi, 2/pi, 0)")
  T.near(g.R:matrix(), SO3.exp{0, 0, pi / 2}:matrix(), 0, "g.R")
  T.near(g:log(), dm.vec{0, 0, pi / 2, 1, 0, 0}, 1e-15, "SE3 log")
  T.near(g * {1, 0, 0}, dm.vec{2 / pi, 2 / pi + 1, 0}, 1e-15, "SE3 acts on points")
  T.is(g[1][4], 2 / pi, "g[i]: row of the 4x4 matrix")
  T.is(tostring(g), "<SE3 rotation 1.5708 about (0, 0, 1), translation (0.63662, 0.63662, 0)>",
       "SE3 printing")
  local h = SE2.exp{1, 2, 3}
  T.is(h.theta, 1.0, "SE2 g.theta")
  T.near((h * h:inv()):log(), dm.vec{0, 0, 0}, 1e-15, "SE2 inverse")
  T.near(SE2.Ad(h) * SE2.Ad(h:inv()), dm.mat{{1,0,0},{0,1,0},{0,0,1}}, 1e-15, "SE2 Ad")
  local a = SO2.exp{3}
  T.is((a * a).theta, 6.0, "SO2 composition adds unwrapped angles")
  T.near((a * a):log(), dm.vec{6 - 2 * pi}, 1e-15, "SO2 log: principal value")
  local R3 = dm.lie.Rn(3)
  T.is(tostring(R3.exp{1, 2, 3} * R3.exp{1, 1, 1}), "<R3 (2, 3, 4)>", "R^n adds")
  T.is(R3.exp{1, 2, 3}[2], 2.0, "R^n g[i]: component")
  local P = dm.lie.product(SE3, dm.lie.T(3))
  local q = P.exp{0, 0, 1, 1, 2, 3, 0.1, 0.2, 0.3}
  T.ok(tostring(q[1]):find("^<SE3 ") and tostring(q[2]) == "<T3 angles (0.1, 0.2, 0.3)>",
       "product g[k]: factors")
  local M = P.Ad(q)
  T.ok(M:rows() == 9 and M[1][7] == 0 and M[7][1] == 0, "product Ad is block diagonal")
  T.ok(tostring(q):find(" | angles %(0.1, 0.2, 0.3%)>$"), "product printing: " .. tostring(q))
end)

T.group("symbolic elements", function()
  local x, y = dm.sym("x"), dm.sym("y")
  local R = SO3.exp{0, 0, x}
  T.ok(R:is_symbolic(), "exp of expressions is symbolic")
  T.is(tostring(R), "<SO3 element (symbolic)>", "printing a symbolic element")
  local e = R[1][1]
  T.near(e:eval{x = 0.5}, math.cos(0.5), 1e-16, "R[1][1] = cos x")
  T.near(e:diff(x):eval{x = 0.5}, -math.sin(0.5), 1e-16, "d R[1][1]/dx = -sin x")
  T.near(e:diff(x):eval{x = 0}, 0, 0, "... exactly 0 at x = 0 (series branch)")
  local S = SO3.exp{y, 0, 0}
  local v = (R * S) * {0, 1, 0}
  T.near(v[3]:eval{x = 0.3, y = 0.7}, math.sin(0.7), 1e-15, "symbolic compose and action")
  local w = (R * S):log()
  T.near(w[3]:eval{x = 0.3, y = 0}, 0.3, 1e-15, "symbolic log")
  local mixed = SO3.exp{0.3, 0, 0} * R
  T.ok(mixed:is_symbolic(), "numeric * symbolic is symbolic")
end)

T.group("spheres", function()
  local S = dm.lie.sphere()
  T.is(tostring(S), "<sphere S^2 in R^3>", "tostring")
  T.near(S.dist({0, 0, 1}, {0, 1, 0}), pi / 2, 1e-15, "dist")
  T.near(S.log({0, 0, 1}, S.exp({0, 0, 1}, {0.3, 0.4, 0})), dm.vec{0.3, 0.4, 0}, 1e-15, "log(exp)")
  T.near(S.rotation({0, 0, 1}, {1, 0, 0}) * {0, 0, 1}, dm.vec{1, 0, 0}, 1e-16, "rotation carries p0 to p1")
  T.near(S.project(SO3.exp{0, pi / 2, 0}), dm.vec{1, 0, 0}, 1e-16, "project R e3")
  local S3 = dm.lie.sphere(3)
  T.near(S3.dist({1, 0, 0, 0}, {0, 0, 0, 1}), pi / 2, 1e-15, "S^3")
end)

T.group("errors", function()
  local F = SO3.element{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}
  T.error_like(function() SO3.icay(F) end,
    "G%.icay: the SO3 element is a rotation by pi: the inverse Cayley map is undefined there %(its cut locus%); input: rotation 3%.14159 about %(1, 0, 0%)",
    "icay at the cut locus names the operation and the input")
  T.error_like(function() SO3.element{{1, 0, 0}, {0, 1.001, 0}, {0, 0, 1}} end,
    "G%.element: SO3 element: max |R%^T R %- I| = 0%.002 %(> tol 1e%-10%): not a rotation %(normalize = true projects onto the group%)",
    "not a rotation")
  T.error_like(function() SO3.element{{1, 0, 0}, {0, 1, 0}, {0, 0, -1}} end,
    "det R < 0: a reflection, not a rotation", "reflection")
  T.error_like(function() SO3.exp{1, 2} end,
    "G%.exp: the SO3 algebra vector must have 3 entries, got 2", "wrong algebra size")
  T.error_like(function() SO3.exp{1, "a", 2} end,
    "G%.exp: the SO3 algebra vector%[2%] must be a number or an expression, got string", "bad entry")
  T.error_like(function() SO3.log(SE3.identity()) end,
    "G%.log: argument #1 must be an element of SO3, got an element of SE3", "wrong group")
  T.error_like(function() return SO3.identity() * SE3.identity() end,
    "g %* h: elements of different groups %(SO3 and SE3%)", "compose across groups")
  T.error_like(function() return SO3.identity() * {1, 2} end,
    "g %* x: the point of R%^3 that SO3 acts on must have 3 entries, got 2", "action size")
  T.error_like(function() return SO3.identity().foo end,
    "SO3 element has no field 'foo'", "unknown element field")
  T.error_like(function() return SO3.foo end, "SO3 has no field 'foo'", "unknown group field")
  T.error_like(function() return SO3.identity()[4] end, "SO3 element: row 4 out of range 1%.%.3",
    "row out of range")
  T.error_like(function() dm.lie.Rn(0) end, "dm%.lie%.Rn: n must be in 1%.%.64, got 0", "Rn(0)")
  T.error_like(function() dm.lie.group("SO4") end,
    "dm%.lie%.group: Lie group name: cannot read 'SO4'", "unknown group name")
  T.error_like(function() SO3.dexp({1, 2, 3}, "up") end,
    "G%.dexp: side must be \"right\" or \"left\", got \"up\"", "bad side")
  T.error_like(function() dm.lie.sphere().log({0, 0, 1}, {0, 0, -1}) end,
    "S%.log: sphere log: q = %-p %(antipodal points%)", "sphere log at the antipode")
  T.error_like(function() SO3.exp{0, 0, dm.sym("x")}:dist(SO3.identity()) end,
    "g:dist: needs a numeric SO3 element, got a symbolic one", "numeric-only on symbolic")
end)

T.group("help", function()
  local byname, byval = dm.docs()
  T.ok(byval[SO3.exp] ~= nil and byval[SO3.exp].sig == "G.exp(xi) -> g", "help(G.exp) by value")
  T.ok(byname["G.dexpinv"] ~= nil and byname["g:matrix"] ~= nil and byname["S.rotation"] ~= nil,
       "help entries for group, element and sphere functions")
end)

T.done()
