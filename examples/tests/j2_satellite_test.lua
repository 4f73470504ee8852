-- j2_satellite_test.lua -- a user's test suite for the J2 satellite, to copy
-- and adapt.  Run every *_test.lua under a directory, each in a fresh dmech
-- process, several at a time:
--
--   dmech test examples/tests          (-v shows every test, --tap for CI)
--
-- or this file alone: dmech examples/tests/j2_satellite_test.lua (TAP).
-- help "dm.test" lists the assertions; each failure prints the file:line of
-- the assertion, the values and the tolerance.
--
-- The satellite: cylindrical coordinates (r, theta, z) about an oblate Earth
-- (J2 = 0.05, Earth radius 1, GM = 1); an inclined (25 deg), slightly
-- eccentric (e = 0.06) orbit of semi-major axis 1.7 started at periapsis on
-- the ascending node.  One orbit takes 2 pi 1.7^1.5 = 13.9 time units.
local T = dm.test

local sat = dm.systems.j2_cylindrical{J2 = 0.05}
local a, e, inc = 1.7, 0.06, math.rad(25)
local rp = a * (1 - e)
local vp = math.sqrt((1 + e) / rp)
local s0 = {q = {rp, 0, 0}, v = {0, vp * math.cos(inc) / rp, vp * math.sin(inc)}}
local period = 2 * math.pi * a^1.5

T.group("gauss s=2 h=0.05, 15 orbits", function()
  local I = dm.integrator(sat, {method = "gauss", stages = 2, h = 0.05})
  local tr = I:run(s0, {t = 15 * period})
  -- theta is cyclic: a variational integrator keeps its momentum J =
  -- r^2 thetadot exactly (discrete Noether), so only round-off may move it.
  T.conserved(tr, "p_theta", 1e-14)
  T.conserved(tr, function(s) return s.r^2 * s.v_theta end, 1e-13, "r^2 thetadot conserved")
  -- a symplectic method of order 4: the energy error stays bounded, of size
  -- C h^4 (3e-11 here), with no drift over the orbits
  T.conserved(tr, "energy", {abs = 2e-10})
  -- the step map is symplectic to round-off
  T.symplectic(I, s0, 1e-14)
end)

T.group("convergence of gauss s=2", function()
  -- errors of the state at t = 4 against Gauss s=3 at h = 0.01 (order 6)
  local function final(method, stages, h)
    local tr = dm.integrator(sat, {method = method, stages = stages, h = h})
      :run(s0, {steps = math.floor(4 / h + 0.5)})
    local s = tr[#tr]
    return {s.r, s.theta, s.z, s.p_r, s.p_theta, s.p_z}
  end
  local ref = final("gauss", 3, 0.01)
  T.order(function(h)
    local x = final("gauss", 2, h)
    for k = 1, #x do x[k] = x[k] - ref[k] end
    return x                      -- a vector error: its max norm is used
  end, {0.2, 0.1, 0.05}, 4, 0.15)
end)

T.group("Routh reduction by theta", function()
  local red = dm.routh(sat, {cyclic = {"theta"}})
  -- derived, not typed in: the Routhian carries the centrifugal term
  T.like(red.routhian, "0%.5%*mu_theta%^2/r%^2")
  local st, mu = red:project(s0)
  T.near(mu, rp^2 * s0.v[2], 1e-15, "mu = r^2 thetadot of the initial state")
  T.near(st.q, {rp, 0}, 0, "shape point (r, z)")
  T.near(red.mu, mu, 0, "the reduction took the state's mu")
  -- the reduced midpoint rule plus reconstruction is the unreduced midpoint
  -- rule: the two runs agree to round-off, sample by sample
  local rt = dm.integrator(red, {method = "midpoint", h = 0.3}):run(st, {steps = 500})
  local full = red:reconstruct(rt, {theta = 0})
  local un = dm.integrator(sat, {method = "midpoint", h = 0.3}):run(s0, {steps = 500})
  T.agree(full, un, {"r", "theta", "z", "p_r", "p_theta", "p_z"}, 1e-11,
          "reduced + reconstructed = unreduced")
  -- second order at a large step: a bounded energy error of 4e-5
  T.conserved(rt, "energy", {abs = 2e-4}, "reduced energy bounded at h = 0.3")
end)

T.group("Cartesian coordinates", function()
  -- the same satellite in (x, y, z): the z angular momentum is a quadratic
  -- invariant, which Gauss methods keep exactly (to round-off)
  local cart = dm.systems.j2{J2 = 0.05}
  local v = s0.v
  local tr = dm.integrator(cart, {method = "gauss", stages = 2, h = 0.05})
    :run({q = {rp, 0, 0}, v = {0, rp * v[2], v[3]}}, {t = 5 * period})
  T.conserved(tr, function(s) return s.x * s.p_y - s.y * s.p_x end, 1e-13, "L_z conserved")
end)
