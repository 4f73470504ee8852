-- foucault.lua -- the Foucault pendulum as a holonomy: in one sidereal day
-- the Earth's rotation carries the pendulum's support once around its
-- latitude circle, and its plane of swing is parallel-transported along
-- the way (Levi-Civita connection of the sphere).  The plane comes back
-- turned by the holonomy of the circle, the enclosed area 2 pi (1 - sin L)
-- = -2 pi sin L (mod 2 pi): clockwise by 2 pi sin L per day in the north.
-- The circle is a geodesic N-gon on the frame bundle SO(3) -> S^2, lifted
-- with the discrete Levi-Civita connection (geodesic edges: exact), so
-- the only error is the polygon's: O(N^-2).
-- doc/bundles-connections-holonomy.md §7.  Writes foucault.png and
-- foucault_convergence.png.
--
--   src/dmech examples/foucault.lua
local dm = require "dmech"
local pi = math.pi
local SO3 = dm.lie.SO3()

local S = dm.sphere_frames()
local LC = dm.discrete_connection{bundle = S, rule = "levi-civita"}
print(S)
print(LC)

-- the latitude circle at L (radians) as an N-gon traversed eastward, and a
-- frame at its start: e1 pointing north... any frame with R e3 = p0 will do
local function circle(L, N)
  local pts = {}
  for k = 0, N do
    local t = 2 * pi * k / N
    pts[#pts + 1] = {math.cos(L) * math.cos(t), math.cos(L) * math.sin(t), math.sin(L)}
  end
  pts[#pts] = pts[1]
  return pts
end
local function frame(p)
  local e1 = {0, 1, 0}                              -- east at (cos L, 0, sin L)
  local e2 = {p[2] * e1[3] - p[3] * e1[2], p[3] * e1[1] - p[1] * e1[3], p[1] * e1[2] - p[2] * e1[1]}
  return SO3.element(dm.mat{{e1[1], e2[1], p[1]}, {e1[2], e2[2], p[2]}, {e1[3], e2[3], p[3]}})
end
-- the turn of the plane of swing over one day, per latitude: the holonomy
-- angle is defined mod 2 pi; unwrap it by continuity along the latitudes
local function day_turn(L, N)
  local pts = circle(L, N)
  return LC:holonomy(pts, S:point{R = frame(pts[1])}).angle
end

local N = 256
local lats, turn, exact = {}, {}, {}
local prev
for i = -89, 89 do
  local L = i * pi / 180
  local a = day_turn(L, N)
  if prev then a = a + 2 * pi * math.floor((prev - a) / (2 * pi) + 0.5) end
  prev = a
  lats[#lats + 1], turn[#turn + 1], exact[#exact + 1] = i, a * 180 / pi, -360 * math.sin(L)
end
-- the turn is defined mod 360: unwrapped by continuity, its branch is fixed
-- by the equator, a great circle, along which the plane does not turn
local off = turn[90]
for k = 1, #turn do turn[k] = turn[k] - off end
local worst = 0
for k = 1, #turn do worst = math.max(worst, math.abs(turn[k] - exact[k])) end
print(("N = %d edges: turn per day = -360 sin(latitude) degrees to %.2e degrees "
       .. "(worst over the latitudes -89..89)"):format(N, worst))
for _, d in ipairs{0, 30, 48.85, 90 - 1e-9} do
  local L = d * pi / 180
  print(("latitude %6.2f: holonomy %.9f  (2 pi (1 - sin L) mod 2 pi = %.9f)"):format(d,
    day_turn(L, N) % (2 * pi), (2 * pi * (1 - math.sin(L))) % (2 * pi)))
end

-- the plane of swing over the day at Paris (48.85 N): the angle from east
-- of the transported frame's first axis, along the lifted circle
local L = 48.85 * pi / 180
local pts = circle(L, N)
local q0 = S:point{R = frame(pts[1])}
local qs = LC:lift(pts, q0)
local hours, angle = {}, {}
for k, q in ipairs(qs) do
  local R = q.R:matrix()
  -- the transported e1 against the local east direction at p
  local p = {R[1][3], R[2][3], R[3][3]}
  local east = {-p[2], p[1], 0}
  local ne = math.sqrt(east[1]^2 + east[2]^2)
  local north = {p[2] * east[3] - p[3] * east[2], p[3] * east[1] - p[1] * east[3], p[1] * east[2] - p[2] * east[1]}
  local c = (R[1][1] * east[1] + R[2][1] * east[2] + R[3][1] * east[3]) / ne
  local s = (R[1][1] * north[1] + R[2][1] * north[2] + R[3][1] * north[3]) / ne
  local a = math.atan(s, c) * 180 / pi
  if k > 1 then a = a + 360 * math.floor((angle[k - 1] - a) / 360 + 0.5) end
  hours[k], angle[k] = 24 * (k - 1) / N, a
end
print(("Paris: the plane turns by %.4f degrees in a sidereal day (-360 sin L = %.4f)"):format(
  angle[#angle] - angle[1], -360 * math.sin(L)))

-- the plane of swing every sidereal hour for half a day, seen from above
-- (east right, north up): it turns clockwise by 360 sin L / 24 per hour
local rose = {title = "Paris, 48.85 N: the plane of swing every hour, 0h to 12h",
              xlabel = "east", ylabel = "north", aspect = "equal", key = false,
              xrange = {-1.3, 1.3}, yrange = {-1.3, 1.3}, commands = {}}
for h = 0, 12 do
  local k = math.floor(h * N / 24 + 0.5) + 1
  local a = angle[k] * pi / 180
  local red = math.floor(230 * h / 12)
  rose[#rose + 1] = {{-math.cos(a), math.cos(a)}, {-math.sin(a), math.sin(a)},
                     with = ("lines lw 2 lc rgb '#%02x30%02x'"):format(red, 230 - red)}
  if h % 2 == 0 then
    table.insert(rose.commands, ("set label %d '%dh' at %g, %g center"):format(h + 1, h,
      1.15 * math.cos(a), 1.15 * math.sin(a)))
  end
end
local lat5, turn5 = {}, {}
for k = 1, #lats, 4 do lat5[#lat5 + 1], turn5[#turn5 + 1] = lats[k], turn[k] end
dm.plot{
  {{lats, exact, with = "lines lw 2", legend = "-360 sin(latitude)"},
   {lat5, turn5, with = "points pt 6 ps 1", legend = ("Levi-Civita holonomy, %d-gon"):format(N)},
   title = "turn of the plane of swing in one sidereal day", xlabel = "latitude (degrees)",
   ylabel = "turn (degrees, + = counter-clockwise)", xrange = {-90, 90},
   commands = {"set xtics 30", "set ytics 90"}},
  rose,
  layout = "1,2", size = {1300, 520}, output = "foucault.png"}

-- convergence with the number of edges at latitude 30 (holonomy -> pi)
local Ns, err = {}, {}
for i, n in ipairs{8, 16, 32, 64, 128, 256, 512, 1024} do
  local a = day_turn(pi / 6, n) % (2 * pi)
  Ns[i], err[i] = 2 * pi * math.cos(pi / 6) / n, a - pi
  print(("latitude 30, N = %4d: holonomy %.9f, error %+.3e"):format(n, a, err[i]))
end
dm.plot_convergence{h = Ns, errors = {{"geodesic N-gon, latitude 30", err}}, orders = {2},
  xlabel = "edge length (Earth radii)", ylabel = "|holonomy - pi| (rad)",
  title = "Foucault: the polygon converges to the latitude circle at second order",
  output = "foucault_convergence.png"}
