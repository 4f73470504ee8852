-- falling_cat.lua -- the planar three-link cat turns itself over with zero
-- angular momentum: a loop in its shape space (the two joint angles) lifts,
-- through the mechanical connection, to a net rotation of the body -- the
-- geometric phase.  The loop (a circle about (2, -2) in the joint angles)
-- is sized by bisection on its holonomy so that three loops turn the cat by
-- exactly pi; the net rotation of circles of growing radius is checked
-- against minus the integral of the curvature over the disc (Stokes); the
-- discrete horizontal lift converges at first order (euler) and second
-- order (midpoint).  doc/bundles-connections-holonomy.md §2, §8.
-- Writes falling_cat.png, falling_cat_snapshots.png and
-- falling_cat_convergence.png.
--
--   src/dmech examples/falling_cat.lua
local dm = require "dmech"
local pi = math.pi

local C = dm.bundles.cat()                          -- S = T^2 (joint angles), G = SO(2)
local A = dm.mechanical_connection{bundle = C}      -- A = I^-1 C, derived symbolically
print(C)
print(("A(0, 0) = (%.15f, %.15f), 7/27 = %.15f"):format(A:at{0, 0}[1][1], A:at{0, 0}[1][2], 7 / 27))

-- a circle of radius r about c in the shape plane, counter-clockwise
local c = {2.0, -2.0}
local function circle(r)
  return function(s) return {c[1] + r * dm.cos(2 * pi * s), c[2] + r * dm.sin(2 * pi * s)} end
end
local function phase(r)
  return A:holonomy(circle(r), C:point{x = {c[1] + r, c[2]}, g = 0}, {tol = 1e-11}).angle
end

-- size the loop: three loops turn the cat by -pi
local lo, hi = 0.5, 1.5
for _ = 1, 40 do
  local mid = 0.5 * (lo + hi)
  if phase(mid) > -pi / 3 then lo = mid else hi = mid end
end
local r = 0.5 * (lo + hi)
print(("loop radius %.10f: one loop turns the body by %.12f (-pi/3 = %.12f)"):format(r, phase(r), -pi / 3))

