-- mech_integrators.lua -- the integrators through the Lua API on TRACED
-- systems: the pendulum's one-step values (1e-13) and orders (within 0.1)
-- for Gauss s=1..4, Lobatto s=2..4 and every composition, time reversal on
-- Kepler (<= 1e-12; reference problems of doc/integrators.md §12), symplecticity defects (<= 1e-12 for symplectic methods,
-- clearly non-zero for rk4), user PRK tableaus, the DEL view (discrete
-- Legendre transforms, two-point steps) and the discrete momentum J_d.
local T = require "dmech.test"
local dm = require "dmech"

local pend = dm.system{name = "pendulum", coords = {"q"},
  L = function(q, v) return 0.5 * v.q^2 + dm.cos(q.q) end}
local s0 = {q = {1}, p = {0.5}}

-- one step, h = 0.1 (doc/integrators.md §12.1)
local one_step = {
  {{method = "midpoint"}, 1.0457319775935514958, 0.41463955187102991597},
  {{method = "gauss", stages = 1}, 1.0457319775935514958, 0.41463955187102991597},
  {{method = "gauss", stages = 2}, 1.045750310037518364, 0.41460947604204174098},
  {{method = "gauss", stages = 3}, 1.0457503205397358305, 0.41460947550868741033},
  {{method = "trapezoid"}, 1.0457926450759605175, 0.41466034594502186448},
  {{method = "trapezoid", explicit = false}, 1.0457926450759605175, 0.41466034594502186448},
  {{method = "lobatto", stages = 2}, 1.0457926450759605175, 0.41466034594502186448},
  {{method = "lobatto", stages = 3}, 1.0457503318316956076, 0.41460947159014490595},
  {{method = "lobatto", stages = 4}, 1.0457503205353137737, 0.41460947550646890948},
}
for _, c in ipairs(one_step) do
  local o = c[1]
  o.h = 0.1
  local I = dm.integrator(pend, o)
  local s = I:step(s0)
  T.ok(math.abs(s.q[1] - c[2]) <= 1e-13 and math.abs(s.p[1] - c[3]) <= 1e-13 and s.t == 0.1,
       ("pendulum one step %s: q1 off by %.2g, p1 by %.2g"):format(tostring(I), s.q[1] - c[2], s.p[1] - c[3]))
end

