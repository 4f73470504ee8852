-- heavy_top.lua -- the heavy top on SO(3) with the Lie group variational
-- integrator (lgvi; doc/lie.md): nutation and precession of a symmetric
-- top, the path of its apex on the sphere, and a tumbling asymmetric top.
--
--   src/dmech examples/heavy_top.lua [output-directory]
--
-- L = 1/2 (J1 W1^2 + J2 W2^2 + J3 W3^2) - m g l R33: the centre of mass at
-- distance l on the body's third axis, whose direction in space (the apex)
-- is R e3 = (R13, R23, R33).  The potential's moment m g l (R^T e3) x e3 is
-- derived from L by dmech; lgvi conserves the vertical angular momentum
-- e3 . (R Pi) to round-off and (for the symmetric top) the spin Pi3, and
-- keeps the energy error bounded.
--
-- Symmetric top: J = (1, 1, 0.4), m g l = 1, released at a tilt of 0.6 rad
-- with spin W3 = 6 and (a) no transverse velocity: the apex starts at rest
-- and traces cusps; (b) a transverse velocity against the precession: the
-- apex traces loops.  Panel 1: the apex seen from above; panel 2: the
-- nutation angle acos(R33).  Panel 3: the asymmetric top J = (1.3, 2.1, 3.4),
-- m g l = 9.81 * 0.3, Pi0 = (0.5, 0.2, 1), tilted by 0.5 rad, tumbling: its
-- apex wanders over most of the sphere.
local dm = require "dmech"

local outdir = (arg and arg[1]) or "."
local SO3 = dm.lie.SO3()
local function top(J, mgl, name)
  return dm.system{space = SO3, name = name,
    params = {J1 = J[1], J2 = J[2], J3 = J[3], mgl = mgl},
    L = function(R, W, p)
      return 0.5 * (p.J1 * W[1]^2 + p.J2 * W[2]^2 + p.J3 * W[3]^2) - p.mgl * R[3][3]
    end}
end

local function report(label, tr, symmetric)
  local E, J3 = tr:energy(), tr:momentum("3")
  local mu3 = tr:column("mu3")
  local dE, dJ, dS = 0, 0, 0
  for k = 1, #tr do
    dE = math.max(dE, math.abs(E[k] - E[1]))
    dJ = math.max(dJ, math.abs(J3[k] - J3[1]))
    dS = math.max(dS, math.abs(mu3[k] - mu3[1]))
  end
  -- Pi3 is a constant of motion of the symmetric top only: for the
  -- asymmetric one its range is printed, as a measure of the tumbling
  print(("%-28s max |E - E0| %.2g, vertical momentum drift %.2g, %s %.2g"):format(
    label, dE, dJ, symmetric and "spin Pi3 drift" or "spin Pi3 range (not conserved)", dS))
end

local sym = top({1, 1, 0.4}, 1, "symmetric top")
local I = dm.integrator(sym, {method = "lgvi", h = 0.002})
local g0 = SO3.exp{0.6, 0, 0}
local cusp = I:run({g = g0, xi = {0, 0, 6}}, {t = 16, every = 5})
local loop = I:run({g = g0, xi = {-0.6, 0, 6}}, {t = 16, every = 5})
report("symmetric top, cusps:", cusp, true)
report("symmetric top, loops:", loop, true)
for _, tr in ipairs{cusp, loop} do
  tr:derive("nutation", function(s) return math.acos(math.max(-1, math.min(1, s.R33))) end)
end

local asym = top({1.3, 2.1, 3.4}, 9.81 * 0.3, "asymmetric top")
local tumble = dm.integrator(asym, {method = "lgvi", h = 0.002}):run(
  {g = SO3.exp{0.5, 0, 0}, mu = {0.5, 0.2, 1.0}}, {t = 40, every = 5})
report("asymmetric top, tumbling:", tumble)

-- a wire sphere for panel 3
local wire = {}
for k = 0, 5 do
  local x, y, z, u, v, w = {}, {}, {}, {}, {}, {}
  local phi, lat = k * math.pi / 6, (k - 2.5) * math.pi / 6
  for i = 0, 120 do
    local a = 2 * math.pi * i / 120
    x[#x + 1], y[#y + 1], z[#z + 1] = math.cos(a) * math.cos(phi), math.cos(a) * math.sin(phi), math.sin(a)
    u[#u + 1], v[#v + 1], w[#w + 1] = math.cos(lat) * math.cos(a), math.cos(lat) * math.sin(a), math.sin(lat)
  end
  wire[#wire + 1] = {x, y, z, with = "lines lc rgb '#dddddd'"}
  wire[#wire + 1] = {u, v, w, with = "lines lc rgb '#dddddd'"}
end
local p3 = {{tumble, "R13", "R23", "R33", with = "lines lc rgb '#9467bd'", title = "apex R e3"},
            title = "asymmetric top tumbling (t = 0..40)", xlabel = "x", ylabel = "y", zlabel = "z",
            aspect = "equal", view = {65, 30},
            commands = {"set xrange [-1.05:1.05]", "set yrange [-1.05:1.05]",
                        "set zrange [-1.05:1.05]", "set xyplane at -1.05", "set xtics 0.5",
                        "set ytics 0.5", "set ztics 0.5", "set key top right"}}
for _, w in ipairs(wire) do table.insert(p3, 1, w) end

local file = outdir .. "/heavy_top.png"
dm.plot{
  {{cusp, "R13", "R23", with = "lines lw 1.5 lc rgb '#1f77b4'", title = "(a) released at rest: cusps"},
   {loop, "R13", "R23", with = "lines lw 1.5 lc rgb '#d62728'", title = "(b) against the precession: loops"},
   title = "symmetric top: apex R e3 seen from above (t = 0..16)", xlabel = "x", ylabel = "y",
   aspect = "equal", commands = {"set key below"}},
  {{cusp, "t", "nutation", with = "lines lw 1.5 lc rgb '#1f77b4'", title = "(a)"},
   {loop, "t", "nutation", with = "lines lw 1.5 lc rgb '#d62728'", title = "(b)"},
   title = "nutation angle acos(R33)", xlabel = "t", ylabel = "angle from the vertical (rad)",
   commands = {"set key top right"}},
  p3,
  layout = "1,3", size = {1700, 560}, output = file}
print("  wrote " .. file)
