-- plot_gallery.lua -- four kinds of plot, each one PNG written by one command:
--   gallery_curve.png      a 2-D curve (Kepler ellipse from its polar equation)
--   gallery_orbit3d.png    a 3-D orbit (satellite around an oblate planet, J2)
--   gallery_reduced.png    a 1x2 multiplot: the orbit beside its reduced (r, z) curve
--   gallery_energy.png     a time series (energy error of the integrator)
--
--   src/dmech examples/plot_gallery.lua [output-directory]
local dm = dm or require "dmech"
local outdir = arg and arg[1] or "."

-- {== the data: Stoermer-Verlet for a satellite in the J2 field ===========
--   V = -1/R + J2/R^3 (3/2 z^2/R^2 - 1/2)   (doc/reduce.md §13)
local J2 = 0.05
local function accel(x, y, z)
  local R2 = x * x + y * y + z * z
  local R = math.sqrt(R2)
  local R3, R5, R7 = R2 * R, R2 * R2 * R, R2 * R2 * R2 * R
  -- a = -grad V
  local common = -1 / R3 + J2 * (7.5 * z * z / R7 - 1.5 / R5)
  return common * x, common * y, common * z - J2 * 3 * z / R5
end
local function energy(x, y, z, vx, vy, vz)
  local R = math.sqrt(x * x + y * y + z * z)
  return 0.5 * (vx * vx + vy * vy + vz * vz) - 1 / R + J2 / R ^ 3 * (1.5 * z * z / (R * R) - 0.5)
end

local h, steps, every = 0.02, 30000, 10
local x, y, z, vx, vy, vz = 2, 0, 0.3, 0, 0.6, 0.1
local ax, ay, az = accel(x, y, z)
local E0 = energy(x, y, z, vx, vy, vz)
local T, X, Y, Z, Rc, dE = {}, {}, {}, {}, {}, {}
for k = 0, steps do
  if k % every == 0 then
    local i = #T + 1
    T[i], X[i], Y[i], Z[i] = k * h, x, y, z
    Rc[i] = math.sqrt(x * x + y * y)
    dE[i] = energy(x, y, z, vx, vy, vz) - E0
  end
  vx, vy, vz = vx + 0.5 * h * ax, vy + 0.5 * h * ay, vz + 0.5 * h * az
  x, y, z = x + h * vx, y + h * vy, z + h * vz
  ax, ay, az = accel(x, y, z)
  vx, vy, vz = vx + 0.5 * h * ax, vy + 0.5 * h * ay, vz + 0.5 * h * az
end
-- any object with :column(name) plots; a trajectory is one
local orbit = dm.trajectory{ t = T, columns = {x = X, y = Y, z = Z, r = Rc, dE = dE},
                             meta = {system = "J2 satellite", method = "Stoermer-Verlet", h = h} }
-- }==

local function out(name) return outdir .. "/" .. name end

-- 1. a 2-D curve: r(theta) = p / (1 + e cos theta), drawn parametrically
local p, e = 1.5, 0.6
dm.plot{ {function(th) local r = p / (1 + e * math.cos(th)) return r * math.cos(th), r * math.sin(th) end,
          range = {0, 2 * math.pi}, samples = 400, title = "r = p / (1 + e cos θ)", with = "lines lw 2"},
         {{0}, {0}, with = "points pt 7 ps 1.5", title = "focus"},
         title = "Kepler ellipse, e = 0.6", xlabel = "x", ylabel = "y", aspect = "equal", grid = true,
         output = out("gallery_curve.png"), size = {640, 480} }

-- 2. a 3-D orbit: three columns give splot
dm.plot{ {orbit, "x", "y", "z", title = "J2 orbit"},
         title = "Satellite around an oblate planet (J2 = 0.05)", xlabel = "x", ylabel = "y", zlabel = "z",
         aspect = "equal", view = {65, 30}, output = out("gallery_orbit3d.png"), size = {800, 600} }

-- 3. reduced beside unreduced: a 1x2 multiplot
dm.plot{ {{orbit, "x", "y", title = "unreduced: (x, y)"}, title = "orbital plane", xlabel = "x", ylabel = "y",
          aspect = "equal", key = false},
         {{orbit, "r", "z", title = "reduced: (r, z)"}, title = "meridian plane", xlabel = "r", ylabel = "z",
          key = false},
         layout = "1,2", title = "The orbit and its reduction by the rotational symmetry",
         output = out("gallery_reduced.png"), size = {1000, 450} }

-- 4. a time series: the energy error of a symplectic method stays bounded
dm.plot{ {orbit, "t", "dE", title = "E(t) - E(0)"},
         title = string.format("Energy error, Stoermer-Verlet, h = %g", h), xlabel = "t", ylabel = "energy error",
         grid = true, output = out("gallery_energy.png"), size = {800, 400} }

print("wrote gallery_curve.png, gallery_orbit3d.png, gallery_reduced.png, gallery_energy.png in " .. outdir)
