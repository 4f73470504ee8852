-- harmonic_map.lua -- a discrete harmonic map from the unit disc into R^3
-- (thesis section 3.12): minimise S_d(phi) = 1/2 sum_e *1(e) |d phi(e)|^2 with
-- phi fixed on the boundary circle, here a saddle-shaped closed curve.  The
-- discrete Euler-Lagrange equation is Laplacian(0) phi = 0 at every interior
-- vertex, componentwise.  Checked: the Euler-Lagrange residual, that the
-- energy grows under interior perturbations, and that linear boundary data
-- give an exactly linear map.  Writes harmonic_map.png.
--
--   src/dmech examples/harmonic_map.lua
local dm = require "dmech"

local D = dm.mesh.disc{radius = 1, n = 20}
local X = D:vertices()
local boundary = D:boundary(0)
-- boundary curve: (x, y) -> (x, y, 0.4 (x^2 - y^2) + 0.15 sin(6 theta))
local function curve(x, y)
  local th = math.atan(y, x)
  return x, y, 0.4 * (x * x - y * y) + 0.15 * math.sin(6 * th)
end
local phi = {}
for c = 1, 3 do
  local L = D:laplacian(0, {boundary = "dirichlet", value = function(x, y) return (select(c, curve(x, y))) end})
  phi[c] = L:solve(D:cochain(0, 0))
end

-- energy and its Euler-Lagrange residual (the gradient of S_d)
local S0 = D:laplacian(0) -- Delta0 = *0^-1 d^T *1 d: residual at interior vertices
local s1 = D:star(1)
local function energy(p)
  local E = 0
  for c = 1, 3 do local dp = D:d(0) * p[c]; E = E + 0.5 * (s1 * dp):vec():dot(dp:vec()) end
  return E
end
local res = 0
for c = 1, 3 do
  local r = S0 * phi[c]
  for i = 1, #r do if boundary[i] == 0 then res = math.max(res, math.abs(r[i])) end end
end
local E = energy(phi)
print(string.format("S_d(phi) = %.12f   max Euler-Lagrange residual inside = %.2e", E, res))
assert(res < 1e-10)
-- any interior perturbation raises the energy (S_d is convex, phi its minimiser)
for k = 1, 3 do
  local q = {phi[1]:copy(), phi[2]:copy(), phi[3]:copy()}
  for i = 1, #q[3] do
    if boundary[i] == 0 then q[3][i] = q[3][i] + 1e-3 * math.sin(k * X[i][1] + 2.385 * X[i][2]) end
  end
  local dE = energy(q) - E
  print(string.format("perturbation %d: S_d grows by %.3e", k, dE))
  assert(dE > 0)
end
-- linear boundary data give a linear map, exactly
local lin = D:laplacian(0, {boundary = "dirichlet", value = function(x, y) return 2.385 * x - 0.5 * y + 1 end})
  :solve(D:cochain(0, 0))
local lerr = (lin - D:cochain(0, function(x, y) return 2.385 * x - 0.5 * y + 1 end)):norm(math.huge)
print(string.format("linear boundary data: max deviation from the linear map %.2e", lerr))
assert(lerr < 1e-12)

-- the image surface: the same simplices with the vertices moved to phi
local V = {}
for i = 1, #X do V[i] = {phi[1][i], phi[2][i], phi[3][i]} end
local image = D:moved(V)
dm.plot_mesh{image, values = image:cochain(0, phi[3]), edges = true, view = {55, 35},
  title = "discrete harmonic map of the disc spanning a saddle curve", cblabel = "height z",
  output = "harmonic_map.png"}
print("wrote harmonic_map.png")
