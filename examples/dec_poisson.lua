-- dec_poisson.lua -- Poisson's equation on the unit disc with discrete
-- exterior calculus: Laplacian(0) u = f, u = 0 on the circle, for the
-- manufactured solution u = cos(pi r^2 / 2) on Delaunay discs of 4 to 64
-- rings.  The error at the vertices falls like h^2 (h = 1/rings); the
-- log-log plot shows it against the h^2 reference line, and the finest
-- solution is drawn as a coloured surface with its gradient.
-- Writes dec_poisson_convergence.png and dec_poisson_solution.png.
--
--   src/dmech examples/dec_poisson.lua
local dm = require "dmech"

local pi = math.pi
local function exact(x, y) return math.cos(pi * (x * x + y * y) / 2) end
-- the PSD Laplacian is minus the analyst's: Delta u = -lap u
local function source(x, y)
  local q = x * x + y * y
  return 2 * pi * math.sin(pi * q / 2) + pi * pi * q * math.cos(pi * q / 2)
end

local hs, errs = {}, {}
print(string.format("%6s %9s %9s %12s %7s", "rings", "vertices", "h", "max error", "order"))
local D, u
for _, n in ipairs{4, 8, 16, 32, 64} do
  D = dm.mesh.disc{radius = 1, n = n}
  u = D:laplacian(0, {boundary = "dirichlet"}):solve(D:cochain(0, source))
  local err = (u - D:cochain(0, exact)):norm(math.huge)
  hs[#hs + 1], errs[#errs + 1] = 1 / n, err
  local order = #errs > 1 and math.log(errs[#errs - 1] / err, 2) or nil
  print(string.format("%6d %9d %9.5f %12.4e %7s", n, D:count(0), 1 / n, err,
                      order and string.format("%.3f", order) or ""))
  if order then assert(order > 1.9, "order 2 expected") end
end

local ref = {}
for i, h in ipairs(hs) do ref[i] = errs[1] * (h / hs[1]) ^ 2 end
dm.plot{
  {hs, errs, with = "linespoints pt 7 lw 2", title = "DEC, max error at the vertices"},
  {hs, ref, with = "lines dt 2 lw 1.5", title = "reference slope h^2"},
  logscale = "xy", grid = true, key = "top left",
  xlabel = "h = 1 / rings", ylabel = "max_v |u_h(v) - u(v)|",
  title = "Poisson on the unit disc, u = cos(pi r^2/2): order 2",
  output = "dec_poisson_convergence.png"}

local coarse = dm.mesh.disc{radius = 1, n = 16}
local uc = coarse:laplacian(0, {boundary = "dirichlet"}):solve(coarse:cochain(0, source))
dm.plot_mesh{coarse, values = uc, arrows = coarse:d(0) * uc, every = 5,
  title = "u on 16 rings; arrows: sharp of du (grad u)",
  cblabel = "u", output = "dec_poisson_solution.png"}
print("wrote dec_poisson_convergence.png, dec_poisson_solution.png")