-- orders by step halving against the exact (q, p)(2) (doc/integrators.md §12.2)
local exact = {q = {0.29104535735144390609}, p = {-1.0417697671437177188}}
local std, long = {0.2, 0.1, 0.05, 0.025}, {0.5, 0.25, 0.125}
local orders = {
  {{method = "gauss", stages = 1}, 2, std}, {{method = "gauss", stages = 2}, 4, std},
  {{method = "gauss", stages = 3}, 6, std}, {{method = "gauss", stages = 4}, 8, long},
  {{method = "lobatto", stages = 2}, 2, std}, {{method = "lobatto", stages = 3}, 4, std},
  {{method = "lobatto", stages = 4}, 6, {0.5, 0.25, 0.125, 0.0625}},
  {{method = "composition", order = 4, scheme = "yoshida4"}, 4, {0.4, 0.2, 0.1, 0.05}},
  {{method = "composition", order = 6, scheme = "yoshida6"}, 6, {0.4, 0.2, 0.1, 0.05}},
  {{method = "composition", order = 6, scheme = "kahanli6"}, 6, {0.4, 0.2, 0.1, 0.05}},
  {{method = "composition", order = 8, scheme = "mclachlan8"}, 8, long},
  {{method = "composition", order = 8, scheme = "kahanli8"}, 8, long},
}
for _, c in ipairs(orders) do
  local order, err = dm.integrator(pend, c[1]):order_estimate{state = s0, t = 2, h = c[3], reference = exact}
  T.ok(math.abs(order - c[2]) <= 0.1, ("pendulum order %s %s: order %.3f (expected %d; errors %.3g .. %.3g)"):format(
       c[1].method, c[1].stages or c[1].scheme, order, c[2], err[1], err[#err]))
end
local _, g2err = dm.integrator(pend, {method = "gauss", stages = 2}):order_estimate{state = s0, t = 2, h = std,
                                                                                  reference = exact}
T.ok(math.abs(g2err[1] / 1.587e-6 - 1) < 1e-3 and math.abs(g2err[4] / 3.883e-10 - 1) < 1e-3,
     "pendulum G2 errors are the reference 1.587e-6 .. 3.883e-10")
local order_ref = dm.integrator(pend, {method = "lobatto", stages = 3}):order_estimate{state = s0, t = 2, h = std}
T.ok(math.abs(order_ref - 4) <= 0.1, ("order against the default reference (Gauss 6): %.3f"):format(order_ref))

-- time reversal (doc/integrators.md §12.6) and the symplecticity defect on Kepler e = 0.6
local kep = dm.systems.kepler()
local k0 = {q = {0.4, 0}, p = {0, 2}}
local symplectic = {
  {method = "midpoint"}, {method = "gauss", stages = 1}, {method = "gauss", stages = 2},
  {method = "gauss", stages = 3}, {method = "gauss", stages = 4}, {method = "trapezoid"},
  {method = "trapezoid", explicit = false}, {method = "lobatto", stages = 2},
  {method = "lobatto", stages = 3}, {method = "lobatto", stages = 4},
  {method = "composition", order = 4}, {method = "composition", order = 4, base = "midpoint"},
  {method = "composition", order = 6, scheme = "yoshida6"}, {method = "composition", order = 6, scheme = "kahanli6"},
  {method = "composition", order = 8, scheme = "mclachlan8"}, {method = "composition", order = 8, scheme = "kahanli8"},
  {method = "prk", tableau = dm.tableau("lobatto", 3)},
}
for _, o in ipairs(symplectic) do
  o.h = 0.05
  local I = dm.integrator(kep, o)
  local rev, def = I:reversal(k0, 200), I:symplecticity_defect(k0)
  T.ok(I.symplectic and I.symmetric and rev <= 1e-12 and def <= 1e-12,
       ("Kepler %s: reversal after 2x200 steps %.2g, symplecticity defect %.2g"):format(tostring(I), rev, def))
end
local rk4 = dm.integrator(kep, {method = "rk4", h = 0.05})
local drk = rk4:symplecticity_defect(k0)
T.ok(not rk4.symplectic and drk > 1e-6, ("rk4 is not symplectic: defect %.3g"):format(drk))
T.ok(rk4:reversal(k0, 200) > 1e-4, "rk4 is not symmetric: reversal error")
local jac = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.05}):jacobian(k0)
T.ok(#jac == 4 and math.abs(jac:det() - 1) < 1e-13, "the step Jacobian is 4x4 with det 1")

-- user PRK tableaus
local l3 = dm.tableau("lobatto", 3)
T.ok(l3.s == 3 and l3.order == 4 and l3.symplectic and math.abs(l3.a[2][1] - 5 / 24) < 1e-16
     and math.abs(l3.at[3][2] - 5 / 6) < 2.3e-16 and l3.defect < 1e-15, "dm.tableau('lobatto', 3): the exact coefficients")
local g2 = dm.tableau("gauss", 2)
T.near(g2.c[1], 0.21132486540518712, 1e-16, "dm.tableau('gauss', 2).c[1]")
local prk = dm.integrator(pend, {method = "prk", tableau = {a = l3.a, b = l3.b, at = l3.at, c = l3.c}, h = 0.1})
local lob = dm.integrator(pend, {method = "lobatto", stages = 3, h = 0.1})
local a, b = prk:step(s0), lob:step(s0)
T.ok(math.abs(a.q[1] - b.q[1]) < 1e-15 and math.abs(a.p[1] - b.p[1]) < 1e-15, "prk with the Lobatto 3 table = lobatto s=3")
local sym = dm.integrator(pend, {method = "prk", tableau = {a = {{0.25, 0.25 - math.sqrt(3) / 6},
  {0.25 + math.sqrt(3) / 6, 0.25}}, b = {0.5, 0.5}}, h = 0.1})
local g = sym:step(s0)
T.ok(math.abs(g.q[1] - 1.045750310037518364) < 1e-13, "prk with a alone (at = symplectic partner) is Gauss 2")
T.error_like(function()
  dm.integrator(pend, {method = "prk", h = 0.1, tableau = {a = {{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.5, 0, 0}, {0, 0, 1, 0}},
    b = {1 / 6, 1 / 3, 1 / 3, 1 / 6}, at = {{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.5, 0, 0}, {0, 0, 1, 0}}}})
end, "not symplectic: .* at %(i, j%) = %(1, 2%)", "a non-symplectic PRK tableau is refused naming (i, j)")

-- DEL view: discrete Legendre transforms and two-point steps
local G2 = dm.integrator(kep, {method = "gauss", stages = 2, h = 0.05})
local s1 = G2:step(k0)
local s2 = G2:step(s1)
local p0, p1, Ld = G2:dlegendre(k0.q, s1.q)
T.ok(math.abs(p0[1] - 0) + math.abs(p0[2] - 2) < 1e-13 and (p1 - s1.p):norm() < 1e-13 and type(Ld) == "number",
     "dlegendre(q0, q1) recovers p0 and p1 of the step")
T.ok((G2:del_step(k0.q, s1.q) - s2.q):norm() < 1e-13, "del_step(q0, q1) = q2 of the (q, p) steps")
local mp = dm.integrator(kep, {method = "midpoint", h = 0.05})
local m1 = mp:step(k0)
local _, _, Ldm = mp:dlegendre(k0.q, m1.q)
local qm, vm = (k0.q[1] + m1.q[1]) / 2, {(m1.q[1] - 0.4) / 0.05, (m1.q[2] - 0) / 0.05}
local qbar = {(0.4 + m1.q[1]) / 2, m1.q[2] / 2}
T.near(Ldm, 0.05 * kep:lagrangian{q = qbar, v = vm}, 1e-14, "midpoint Ld = h L((q0+q1)/2, (q1-q0)/h)")
T.error_like(function() rk4:dlegendre(k0.q, s1.q) end, "method 'rk4' has no discrete Lagrangian", "rk4 is not variational")

-- discrete momentum J_d along the cyclic angle is conserved
local pol = dm.systems.kepler_polar()
for _, o in ipairs{{method = "gauss", stages = 2}, {method = "midpoint"}, {method = "lobatto", stages = 3}} do
  o.h = 0.05
  local I = dm.integrator(pol, o)
  local tr = I:run({q = {0.4, 0}, p = {0, 0.8}}, {steps = 300})
  local r, th = tr:column("r"), tr:column("theta")
  local dev = 0
  for k = 1, #tr - 1 do
    local J = I:discrete_momentum({r[k], th[k]}, {r[k + 1], th[k + 1]}, "theta")
    dev = math.max(dev, math.abs(J - 0.8))
  end
  T.ok(dev <= 2e-15 * 300, ("J_d(theta) of %s conserved over 300 steps: %.2g"):format(o.method, dev))
end
T.done()
