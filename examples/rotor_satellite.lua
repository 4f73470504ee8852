-- rotor_satellite.lua -- reorienting a satellite with three internal rotors
-- and zero angular momentum: spinning the rotors around a closed loop in
-- rotor space turns the body by the holonomy of the mechanical connection
-- A = diag(k_i/I_i) on the bundle SO(3) x T^3 -> T^3.  The group is SO(3):
-- the result of two loops depends on their order, and a small square of
-- side a turns the body by exp(-a^2 B(e1, e2)) + O(a^3), B(e1, e2) =
-- -(k1 k2/(I1 I2)) e3 (the curvature).
-- doc/bundles-connections-holonomy.md §2, §8.  Writes rotor_satellite.png.
--
--   src/dmech examples/rotor_satellite.lua
local dm = require "dmech"
local pi = math.pi
local SO3 = dm.lie.SO3()

local R = dm.bundles.rotor{I1 = 1, I2 = 1.2, I3 = 1.5, k1 = 0.5, k2 = 0.45, k3 = 0.4}
local A = dm.mechanical_connection{bundle = R}
local Ad = dm.discrete_connection{from = A, rule = "midpoint"}
print(A)
local c = {0.5, 0.45 / 1.2, 0.4 / 1.5}
print(("curvature B(e1, e2) = %s, -(c1 c2) e3 = %.15f"):format(tostring(A:curvature({0, 0, 0}, 1, 2)),
  -c[1] * c[2]))

-- a square of side a in the rotor-angle plane (i, j), counter-clockwise,
-- m points per leg, appended to the path xs
local function square(xs, i, j, a, m)
  local x0 = xs[#xs]
  local corners = {{0, 0}, {a, 0}, {a, a}, {0, a}, {0, 0}}
  for leg = 1, 4 do
    for k = 1, m do
      local s = k / m
      local p = {x0[1], x0[2], x0[3]}
      p[i] = x0[i] + corners[leg][1] + s * (corners[leg + 1][1] - corners[leg][1])
      p[j] = x0[j] + corners[leg][2] + s * (corners[leg + 1][2] - corners[leg][2])
      xs[#xs + 1] = p
    end
  end
end

-- the manoeuvre: n loops in the (1, 2) plane, then n in the (2, 3) plane,
-- and the same loops in the other order
local a, n, m = 1.0, 3, 40
local function manoeuvre(order)
  local xs = {{0, 0, 0}}
  for _, pl in ipairs(order) do
    for _ = 1, n do square(xs, pl[1], pl[2], a, m) end
  end
  return xs, Ad:lift(xs, R:point{x = {0, 0, 0}, g = SO3.identity()})
end
local xs, qs = manoeuvre{{1, 2}, {2, 3}}
local _, qs2 = manoeuvre{{2, 3}, {1, 2}}
local t, phi, rv = {}, {{}, {}, {}}, {{}, {}, {}}
for k, q in ipairs(qs) do
  t[k] = (k - 1) / (4 * m)
  local w = q.g:log()
  for i = 1, 3 do phi[i][k], rv[i][k] = xs[k][i], w[i] end
end
local g1, g2 = qs[#qs].g, qs2[#qs2].g
print(("after %d loops in (1,2) then %d in (2,3): %s"):format(n, n, tostring(g1)))
print(("the other order:                      %s"):format(tostring(g2)))
print(("the two attitudes differ by %.6f rad: the holonomy group is not abelian"):format(g1:dist(g2)))

-- the tip of the body's x axis, R e1, over both manoeuvres
local tip = {{{}, {}}, {{}, {}}}
for s, list in ipairs{qs, qs2} do
  for k, q in ipairs(list) do
    local e = q.g * {1, 0, 0}
    tip[s][1][k], tip[s][2][k] = e[2], e[3]
  end
end

-- small squares: log P/a^2 -> (0, 0, c1 c2), error O(a)
local as, err = {}, {}
for i = 1, 7 do
  local s = 0.8 / 2^(i - 1)
  local P = Ad:holonomy({{0, 0, 0}, {s, 0, 0}, {s, s, 0}, {0, s, 0}, {0, 0, 0}},
    R:point{x = {0, 0, 0}, g = SO3.identity()}).body
  local w = P:log() / s^2
  as[i], err[i] = s, math.sqrt(w[1]^2 + w[2]^2 + (w[3] - c[1] * c[2])^2)
  print(("square of side %.5f: log P/a^2 = (%+.3e, %+.3e, %.9f), c1 c2 = %.9f"):format(s, w[1],
    w[2], w[3], c[1] * c[2]))
end

dm.plot{
  {{t, phi[1], with = "lines lw 2", legend = "rotor 1"}, {t, phi[2], with = "lines lw 2", legend = "rotor 2"},
   {t, phi[3], with = "lines lw 2", legend = "rotor 3"},
   title = ("rotor angles: %d squares in (1,2), then %d in (2,3), side %.1f rad"):format(n, n, a),
   xlabel = "loops", ylabel = "rotor angle (rad)", key = "outside", yrange = {-0.1, 1.1}},
  {{t, rv[1], with = "lines lw 2", legend = "x"}, {t, rv[2], with = "lines lw 2", legend = "y"},
   {t, rv[3], with = "lines lw 2", legend = "z"},
   title = "body attitude: rotation vector log R", xlabel = "loops", ylabel = "rad", key = "outside"},
  {{tip[1][1], tip[1][2], with = "lines lw 2", legend = "(1,2) first"},
   {tip[2][1], tip[2][2], with = "lines lw 2", legend = "(2,3) first"},
   {{tip[1][1][#qs]}, {tip[1][2][#qs]}, with = "points pt 7 ps 1.5", legend = "its end"},
   {{tip[2][1][#qs2]}, {tip[2][2][#qs2]}, with = "points pt 5 ps 1.5", legend = "its end"},
   title = "tip of the body x axis: the order of the loops matters",
   xlabel = "y", ylabel = "z", aspect = "equal", key = "outside", commands = {"set xtics 0.2"}},
  dm.plot_convergence{h = as, errors = {{"|log P/a^2 - (0, 0, c1 c2)|", err}}, orders = {1},
    xlabel = "side a of the square (rad)", ylabel = "error", panel = true,
    title = "small loops: holonomy/area -> -curvature"},
  layout = "2,2", size = {1300, 1000}, output = "rotor_satellite.png"}
