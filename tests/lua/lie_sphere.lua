-- lie_sphere.lua -- systems on the sphere S^2 (dm.system{space =
-- dm.lie.sphere(2)}) stepped by lgvi through the run driver: the spherical
-- pendulum L = (m/2)|v|^2 - m g z.  |x| = 1 to round-off with no
-- projection, the vertical angular momentum (x p)_z conserved to round-off
-- (discrete Noether: the step commutes with rotations about z), energy
-- bounded, order 2 by step halving against the same pendulum in spherical
-- coordinates, the steps equal to those of RATTLE (Lobatto IIIA-IIIB, s =
-- 2) on R^3 with the constraint |x|^2 = 1, the symplecticity defect on
-- T*S^2, and the errors.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"   -- the tape: no compiler runs in this test

local S2 = dm.lie.sphere(2)
local m, g = 1.7, 9.81
local function Lcart(x, v, p)
  return 0.5 * p.m * (v[1]^2 + v[2]^2 + v[3]^2) - p.m * p.g * x[3]
end
local pend = dm.system{space = S2, name = "spherical pendulum", params = {m = m, g = g},
  L = Lcart}

-- the start: theta (from the upward z axis), phi and their rates
local th, ph, dth, dph = 2.385, 0.3, 0.2, 1.1 / math.sin(2.385)
local function cart(t, f, dt, df)
  local st, ct, sf, cf = math.sin(t), math.cos(t), math.sin(f), math.cos(f)
  return {st * cf, st * sf, ct},
         {ct * cf * dt - st * sf * df, ct * sf * dt + st * cf * df, -st * dt}
end
local x0, v0 = cart(th, ph, dth, dph)
local s0 = {q = x0, v = v0}

local function radius_dev(tr)
  local a, b, c, d = tr:column("x1"), tr:column("x2"), tr:column("x3"), 0
  for k = 1, #a do d = math.max(d, math.abs(math.sqrt(a[k]^2 + b[k]^2 + c[k]^2) - 1)) end
  return d
end
local function Lz(tr)
  local a, b, p, q, out = tr:column("x1"), tr:column("x2"), tr:column("p_x1"),
                          tr:column("p_x2"), {}
  for k = 1, #a do out[k] = a[k] * q[k] - b[k] * p[k] end
  return out
end
local function maxdev(v, i, j)
  local d = 0
  for k = i, j do d = math.max(d, math.abs(v[k] - v[1])) end
  return d
end

