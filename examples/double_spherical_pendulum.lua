-- double_spherical_pendulum.lua -- thesis figures 2.7-2.9 and the constrained
-- R^3 x R^3 variant of section 2.10.4: Routh reduction with a non-trivial
-- magnetic term, derived by dmech from the Lagrangian, in several charts.
--
--   src/dmech examples/double_spherical_pendulum.lua [output-directory]
--
-- System (dm.systems.double_spherical_pendulum, form "shape"): m1 = m2 = 1,
-- l1 = l2 = 1, g = 9.81, coordinates (theta, r1, r2, phi), theta the azimuth
-- of the first bob, phi = theta2 - theta1, bobs hanging below their pivots
-- (q1 = first bob from the pivot, q2 = second bob from the first).
-- dm.routh reduces by theta (the simultaneous rotation): locked inertia
-- I = m1 r1^2 + m2 (r1^2 + r2^2 + 2 r1 r2 cos phi), connection A, magnetic
-- 2-form beta (doc/reduce.md §14).  Initial condition: r1 = 0.67, r2 = 0.36,
-- phi = 0.68, thetadot = 1.2, r1dot = -0.22, r2dot = 0.24, phidot = -0.61 (a
-- motion whose bobs pass close to the vertical axis, r2 down to ~0.03).
--
-- Where a reduced chart is singular.  Write the horizontal positions as
-- complex numbers w1 = x1 + i y1, w2 = x2 + i y2; the rotation multiplies both
-- by e^{i theta}.  (w1, w2) in C^2 \ 0 modulo this action is the Hopf bundle
-- over CP^1 = S^2, which has no global section.  An additive chart (theta, x)
-- is such a section: theta = arg c(w) for a complex linear form c, and it is
-- singular exactly on the complex line c(w) = 0 (the fibre over one point of
-- S^2).  So every chart of the reduction has a singular set; one can only
-- choose where it lies:
--   cylindrical (r1, r2, phi):  c = w1 and phi = arg w2 - arg w1: singular at
--                               r1 = 0 AND at r2 = 0;
--   "bob 1 polar":  bob 1 in (r1, theta1, z1), bob 2 in Cartesian (xi2, eta2,
--                   z2) of the frame rotated by theta1 (c = w1): singular
--                   only at r1 = 0 (bob 1 directly below the pivot);
--   "bob 2 polar":  the ABSOLUTE position of bob 2, q1 + q2, in (R, Theta, Z),
--                   bob 1 in Cartesian (xi1, eta1, z1) of the frame rotated by
--                   Theta (c = w1 + w2): singular only where bob 2 is
--                   directly below the pivot, R = 0.
-- The two new charts live in V = R^3 x R^3 with the length constraints on
-- the preshape space (RSPRK with Lobatto IIIA-IIIB, multipliers at every
-- stage); dmech derives their I, A, beta and Routhian like any other.  Near
-- its singular set a chart's frame spins at ~ |v|/|c| and the step must
-- resolve that spin; choose c so that |c(w(t))| stays away from 0 along the
-- motion (here bob 2 stays more than 0.4 from the axis while r1 and r2 come
-- within 0.03 of it; the example prints these distances).
--
-- Figures (PNG):
--   dsp_fig2_7.png  r1, r2, phi against t and the horizontal path of m2 relative
--                   to m1 (RSPRK, 2-stage Gauss = 4th order, h = 0.01);
--   dsp_fig2_8.png  |E - E0|/E0 on a log scale up to t = 1500: RSPRK (h = 0.01)
--                   in the thesis's chart (bounded, with spikes and level
--                   jumps at the close approaches r2 -> 0) and in the
--                   "bob 2 polar" chart (bounded at ~1e-8, no spikes);
--                   classical RK4 on the unreduced system with h/4 drifts
--                   linearly.  Right: maxima per interval of 50 and the
--                   fitted drift;
--   dsp_fig2_9.png  RSPRK against SPRK on the classical Routhian (momentum
--                   shift): differences in r1, r2, phi and E at round-off;
--   dsp_constrained.png  energy error (log scale) of the same motion in the
--                   charts (r1, r2, phi), bob 1 polar, bob 2 polar and in the
--                   unreduced Cartesian system (Lobatto IIIA-IIIB s = 3,
--                   h = 0.01, t <= 60) above the distances r1, r2, R of the
--                   configuration from the singular sets: the cylindrical
--                   chart spikes and jumps at the r2 passes, "bob 1 polar"
--                   spikes at the r1 passes only (no jump), "bob 2 polar" and
--                   the unreduced Cartesian system do not spike.  The printed
--                   text adds the R3xR3 cylindrical chart (same as (r1, r2,
--                   phi)), the position-space orders of agreement and the
--                   spike / jump sizes at every close approach.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local P = {m1 = 1, m2 = 1, l1 = 1, l2 = 1, g = 9.81}
local dsp = dm.systems.double_spherical_pendulum{form = "shape"}
local q0, v0 = {0, 0.67, 0.36, 0.68}, {1.2, -0.22, 0.24, -0.61}
local h = 0.01
local clock0 = os.clock()