-- the manoeuvre: three loops, N points each, lifted by the midpoint rule
local Ad = dm.discrete_connection{from = A, rule = "midpoint"}
local N, loops = 400, 3
local xs, t = {}, {}
for k = 0, loops * N do
  local s = 2 * pi * k / N
  xs[#xs + 1] = {c[1] + r * math.cos(s), c[2] + r * math.sin(s)}
  t[#t + 1] = k / N
end
local qs = Ad:lift(xs, C:point{x = xs[1], g = 0})
local theta, x1, x2 = {}, {}, {}
for k, q in ipairs(qs) do
  theta[k] = q.g:coords()[1]                        -- unwrapped angle
  x1[k], x2[k] = xs[k][1], xs[k][2]
end
print(("after %d loops: body angle %.10f (-pi = %.10f; discrete lift, N = %d per loop)"):format(
  loops, theta[#theta], -pi, N))

-- the three rods in space (centre of mass fixed at 0), at shape x and angle th
local function rods(x, th, dx)
  local ends = {{{-0.5, 0}, {0.5, 0}},
                {{-0.5, 0}, {-0.5 - math.cos(x[1]), -math.sin(x[1])}},
                {{0.5, 0}, {0.5 + math.cos(x[2]), math.sin(x[2])}}}
  local cm = {0, 0}
  for _, e in ipairs(ends) do
    cm[1] = cm[1] + (e[1][1] + e[2][1]) / 6
    cm[2] = cm[2] + (e[1][2] + e[2][2]) / 6
  end
  local out = {}
  for i, e in ipairs(ends) do
    local X, Y = {}, {}
    for j = 1, 2 do
      local px, py = e[j][1] - cm[1], e[j][2] - cm[2]
      X[j] = dx + math.cos(th) * px - math.sin(th) * py
      Y[j] = math.sin(th) * px + math.cos(th) * py
    end
    out[i] = {X, Y}
  end
  return out
end
local snaps = {title = "the cat every half loop (body black, its head a dot; legs red and blue; "
                 .. "centre of mass fixed, snapshots spread out along x)",
               xlabel = "x", ylabel = "y", aspect = "equal", key = false,
               xrange = {-2, 21.5}, yrange = {-1.8, 1.8}, commands = {}}
for i, k in ipairs{1, N / 2 + 1, N + 1, 3 * N / 2 + 1, 2 * N + 1, 5 * N / 2 + 1, 3 * N + 1} do
  local R = rods(xs[k], theta[k], 3.2 * (i - 1))
  snaps[#snaps + 1] = {R[1][1], R[1][2], with = "lines lw 4 lc rgb '#202020'"}
  snaps[#snaps + 1] = {R[2][1], R[2][2], with = "lines lw 2 lc rgb '#c03030'"}
  snaps[#snaps + 1] = {R[3][1], R[3][2], with = "lines lw 2 lc rgb '#3050c0'"}
  snaps[#snaps + 1] = {{R[1][1][2]}, {R[1][2][2]}, with = "points pt 7 ps 1.2 lc rgb '#202020'"}
  table.insert(snaps.commands, ("set label %d 't = %.1f' at %g, -1.5 center"):format(i, (i - 1) / 2,
    3.2 * (i - 1)))
end

-- Stokes: the phase of circles of radius rho = minus the curvature's flux
local rhos, hol, flux = {}, {}, {}
local nr, nt = 40, 80                               -- midpoint rule in polar coordinates
local worst = 0
for i = 1, 8 do
  local rho = 0.15 * i
  local f = 0
  for a = 1, nr do
    local rr = rho * (a - 0.5) / nr
    for b = 1, nt do
      local ph = 2 * pi * (b - 0.5) / nt
      f = f + A:curvature({c[1] + rr * math.cos(ph), c[2] + rr * math.sin(ph)}, 1, 2)[1] * rr
    end
  end
  f = f * (rho / nr) * (2 * pi / nt)
  rhos[i], hol[i], flux[i] = rho, phase(rho), -f
  worst = math.max(worst, math.abs(hol[i] - flux[i]) / math.abs(hol[i]))
end
print(("Stokes: holonomy = -(flux of the curvature) to %.1e relative (midpoint rule %dx%d)"):format(
  worst, nr, nt))

dm.plot{
  {{x1, x2, with = "lines lw 2", legend = "shape loop"},
   {{x1[1]}, {x2[1]}, with = "points pt 7 ps 1.5", legend = "start"},
   title = ("shape loop: circle r = %.4f about (2, -2), counter-clockwise"):format(r),
   xlabel = "x1 (rad)", ylabel = "x2 (rad)", aspect = "equal", commands = {"set xtics 0.5"}},
  {{t, theta, with = "lines lw 2", legend = "body angle (midpoint lift)"},
   {{0, 3}, {0, -pi}, with = "lines dashtype 2", legend = "-pi/3 per loop"},
   title = "body angle with zero angular momentum", xlabel = "loops", ylabel = "theta (rad)"},
  {{t, x1, with = "lines lw 2", legend = "x1 (left leg)"},
   {t, x2, with = "lines lw 2", legend = "x2 (right leg)"},
   title = "joint angles: the control", xlabel = "loops", ylabel = "angle (rad)"},
  {{rhos, hol, with = "lines lw 2", legend = "holonomy (adaptive transport)"},
   {rhos, flux, with = "points pt 6 ps 1.5", legend = "-flux of the curvature"},
   title = "net rotation of one loop: Stokes", xlabel = "loop radius", ylabel = "rotation (rad)"},
  layout = "2,2", size = {1200, 900}, output = "falling_cat.png"}
snaps.output, snaps.size = "falling_cat_snapshots.png", {1500, 420}
dm.plot(snaps)

-- convergence of the discrete lift on the circle r = 0.5 about (1, 0.5)
local cc = {1, 0.5}
local ref = A:holonomy(function(s) return {cc[1] + 0.5 * dm.cos(2 * pi * s), cc[2] + 0.5 * dm.sin(2 * pi * s)} end,
  C:point{x = {1.5, 0.5}, g = 0}, {tol = 1e-13}).angle
print(("reference phase of the circle r = 0.5 about (1, 0.5): %.10f"):format(ref))
local Eu = dm.discrete_connection{from = A, rule = "euler"}
local hs, eu, mp = {}, {}, {}
for i, n in ipairs{8, 16, 32, 64, 128, 256} do
  local poly = {}
  for k = 0, n do
    poly[#poly + 1] = {cc[1] + 0.5 * math.cos(2 * pi * k / n), cc[2] + 0.5 * math.sin(2 * pi * k / n)}
  end
  poly[#poly] = poly[1]
  local q0 = C:point{x = poly[1], g = 0}
  hs[i] = 2 * pi * 0.5 / n                           -- edge length ~ h
  eu[i] = Eu:holonomy(poly, q0).angle - ref
  mp[i] = Ad:holonomy(poly, q0).angle - ref
  print(("N = %3d: euler error %+.4e   midpoint error %+.4e"):format(n, eu[i], mp[i]))
end
dm.plot_convergence{h = hs, errors = {{"euler", eu}, {"midpoint", mp}}, orders = {1, 2},
  xlabel = "edge length h", ylabel = "|holonomy error| (rad)",
  title = "discrete lift of the cat's loop: euler first order, midpoint second",
  output = "falling_cat_convergence.png"}