T.group("a system on S^2", function()
  T.is(tostring(pend), "<system 'spherical pendulum': 3 coords (x1, x2, x3), g=9.81 m=1.7; "
       .. "traced, tape, separable>", "coordinates x1, x2, x3 by default")
  local I = dm.integrator(pend, {h = 0.01})
  T.is(I.method, "lgvi", "lgvi is the default method on a sphere")
  T.ok(I.symplectic and I.symmetric and I.explicit and I.variational and I.order == 2,
       "lgvi on S^2: explicit, symplectic, symmetric, variational, order 2")
  local tr = I:run(s0, {steps = 20})
  local md = tr:meta()
  T.ok(md.space == "S^2" and md.method == "lgvi" and md.steps == 20, "run metadata: space S^2")
  T.error_like(function() tr:group(1) end, "traj:group: the trajectory is of a system on the "
    .. "sphere S%^2, not on a Lie group: its points are the coordinates %(traj%[k%]%.q%)",
    "traj:group names what a sphere's trajectory holds")
  local f = T.tmpdir("lie_sphere") .. "/pendulum.csv"
  T.ok(tr:save(f), "save as CSV")
  local back = dm.load_trajectory(f)
  T.ok(back:meta().space == "S^2" and #back == #tr, "loaded: space S^2, every sample")
  T.near(back:column("p_x3"), tr:column("p_x3"), 0, "CSV round trip: p_x3 bit for bit")
  T.is(table.concat(tr:names(), ","), "t,x1,x2,x3,p_x1,p_x2,p_x3,v_x1,v_x2,v_x3,energy,"
       .. "momentum_1,momentum_2,momentum_3", "columns: the angular momentum x ^ p, not "
       .. "p_x1, p_x2 of 'cyclic' x1, x2 (the sphere couples them)")
  local s = tr[21]
  T.near(dm.vec{s.momentum_1, s.momentum_2, s.momentum_3},
         dm.vec{s.q[2] * s.p[3] - s.q[3] * s.p[2], s.q[3] * s.p[1] - s.q[1] * s.p[3],
                s.q[1] * s.p[2] - s.q[2] * s.p[1]}, 1e-15, "momentum_k = (x ^ p)_k")
  T.is(#dm.integrator(pend, {h = 0.01}):run(s0, {steps = 2, momentum = false}):names(), 11,
       "momentum = false: no momentum columns")
  T.error_like(function() dm.integrator(pend, {h = 0.01}):run(s0, {steps = 2,
    momentum = {"x1"}}) end, "run: option 'momentum' must be a boolean for a system on S%^2 "
    .. "%(the angular momentum columns momentum_1%.%.%), got table", "momentum = {names} refused")
  T.near(tr:column("p_x2")[1], m * v0[2], 1e-15, "p = m v at the start")
  local named = dm.system{space = S2, coords = {"x", "y", "z"}, params = {m = m, g = g},
    L = Lcart}
  local t2 = dm.integrator(named, {h = 0.01}):run(s0, {steps = 20})
  T.near(t2:column("z"), tr:column("x3"), 0, "coords = {x, y, z} name the same point")
  local S3 = dm.system{space = dm.lie.sphere(3), params = {k = 0.7},
    L = function(x, v, p) return 0.5 * (v[1]^2 + v[2]^2 + v[3]^2 + v[4]^2) - p.k * x[4]^2 end}
  local r = 1 / math.sqrt(4)
  local t3 = dm.integrator(S3, {h = 0.02}):run({q = {r, r, r, r}, v = {0.4, -0.3, 0.2, -0.3}},
                                               {steps = 2000})
  local d3 = 0
  for k = 1, #t3 do
    local s = t3[k].q
    d3 = math.max(d3, math.abs(math.sqrt(s[1]^2 + s[2]^2 + s[3]^2 + s[4]^2) - 1))
  end
  T.ok(t3:meta().space == "S^3" and d3 < 1e-14, "S^3: |x| - 1 = " .. d3 .. " over 2000 steps")
end)

T.group("spherical pendulum: invariants over 10^4 steps", function()
  local tr = dm.integrator(pend, {h = 0.01}):run(s0, {steps = 10000})
  local r = radius_dev(tr)
  T.ok(r < 5e-15, "|x| = 1 to round-off without projection: " .. r)
  local lz = Lz(tr)
  local dl = maxdev(lz, 1, #lz)
  T.ok(dl < 1e-13,
       "vertical angular momentum (x p)_z conserved: " .. dl .. " (of " .. lz[1] .. ")")
  T.conserved(tr, "momentum_3", 1e-13, "the column momentum_3 conserved")
  local m1 = tr:column("momentum_1")
  T.ok(maxdev(m1, 1, #m1) > 0.1, "momentum_1 is not (gravity's torque): " .. maxdev(m1, 1, #m1))
  local e = tr:column("energy")
  local half = (#e + 1) // 2
  local e1, e2 = maxdev(e, 1, half), maxdev(e, half, #e)
  T.ok(e1 < 0.01 and e2 < 1.5 * e1, ("energy bounded: max error %.3g on [0, 50], %.3g on "
       .. "[50, 100]"):format(e1, e2))
  local tr2 = dm.integrator(pend, {h = 0.005}):run(s0, {steps = 20000})
  local e12 = maxdev(tr2:column("energy"), 1, #tr2)
  local ratio = math.max(e1, e2) / e12
  T.ok(ratio > 3.5 and ratio < 4.5, "energy error O(h^2): ratio " .. ratio .. " at h/2")
end)

-- the same pendulum in spherical coordinates (theta from the upward z axis)
local polar = dm.system{coords = {"th", "ph"}, params = {m = m, g = g},
  L = function(q, v, p)
    return 0.5 * p.m * (v.th^2 + dm.sin(q.th)^2 * v.ph^2) - p.m * p.g * dm.cos(q.th)
  end}

T.group("against spherical coordinates and RATTLE", function()
  local t_end = 1.0
  local ref = dm.integrator(polar, {method = "gauss", stages = 4, h = 0.01})
    :run({q = {th, ph}, v = {dth, dph}}, {t = t_end})
  local last = ref[#ref]
  local xr, vr = cart(last.q[1], last.q[2], last.v[1], last.v[2])
  local I = dm.integrator(pend, {h = 0.01})
  local function err(h)
    I.h = h
    local tr = I:run(s0, {t = t_end})
    local q = tr[#tr].q
    return dm.vec{q[1] - xr[1], q[2] - xr[2], q[3] - xr[3]}
  end
  T.order(err, {0.02, 0.01, 0.005, 0.0025}, 2, 0.05,
          "order 2 by step halving, against Gauss 4 in spherical coordinates")
  local o = I:order_estimate{state = s0, t = t_end, h = {0.02, 0.01, 0.005},
    reference = {q = xr, p = {m * vr[1], m * vr[2], m * vr[3]}}}
  T.near(o, 2, 0.05, "integ:order_estimate with that reference: " .. o)
  local o2 = I:order_estimate{state = s0, t = t_end, h = {0.02, 0.01, 0.005}}
  T.near(o2, 2, 0.05, "integ:order_estimate with its own reference (lgvi at h/64): " .. o2)
  -- the discrete Lagrangian is RATTLE's: the same steps to round-off
  local con = dm.system{coords = {"x", "y", "z"}, params = {m = m, g = g}, L = Lcart,
    constraints = function(q, p) return {q.x^2 + q.y^2 + q.z^2 - 1} end}
  local a = dm.integrator(pend, {h = 0.01}):run(s0, {steps = 500})
  local b = dm.integrator(con, {method = "lobatto", stages = 2, h = 0.01}):run(s0, {steps = 500})
  local d = 0
  for i, c in ipairs{"x", "y", "z"} do
    for k = 1, #a do
      d = math.max(d, math.abs(a:column("x" .. i)[k] - b:column(c)[k]),
                   math.abs(a:column("p_x" .. i)[k] - b:column("p_" .. c)[k]))
    end
  end
  T.ok(d < 1e-12, "the steps of RATTLE on R^3 with |x|^2 = 1 to " .. d .. " over 500 steps")
end)

T.group("symplecticity, symmetry, discrete Legendre transforms", function()
  local I = dm.integrator(pend, {h = 0.1})
  T.symplectic(I, s0, 1e-8, "symplecticity defect on T*S^2 (central differences, eps 1e-6)")
  local fast = dm.integrator(pend, {h = 0.1})
  local d = fast:symplecticity_defect({q = x0, v = {3 * v0[1], 3 * v0[2], 3 * v0[3]}})
  T.ok(d < 1e-8, "at three times the speed: " .. d)
  T.ok(I:reversal(s0, 200) < 1e-13, "200 steps forward and back return to the start")
  local tr = dm.integrator(pend, {h = 0.1}):run(s0, {steps = 2})
  local q1, q2 = tr[2].q, tr[3].q
  local p0, p1 = I:dlegendre(x0, q1)
  T.near(p0, dm.vec{m * v0[1], m * v0[2], m * v0[3]}, 1e-13, "-D1 Ld(x0, x1) = p0")
  T.near(p1, tr[2].p, 1e-13, "D2 Ld(x0, x1) = p1")
  T.near(I:del_step(x0, q1), q2, 1e-14, "the two-point DEL step gives x2")
  T.error_like(function() I:jacobian(s0) end, "jacobian: the step Jacobian in coordinates is "
    .. "not defined for method 'lgvi': its states live on a manifold %(S%^2%)",
    "no Jacobian in coordinates")
end)

T.group("errors", function()
  local I = dm.integrator(pend, {h = 0.01})
  T.error_like(function() I:run({q = {0.6, 0, 0.6}, v = {0, 1, 0}}, {steps = 1}) end,
    "the point is not on the sphere: |x|%^2 %- 1 = %-0%.28 %(start from a unit vector%)",
    "a point off the sphere")
  T.error_like(function() I:run({q = x0, v = {0.3, 0.2, 0.1}}, {steps = 1}) end,
    "the momentum is not tangent to the sphere: x%.p = ", "a velocity not tangent")
  T.error_like(function() dm.integrator(pend, {h = 0.5}):run({q = x0, v = {30 * v0[1],
    30 * v0[2], 30 * v0[3]}}, {steps = 1, strict = true}) end,
    "lgvi on S2: the step h = 0%.5 is too large for the speed: the chord h|p|/m = .* must be "
    .. "< 1 %(reduce h%)", "a step longer than the sphere")
  local bad = dm.system{space = S2, params = {m = m},
    L = function(x, v, p) return 0.5 * p.m * (1 + x[1]^2) * (v[1]^2 + v[2]^2 + v[3]^2) end}
  T.error_like(function() dm.integrator(bad, {h = 0.01}) end,
    "lgvi on S2 takes L = %(m/2%)|v|%^2 %- U%(x%) with a constant m", "a mass depending on x")
  local mag = dm.system{space = S2, params = {m = m},
    L = function(x, v, p) return 0.5 * p.m * (v[1]^2 + v[2]^2 + v[3]^2) + 0.4 * v[3] end}
  T.error_like(function() dm.integrator(mag, {h = 0.01}) end,
    "a term linear in v, or m depending on x", "a term linear in v")
  T.error_like(function() dm.system{space = S2, coords = {"x", "y"}, params = {m = m, g = g},
    L = function(x, v, p) return 0.5 * p.m * (v[1]^2 + v[2]^2) end} end,
    "dm.system: a system on the sphere S%^2 has 3 coordinates %(the point in R%^3%), got 2",
    "two coordinates for S^2")
  T.error_like(function() dm.system{space = S2, L = Lcart,
    constraints = function(q) return {q[1]} end} end,
    "dm.system: a system on the sphere S%^2 takes no 'constraints'", "constraints refused")
  local forced = dm.system{space = S2, params = {m = m, g = g}, L = Lcart,
    force = function(q, v, p) return {0.1, 0, 0} end}
  T.error_like(function() dm.integrator(forced, {h = 0.01}) end,
    "lgvi on S2: generalized forces are not supported", "forces refused")
  T.error_like(function() dm.integrator(pend, {method = "gauss", h = 0.01}) end,
    "method 'gauss' does not apply to system 'spherical pendulum' %(a sphere system%)",
    "the methods on coordinates are not offered")
end)

T.done()
