-- rigid_body_test.lua -- a user's test suite for a rigid body on SO(3),
-- to copy and adapt (dmech test examples/tests; help "dm.test").
--
-- The body: principal moments of inertia J = (1.3, 2.1, 3.4); the state is
-- the attitude R (a rotation, body to space) and the body angular momentum
-- Pi = mu.  Free, it tumbles with |Pi| and the spatial momentum R Pi fixed;
-- as a heavy top (centre of mass 0.3 up the body's third axis, m g = 9.81)
-- the energy and the vertical spatial momentum (R Pi)_3 are the invariants.
-- The Lie group variational integrators step R without coordinates (no
-- gimbal lock) and never re-orthonormalize it.
local T = dm.test

local SO3 = dm.lie.SO3()
local function body(mgl)
  return dm.system{space = SO3, name = mgl and "heavy top" or "free rigid body",
    params = {J1 = 1.3, J2 = 2.1, J3 = 3.4, mgl = mgl or 0},
    L = function(R, Om, p)
      return 0.5 * (p.J1 * Om[1]^2 + p.J2 * Om[2]^2 + p.J3 * Om[3]^2) - p.mgl * R[3][3]
    end}
end
local free, top = body(), body(9.81 * 0.3)
-- tumbling close to the unstable middle axis, tilted away from the vertical
local s0 = {g = SO3.exp{0.5, -0.2, 0.3}, mu = {0.3, 2.385, -0.4}}

T.group("free body, lgvi h=0.05, 4000 steps", function()
  local I = dm.integrator(free, {method = "lgvi", h = 0.05})
  local tr = I:run(s0, {steps = 4000, every = 10})
  -- |Pi|^2 is a Casimir of the Lie-Poisson bracket: the Moser-Veselov
  -- step keeps it exactly, so only round-off (~1e-16 per step) may move it
  T.conserved(tr, function(s) return s.mu1^2 + s.mu2^2 + s.mu3^2 end, 1e-13,
              "Casimir |Pi|^2 conserved")
  -- invariance under rotations in space: the spatial momentum R Pi
  -- (recorded as momentum_1..3) is a discrete Noether quantity
  for k = 1, 3 do T.conserved(tr, "momentum_" .. k, 1e-13) end
  -- no normalization anywhere: R stays a rotation to round-off
  local R = tr:group(#tr):matrix()
  T.near(R:t() * R, dm.mat{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, 1e-13, "R^T R = I after 4000 steps")
end)

T.group("heavy top, lgvi h=0.01, 30 time units", function()
  local I = dm.integrator(top, {method = "lgvi", h = 0.01})
  local tr = I:run(s0, {t = 30, every = 5})
  -- symplectic of order 2: the energy error stays bounded, of size C h^2
  -- (7.3e-4 by t = 30, 8.7e-4 by t = 300: no drift)
  T.conserved(tr, "energy", {abs = 1.5e-3})
  -- gravity is invariant under rotations about the vertical: (R Pi)_3
  T.conserved(tr, "momentum_3", 1e-12, "vertical momentum conserved")
end)

T.group("symplecticity of the step map, h=0.2", function()
  -- DPhi^T Omega(mu1) DPhi = Omega(mu0) for the canonical form Omega of
  -- T*SO(3); DPhi by central differences, whose own error is ~5e-10
  T.symplectic(dm.integrator(top, {method = "lgvi", h = 0.2}), s0, 1e-8, "lgvi")
  T.symplectic(dm.integrator(top, {method = "lie:gauss", stages = 2, h = 0.2}), s0, 1e-8,
               "lie:gauss s=2")
  -- a classical Runge-Kutta step on the quaternion ODE is not (its defect
  -- is O(h^5): 2e-6 here)
  local d = dm.integrator(top, {method = "gsl:rk4", h = 0.2}):symplecticity_defect(s0)
  T.ok(d > 1e-7, ("gsl:rk4 is not symplectic: defect %.2g"):format(d))
end)

T.group("convergence by step halving", function()
  -- the error at t = 2 in the attitude (geodesic distance on SO(3)) and in
  -- Pi, against lie:gauss with 4 stages (order 8) at h = 0.01
  local function final(opts, h)
    opts.h = h
    local tr = dm.integrator(top, opts):run(s0, {steps = math.floor(2 / h + 0.5)})
    return tr:group(#tr), dm.vec{tr.p.mu1[#tr], tr.p.mu2[#tr], tr.p.mu3[#tr]}
  end
  local gref, muref = final({method = "lie:gauss", stages = 4}, 0.01)
  local function err(opts)
    return function(h)
      local g, mu = final(opts, h)
      local e = mu - muref
      return {g:dist(gref), e[1], e[2], e[3]}
    end
  end
  T.order(err{method = "lgvi"}, {0.04, 0.02, 0.01}, 2, 0.1, "lgvi: order 2")
  T.order(err{method = "lie:gauss", stages = 2}, {0.2, 0.1, 0.05}, 4, 0.2, "lie:gauss s=2: order 4")
end)

T.group("the reduced (Euler-Poincare) form", function()
  -- the free body's Lagrangian is invariant under rotations: the reduced
  -- integrator steps Pi alone and rebuilds R, giving the unreduced run's
  -- numbers to round-off
  local a = dm.integrator(free, {method = "lgvi", h = 0.05}):run(s0, {steps = 1000, every = 50})
  local b = dm.integrator(dm.euler_poincare(free), {method = "lgvi", h = 0.05})
    :run(s0, {steps = 1000, every = 50})
  T.agree(a, b, {"mu1", "mu2", "mu3", "R11", "R22", "R33"}, 1e-12, "reduced = unreduced")
  T.error_like(function() dm.euler_poincare(top) end, "not invariant under left translations",
               "gravity breaks the symmetry: the reduction is refused")
end)