local red = dm.routh(dsp, {cyclic = {"theta"}})
print(red)
print("  locked inertia I =", red.I)
print("  connection A =", red.A)
local st, mu = red:project{q = q0, v = v0}       -- the reduction takes the state's mu
do
  local ev = red:eval{q = st.q}
  print(("  mu = J(q0, v0) = %.15g; at x0: I = %.15g, beta = %.6g dr1^dphi + %.6g dr2^dphi "
         .. "(the formula: print(red.beta), %d characters)"):format(mu, ev.I, ev.B[1][3], ev.B[2][3],
         #tostring(red.beta)))
end

local function relerr(E)
  local out = {}
  for k = 1, #E do out[k] = (E[k] - E[1]) / E[1] end
  return out
end

local function maxabs(x, i0, i1)
  local m = 0
  for k = i0 or 1, i1 or #x do m = math.max(m, math.abs(x[k])) end
  return m
end

-- upper envelope of |e| over blocks of `width` time units (t equally spaced)
local function envelope(t, e, width)
  local et, ee, blk = {}, {}, math.max(1, math.floor(width / (t[2] - t[1]) + 0.5))
  for i = 1, #t, blk do
    et[#et + 1] = t[i]
    ee[#ee + 1] = maxabs(e, i, math.min(#e, i + blk - 1)) + 1e-17
  end
  return et, ee
end

-- least-squares slope, intercept and standard error of the slope of y(x)
local function linfit(x, y)
  local n, sx, sy, sxx, sxy = #x, 0, 0, 0, 0
  for k = 1, n do
    sx, sy, sxx, sxy = sx + x[k], sy + y[k], sxx + x[k]^2, sxy + x[k] * y[k]
  end
  local a = (n * sxy - sx * sy) / (n * sxx - sx * sx)
  local b, ss = (sy - a * sx) / n, 0
  for k = 1, n do ss = ss + (y[k] - a * x[k] - b)^2 end
  return a, b, n > 2 and math.sqrt(ss / (n - 2) / (sxx - sx * sx / n)) or 0
end

-- {==== the R^3 x R^3 charts (see the header) ============================
-- L from the velocity u1 of bob 1 and the absolute velocity U2 of bob 2 in a
-- rotating frame (|.| is invariant), heights z1 and Z2 of the bobs
local function lagrangian(p, u1, U2, z1, Z2)
  return 0.5 * p.m1 * (u1[1]^2 + u1[2]^2 + u1[3]^2) + 0.5 * p.m2 * (U2[1]^2 + U2[2]^2 + U2[3]^2)
    - p.m1 * p.g * z1 - p.m2 * p.g * Z2
end

-- bob 1 at (r1, 0, z1) in the frame rotated by theta1, bob 2 (from bob 1) at
-- (xi2, eta2, z2) in it: frame velocities (r1dot, r1 w, z1dot) and
-- (xi2dot - w eta2, eta2dot + w xi2, z2dot), w = theta1dot
local bob1_polar = dm.system{name = "double spherical pendulum (R3xR3, bob 1 polar)", params = P,
  coords = {"r1", "theta1", "z1", "xi2", "eta2", "z2"},
  L = function(q, v, p)
    local w = v.theta1
    local u1 = {v.r1, q.r1 * w, v.z1}
    local u2 = {v.xi2 - w * q.eta2, v.eta2 + w * q.xi2, v.z2}
    return lagrangian(p, u1, {u1[1] + u2[1], u1[2] + u2[2], u1[3] + u2[3]}, q.z1, q.z1 + q.z2)
  end,
  constraints = function(q, p)
    return {q.r1^2 + q.z1^2 - p.l1^2, q.xi2^2 + q.eta2^2 + q.z2^2 - p.l2^2}
  end}

-- bob 2 (absolute, q1 + q2) at (R, 0, Z) in the frame rotated by Theta, bob 1
-- at (xi1, eta1, z1) in it
local bob2_polar = dm.system{name = "double spherical pendulum (R3xR3, bob 2 polar)", params = P,
  coords = {"R", "Theta", "Z", "xi1", "eta1", "z1"},
  L = function(q, v, p)
    local w = v.Theta
    return lagrangian(p, {v.xi1 - w * q.eta1, v.eta1 + w * q.xi1, v.z1}, {v.R, q.R * w, v.Z}, q.z1, q.Z)
  end,
  constraints = function(q, p)
    return {q.xi1^2 + q.eta1^2 + q.z1^2 - p.l1^2, (q.R - q.xi1)^2 + q.eta1^2 + (q.Z - q.z1)^2 - p.l2^2}
  end}

-- Cartesian (x1, y1, z1, x2, y2, z2) (q2 from bob 1) from the shape-form state
local function cartesian_state(q, v)
  local th, r1, r2, ph = q[1], q[2], q[3], q[4]
  local thd, rd1, rd2, phd = v[1], v[2], v[3], v[4]
  local s1, s2 = math.sqrt(P.l1^2 - r1^2), math.sqrt(P.l2^2 - r2^2)
  local th2, thd2 = th + ph, thd + phd
  return {r1 * math.cos(th), r1 * math.sin(th), -s1, r2 * math.cos(th2), r2 * math.sin(th2), -s2},
    {rd1 * math.cos(th) - r1 * thd * math.sin(th), rd1 * math.sin(th) + r1 * thd * math.cos(th),
     r1 * rd1 / s1, rd2 * math.cos(th2) - r2 * thd2 * math.sin(th2),
     rd2 * math.sin(th2) + r2 * thd2 * math.cos(th2), r2 * rd2 / s2}
end

-- polar point (X, Y) with velocity (VX, VY): radius, angle, their rates, and
-- the rotation into its frame applied to a point (x, y) with velocity (vx, vy)
local function polar_frame(X, Y, VX, VY, x, y, vx, vy)
  local R = math.sqrt(X^2 + Y^2)
  local c, s = X / R, Y / R
  local w = (X * VY - Y * VX) / R^2
  local xi, eta = c * x + s * y, -s * x + c * y
  return R, math.atan(Y, X), c * VX + s * VY, w, xi, eta,
    c * vx + s * vy + w * eta, -s * vx + c * vy - w * xi
end

-- state of a chart from the Cartesian one
local function chart_state(which, qx, vx)
  if which == "bob1" then
    local r, th, rd, w, xi, eta, xid, etad = polar_frame(qx[1], qx[2], vx[1], vx[2], qx[4], qx[5], vx[4], vx[5])
    return {r, th, qx[3], xi, eta, qx[6]}, {rd, w, vx[3], xid, etad, vx[6]}
  end
  local r, th, rd, w, xi, eta, xid, etad = polar_frame(qx[1] + qx[4], qx[2] + qx[5], vx[1] + vx[4],
                                                       vx[2] + vx[5], qx[1], qx[2], vx[1], vx[2])
  return {r, th, qx[3] + qx[6], xi, eta, qx[3]}, {rd, w, vx[3] + vx[6], xid, etad, vx[3]}
end

-- positions (q1, q2) of a full trajectory of each chart, as columns X1 .. Z2
local POS = {"X1", "Y1", "Z1", "X2", "Y2", "Z2"}
local position = {
  shape = function(s)
    local th2 = s.theta + s.phi
    return s.r1 * math.cos(s.theta), s.r1 * math.sin(s.theta), -math.sqrt(P.l1^2 - s.r1^2),
      s.r2 * math.cos(th2), s.r2 * math.sin(th2), -math.sqrt(P.l2^2 - s.r2^2)
  end,
  bob1 = function(s)
    local c, sn = math.cos(s.theta1), math.sin(s.theta1)
    return s.r1 * c, s.r1 * sn, s.z1, s.xi2 * c - s.eta2 * sn, s.xi2 * sn + s.eta2 * c, s.z2
  end,
  bob2 = function(s)
    local c, sn = math.cos(s.Theta), math.sin(s.Theta)
    local x1, y1 = s.xi1 * c - s.eta1 * sn, s.xi1 * sn + s.eta1 * c
    return x1, y1, s.z1, s.R * c - x1, s.R * sn - y1, s.Z - s.z1
  end,
  cart = function(s) return s.x1, s.y1, s.z1, s.x2, s.y2, s.z2 end,
}
local function positions(tr, kind)
  tr:derive(POS, position[kind])
  local o = {}
  for i, c in ipairs(POS) do o[i] = tr:column(c) end
  return o
end

local qx, vx = cartesian_state(q0, v0)
local charts = {}
-- (native code only where the runs are long: compiling costs more than it
-- saves on the short runs of the bob 1 polar chart)
for _, c in ipairs{{"bob1", bob1_polar, "theta1", "never"}, {"bob2", bob2_polar, "Theta", "auto"}} do
  local rc = dm.routh(c[2], {cyclic = {c[3]}, native = c[4]})
  local q, v = chart_state(c[1], qx, vx)
  local s, m = rc:project{q = q, v = v}
  charts[c[1]] = {red = rc, st = s, theta0 = q[2], mu = m}
end
print(charts.bob1.red)
print("  I =", charts.bob1.red.I)
print("  A =", charts.bob1.red.A)
print(charts.bob2.red)
print("  I =", charts.bob2.red.I)
print("  A =", charts.bob2.red.A)
print(("  mu in the three charts: %.15g, %.15g, %.15g"):format(mu, charts.bob1.mu, charts.bob2.mu))

-- Fig. 2.7 ----------------------------------------------------------------------
do
  local I = dm.integrator(red, {method = "gauss", stages = 2, h = h})
  local rt = I:run(st, {steps = 3000, every = 2})
  local full = red:reconstruct(rt, {theta = q0[1]})
  full:derive({"x2", "y2"}, function(s)
    return s.r2 * math.cos(s.theta + s.phi), s.r2 * math.sin(s.theta + s.phi) end)
  local U = dm.integrator(dsp, {method = "gauss", stages = 2, h = h})
  local un = U:run({q = q0, v = v0}, {steps = 3000, every = 2})
  local d = 0
  for _, c in ipairs{"theta", "r1", "r2", "phi", "p_theta", "p_r1"} do
    local a, b = full:column(c), un:column(c)
    for k = 1, #a do d = math.max(d, math.abs(a[k] - b[k])) end
  end
  local r1, r2 = rt:column("r1"), rt:column("r2")
  local rmin = 1
  for k = 1, #r1 do rmin = math.min(rmin, r1[k], r2[k]) end
  print(("Fig. 2.7: RSPRK Gauss 2, h = %g, t in [0, 30]: min r_i = %.4f; reconstructed full "
         .. "trajectory vs unreduced Gauss 2: max difference %.2e; p_theta - mu = %.1e"):format(
         h, rmin, d, maxabs((function() local p = full:column("p_theta"); local o = {}
           for k = 1, #p do o[k] = p[k] - mu end; return o end)())))
  local file = outdir .. "/dsp_fig2_7.png"
  dm.plot{
    {{rt, "t", "r1", with = "lines"}, title = "r1", xlabel = "t", ylabel = "r1", key = false},
    {{rt, "t", "r2", with = "lines"}, title = "r2", xlabel = "t", ylabel = "r2", key = false},
    {{rt, "t", "phi", with = "lines"}, title = "phi = theta2 - theta1", xlabel = "t", ylabel = "phi", key = false},
    {{full, "x2", "y2", with = "lines"}, title = "m2 relative to m1 (horizontal)", xlabel = "x",
     ylabel = "y", aspect = "equal", key = false},
    layout = "2,2", size = {1200, 900}, output = file}
  print("  wrote " .. file)
end

-- Fig. 2.8 ----------------------------------------------------------------------
-- Long horizon, every step recorded (the spikes last a few steps), log scale.
do
  local T, W = 1500, 50            -- horizon, interval of the per-interval maxima
  local n = math.floor(T / h + 0.5)
  local c = dm.integrator(red, {method = "gauss", stages = 2, h = h}):run(st, {steps = n})
  local b2 = charts.bob2
  local p = dm.integrator(b2.red, {method = "lobatto", stages = 3, h = h}):run(b2.st, {steps = n})
  local u = dm.integrator(dsp, {method = "rk4", h = h / 4}):run({q = q0, v = v0}, {steps = 4 * n, every = 4})
  local runs = {
    {name = "RSPRK Gauss 2, chart (r1, r2, phi)", short = "RSPRK (r1, r2, phi)", t = c:column("t"),
     e = relerr(c:energy()), color = "#9400d3"},
    {name = "RSPRK Lobatto 3, chart \"bob 2 polar\"", short = "RSPRK bob 2 polar", t = p:column("t"),
     e = relerr(p:energy()), color = "#009e73"},
    {name = "RK4 unreduced, h/4", short = "RK4", t = u:column("t"), e = relerr(u:energy()),
     color = "#e69f00"},
  }
  local left, right = {}, {}
  for _, r in ipairs(runs) do
    -- per-interval maxima and their fitted slope (the drift rate)
    r.mid, r.max = {}, {}
    local j, k = 1, 1
    while j * W <= T + 1e-9 do
      local m = 0
      while k <= #r.t and r.t[k] <= j * W + 1e-9 do
        m = math.max(m, math.abs(r.e[k]))
        k = k + 1
      end
      r.mid[j], r.max[j] = (j - 0.5) * W, m
      j = j + 1
    end
    r.slope, r.icpt, r.dslope = linfit(r.mid, r.max)
    r.all, r.tmax = 0, 0
    for k = 1, #r.e do
      if math.abs(r.e[k]) > r.all then r.all, r.tmax = math.abs(r.e[k]), r.t[k] end
    end
    local et, ee = envelope(r.t, r.e, 0.5)
    left[#left + 1] = {et, ee, with = "lines lc rgb '" .. r.color .. "'", title = r.name}
    right[#right + 1] = {r.mid, r.max, with = "linespoints pt 7 ps 0.6 lc rgb '" .. r.color .. "'", title = r.short}
  end
  local rk = runs[3]
  print(("Fig. 2.8: t in [0, %d], h = %g (RK4: h/4 = %g), |dE/E| and the drift rate = fitted slope "
         .. "of the maxima over intervals of %d:"):format(T, h, h / 4, W))
  for _, r in ipairs(runs) do
    local z = math.abs(r.slope) / r.dslope
    print(("  %-38s max %.2e, first interval %.2e, last %.2e, drift %+.2e +- %.1e per unit time (%.1f sigma: %s)"):format(
      r.name, r.all, r.max[1], r.max[#r.max], r.slope, r.dslope, z, z > 3 and "a drift" or "no significant trend"))
  end
  -- when does RK4 stay above an RSPRK's largest error for good?
  for i = 1, 2 do
    local r, over = runs[i], nil
    for k = #rk.e, 1, -1 do
      if math.abs(rk.e[k]) <= r.all then
        if k < #rk.e then over = rk.t[k + 1] end
        break
      end
    end
    if over then
      print(("  RK4 exceeds the largest error of %s (%.2e) for good from t = %.4g on"):format(r.short, r.all, over))
    else
      local tx = (r.all - rk.icpt) / rk.slope
      print(("  RK4 does not overtake the largest error of %s (%.2e) within t = %d; its fitted drift "
             .. "reaches it at t ~ %.0f"):format(r.short, r.all, T, tx))
    end
  end
  do
    local function colmin(tr, name)
      local x, m = tr:column(name), math.huge
      for k = 1, #x do m = math.min(m, x[k]) end
      return m
    end
    print("  RK4 drifts steadily.  In the thesis's chart the RSPRK level jumps at the close approaches to")
    print(("  the singular sets r1 = 0, r2 = 0 (min r1 = %.3f, min r2 = %.3f), which h = %g does not resolve: a"):format(
      colmin(c, "r1"), colmin(c, "r2"), h))
    print(("  walk of the level without trend (its maximum was reached at t = %.1f).  In the \"bob 2 polar\""):format(
      runs[1].tmax))
    print(("  chart the singular set R = 0 is never near (min R = %.2f) and the error stays at its h^4 level."):format(
      colmin(p, "R")))
  end
  right[#right + 1] = {function(t) return rk.slope * t + rk.icpt end, range = {0, T},
                       with = "lines dt 2 lw 2 lc rgb '" .. rk.color .. "'",
                       title = ("RK4 fitted drift %.2e per unit time"):format(rk.slope)}
  for i = 1, 2 do
    local m = runs[i].all
    right[#right + 1] = {function() return m end, range = {0, T}, with = "lines dt 3 lc rgb '" .. runs[i].color .. "'",
                         title = ("largest error of " .. runs[i].short)}
  end
  local file = outdir .. "/dsp_fig2_8.png"
  left.title = "|E - E0|/E0 (upper envelope over 0.5 time units)"
  left.xlabel, left.ylabel, left.logscale, left.key = "t", "|E - E0|/E0", "y", "bottom right"
  left.xrange, left.yrange, left.commands = {0, T}, {1e-12, 1e-3}, {"set format y '%.0e'"}
  right.title = ("maxima over intervals of %d and fitted drift"):format(W)
  right.xlabel, right.ylabel, right.logscale, right.key = "t", "max |E - E0|/E0", "y", "bottom right"
  right.xrange, right.yrange, right.commands = {0, T}, {1e-11, 1e-3}, {"set format y '%.0e'"}
  dm.plot{left, right, layout = "1,2", size = {1500, 600}, output = file}
  print("  wrote " .. file)
end

-- Fig. 2.9 ----------------------------------------------------------------------
do
  local R = dm.integrator(red, {method = "gauss", stages = 2, h = h}):run(st, {steps = 3000, every = 2})
  local C = dm.integrator(red, {method = "classical", stages = 2, h = h}):run(st, {steps = 3000, every = 2})
  local t = R:column("t")
  local series, worst, early = {}, 0, 0
  for _, c in ipairs{"r1", "r2", "phi"} do
    local a, b, d = R:column(c), C:column(c), {}
    for k = 1, #a do
      d[k] = math.abs(a[k] - b[k])            -- zeros are left out on the log axis
      if t[k] <= 5 then early = math.max(early, d[k]) end
    end
    worst = math.max(worst, maxabs(d))
    series[#series + 1] = {t, d, with = "lines", title = "|d " .. c .. "|"}
  end
  local Ea, Eb, dE = R:energy(), C:energy(), {}
  for k = 1, #Ea do dE[k] = math.abs(Ea[k] - Eb[k]) / math.abs(Ea[k]) end
  series[#series + 1] = {t, dE, with = "lines", title = "|dE|/|E|"}
  print(("Fig. 2.9: RSPRK vs SPRK on the classical Routhian: max difference in r1, r2, phi %.2e "
         .. "for t <= 5, %.2e up to t = 30 (round-off amplified by the chaotic motion, fastest in "
         .. "phi at the close approaches), relative difference in E %.2e"):format(early, worst, maxabs(dE)))
  series.title = "RSPRK vs classical-Routhian SPRK (momentum shift): differences"
  series.xlabel = "t"
  series.ylabel = "difference"
  series.logscale = "y"
  series.output = outdir .. "/dsp_fig2_9.png"
  series.size = {1000, 600}
  dm.plot(series)
  print("  wrote " .. series.output)
end

-- Section 2.10.4: the constrained R^3 x R^3 charts, energy error near r -> 0 ------
do
  local T = 60
  -- both bobs cylindrical (the thesis's chart with the constraints kept)
  local r3c = dm.system{name = "double spherical pendulum (R3xR3, cylindrical)", params = P,
    coords = {"r1", "theta1", "z1", "r2", "phi", "z2"},
    L = function(q, v, p)
      local w1, w2 = v.theta1, v.theta1 + v.phi
      local v1sq = v.r1^2 + q.r1^2 * w1^2 + v.z1^2
      local v2sq = v.r2^2 + q.r2^2 * w2^2 + v.z2^2
      local dot = (v.r1 * v.r2 + q.r1 * q.r2 * w1 * w2) * dm.cos(q.phi)
        + (q.r1 * w1 * v.r2 - v.r1 * q.r2 * w2) * dm.sin(q.phi) + v.z1 * v.z2
      return 0.5 * p.m1 * v1sq + 0.5 * p.m2 * (v1sq + v2sq + 2 * dot)
        - p.m1 * p.g * q.z1 - p.m2 * p.g * (q.z1 + q.z2)
    end,
    constraints = function(q, p) return {q.r1^2 + q.z1^2 - p.l1^2, q.r2^2 + q.z2^2 - p.l2^2} end}
  local rc = dm.routh(r3c, {cyclic = {"theta1"}, native = "never"})
  local r1, r2, ph, th = q0[2], q0[3], q0[4], q0[1]
  local rd1, rd2, phd, thd = v0[2], v0[3], v0[4], v0[1]
  local s1, s2 = math.sqrt(P.l1^2 - r1^2), math.sqrt(P.l2^2 - r2^2)
  local stc, muc = rc:project{q = {r1, th, -s1, r2, ph, -s2}, v = {rd1, thd, r1 * rd1 / s1, rd2, phd, r2 * rd2 / s2}}
  local cart = dm.systems.double_spherical_pendulum_r3{}
  local lob = {method = "lobatto", stages = 3}

  -- agreement in position space, orders by step halving (t <= 1)
  do
    local hs, d = {0.04, 0.02, 0.01, 0.005}, {}
    local function pos(h)
      local n, every = math.floor(1 / h + 0.5), math.floor(0.04 / h + 0.5)
      local o = {}
      local opt = {method = "lobatto", stages = 3, h = h}
      o.shape = positions(red:reconstruct(dm.integrator(red, opt):run(st, {steps = n, every = every}),
                                          {theta = q0[1]}), "shape")
      for _, k in ipairs{"bob1", "bob2"} do
        local ch = charts[k]
        o[k] = positions(ch.red:reconstruct(dm.integrator(ch.red, opt):run(ch.st, {steps = n, every = every}),
                                            {theta = ch.theta0}), k)
      end
      o.cart = positions(dm.integrator(cart, opt):run({q = qx, v = vx}, {steps = n, every = every}), "cart")
      return o
    end
    local function dist(a, b)
      local m = 0
      for i = 1, 6 do
        for k = 1, #a[i] do m = math.max(m, math.abs(a[i][k] - b[i][k])) end
      end
      return m
    end
    local pairs_ = {{"bob1", "shape"}, {"bob1", "cart"}, {"bob2", "shape"}, {"bob2", "cart"}}
    for j, hh in ipairs(hs) do
      local o = pos(hh)
      for i, pr in ipairs(pairs_) do
        d[i] = d[i] or {}
        d[i][j] = dist(o[pr[1]], o[pr[2]])
      end
    end
    print("Constrained charts, Lobatto IIIA-IIIB s = 3: positions q1, q2 (theta reconstructed) at t <= 1,")
    print("  max difference for h = 0.04, 0.02, 0.01, 0.005 and the fitted order:")
    local lh = {}
    for j = 1, #hs do lh[j] = math.log(hs[j]) end
    local names = {bob1 = "bob 1 polar", bob2 = "bob 2 polar", shape = "reduced (r1, r2, phi)",
                   cart = "unreduced Cartesian"}
    for i, pr in ipairs(pairs_) do
      local ld = {}
      for j = 1, #hs do ld[j] = math.log(d[i][j]) end
      print(("  %-12s vs %-22s %.2e %.2e %.2e %.2e  order %.2f"):format(names[pr[1]], names[pr[2]],
        d[i][1], d[i][2], d[i][3], d[i][4], (linfit(lh, ld))))
    end
  end

  -- energy error of one motion in every chart (t <= 60, every step)
  local n = math.floor(T / h + 0.5)
  local opt = {method = "lobatto", stages = 3, h = h}
  local a = dm.integrator(red, opt):run(st, {steps = n})
  local runs = {
    {name = "reduced, cylindrical (r1, r2, phi)", tr = a, color = "#9400d3"},
    {name = "reduced, R3xR3 cylindrical", tr = dm.integrator(rc, opt):run(stc, {steps = n})},
    {name = "reduced, R3xR3 bob 1 polar", tr = dm.integrator(charts.bob1.red, opt):run(charts.bob1.st, {steps = n}),
     color = "#56b4e9"},
    {name = "reduced, R3xR3 bob 2 polar", tr = dm.integrator(charts.bob2.red, opt):run(charts.bob2.st, {steps = n}),
     color = "#009e73"},
    {name = "unreduced, Cartesian R3xR3", tr = dm.integrator(cart, opt):run({q = qx, v = vx}, {steps = n}),
     color = "#000000"},
  }
  local t = a:column("t")
  for _, r in ipairs(runs) do r.e = relerr(r.tr:energy()) end
  -- the close approaches, from the first run: minima of r1 below 0.12, of r2 below 0.06
  local R1, R2 = a:column("r1"), a:column("r2")
  local Rabs, Rmin = {}, 1
  do
    local Rp = runs[4].tr:column("R")
    for k = 1, #Rp do Rabs[k] = Rp[k]; Rmin = math.min(Rmin, Rp[k]) end
  end
  local function median(e, i0, i1)
    local v = {}
    for k = math.max(1, i0), math.min(#e, i1) do v[#v + 1] = e[k] end
    table.sort(v)
    return v[(#v + 1) // 2]
  end
  local ev = {r1 = {n = 0, rmin = 1}, r2 = {n = 0, rmin = 1}}
  for _, r in ipairs(runs) do r.spike, r.jump = {r1 = 0, r2 = 0}, {r1 = 0, r2 = 0} end
  for k = 2, #t - 1 do
    for _, pass in ipairs{{"r1", R1, 0.12}, {"r2", R2, 0.06}} do
      local key, Rr, lim = pass[1], pass[2], pass[3]
      if Rr[k] < Rr[k - 1] and Rr[k] <= Rr[k + 1] and Rr[k] < lim then
        ev[key].n = ev[key].n + 1
        ev[key].rmin = math.min(ev[key].rmin, Rr[k])
        for _, r in ipairs(runs) do
          local before = median(r.e, k - 80, k - 20)
          r.spike[key] = math.max(r.spike[key], maxabs((function()
            local o = {}
            for i = math.max(1, k - 10), math.min(#r.e, k + 10) do o[#o + 1] = r.e[i] - before end
            return o end)()))
          r.jump[key] = math.max(r.jump[key], math.abs(median(r.e, k + 20, k + 80) - before))
        end
      end
    end
  end
  print(("Energy error, Lobatto IIIA-IIIB s = 3, h = %g, t in [0, %d] (every step): max |dE/E|, and at the"):format(h, T))
  print(("  %d passes r2 < 0.06 (min %.3f) / %d passes r1 < 0.12 (min %.3f): largest spike (within +-0.1 of"):format(
    ev.r2.n, ev.r2.rmin, ev.r1.n, ev.r1.rmin))
  print("  the pass, from the level before) and largest jump of the level (median after - before):")
  for _, r in ipairs(runs) do
    print(("  %-36s max %.2e | r2 passes: spike %.1e jump %.1e | r1 passes: spike %.1e jump %.1e"):format(
      r.name, maxabs(r.e), r.spike.r2, r.jump.r2, r.spike.r1, r.jump.r1))
  end
  do
    local gmax, G = 0, runs[3].tr
    local a1, b1, c1, d1, e1 = G:column("r1"), G:column("z1"), G:column("xi2"), G:column("eta2"), G:column("z2")
    for k = 1, #a1 do
      gmax = math.max(gmax, math.abs(a1[k]^2 + b1[k]^2 - P.l1^2), math.abs(c1[k]^2 + d1[k]^2 + e1[k]^2 - P.l2^2))
    end
    print(("  (constraints held to %.1e in the bob 1 polar run)"):format(gmax))
  end
  print(("  Singular sets: the cylindrical charts at r1 = 0 and r2 = 0, \"bob 1 polar\" only at r1 = 0"))
  print(("  (bob 1 below the pivot), \"bob 2 polar\" only at R = 0 (bob 2 below the pivot; here R >= %.2f)."):format(Rmin))
  print("  None can be removed: (w1, w2) -> C^2 \\ 0 / rotation is the Hopf bundle, which has no global")
  print("  section, and every additive chart theta = arg c(w) is singular on the line c(w) = 0.  Choose c")
  print("  so that |c(w(t))| stays away from 0 along the motion; only the unreduced Cartesian system has no")
  print("  singular set.")
  local file = outdir .. "/dsp_constrained.png"
  local top = {title = ("|E - E0|/E0, Lobatto IIIA-IIIB s = 3, h = %g (upper envelope over 0.1 time "
                        .. "units)"):format(h), xlabel = "t", ylabel = "|E - E0|/E0", logscale = "y",
               key = "top left", yrange = {1e-11, 1e-1}, commands = {"set format y '%.0e'"}}
  for _, r in ipairs(runs) do
    if r.color then
      local et, ee = envelope(r.tr:column("t"), r.e, 0.1)
      top[#top + 1] = {et, ee, with = "lines lc rgb '" .. r.color .. "'", title = r.name}
    end
  end
  dm.plot{
    top,
    {{t, R1, with = "lines lc rgb '#56b4e9'", title = "r1 (= 0: singular set of the cylindrical and bob 1 polar charts)"},
     {t, R2, with = "lines lc rgb '#9400d3'", title = "r2 (= 0: singular set of the cylindrical charts)"},
     {runs[4].tr:column("t"), Rabs, with = "lines lc rgb '#009e73'",
      title = "R = |w1 + w2| (= 0: singular set of bob 2 polar)"},
     title = "distance of the configuration from the singular sets", xlabel = "t", ylabel = "distance",
     key = "top right",
     -- (a yrange option would be set before the previous panel's log scale is unset)
     commands = {"set format y '%g'", "set yrange [0:1.6]"}},
    layout = "2,1", size = {1300, 1000}, output = file}
  print("  wrote " .. file)
end
print(("total CPU time %.1f s"):format(os.clock() - clock0))
