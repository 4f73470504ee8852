-- maxwell_prism.lua -- Maxwell's equations on a space-time prism complex
-- (thesis section 3.12): space is a triangulated disc K', time a uniform grid,
-- and the potential A is a 1-form on K' x {t_m} in temporal gauge (zero on
-- the vertical edges).  With the Lorentzian star (+ on horizontal 2-cells,
-- - on vertical ones, doc/exterior-calculus.md §10), the discrete action
--   S_d(A) = 1/2 sum_m [ dt <d A^m, d A^m>_*2 - (1/dt) |A^{m+1} - A^m|^2_*1 ]
-- has the Euler-Lagrange equations
--   *1 (A^{m+1} - 2 A^m + A^{m-1}) / dt^2 = - d1^T *2 d1 A^m
-- on interior edges (a perfect conductor on the circle: A = 0 there).
-- Starts at rest in a localised magnetic field.
-- Checked: Gauss's law D *1 E (D = -d0^T) is kept to round-off inside, the discrete energy
--   1/2 |E^{m+1/2}|^2_*1 + 1/2 <d A^m, d A^{m+1}>_*2
-- does not drift, and first the 1+1 scalar case: with dt = h the scheme
-- reproduces d'Alembert's solution g(x - t) exactly.
-- Writes maxwell_prism_energy.png and maxwell_prism_field.png.
--
--   src/dmech examples/maxwell_prism.lua
local dm = require "dmech"

-- 1+1: a scalar field on a path of 40 cells, dt = h
do
  local ncell, steps = 40, 30
  local P = dm.mesh.path{n = ncell}                  -- unit spacing: h = 1
  local L0 = P:laplacian(0)
  local g = function(s) return math.exp(-((s - 12) / 3) ^ 2) end
  local prev = P:cochain(0, function(x) return g(x + 1) end)  -- t = -1
  local cur = P:cochain(0, function(x) return g(x) end)       -- t = 0
  local err = 0
  for m = 1, steps do
    local nxt = cur * 2 - prev - L0 * cur                      -- dt = h = 1
    nxt[1], nxt[ncell + 1] = g(0 - m), g(ncell - m)            -- ends from the exact solution
    prev, cur = cur, nxt
    for i = 1, #cur do err = math.max(err, math.abs(cur[i] - g(i - 1 - m))) end
  end
  print(string.format("1+1 leapfrog with dt = h, %d cells, %d steps: max |phi - g(x - t)| = %.1e", ncell, steps, err))
  assert(err < 1e-13)
end

-- 2+1: Maxwell on a disc
local K = dm.mesh.disc{radius = 1, n = 24}
local d1, D1 = K:d(1), K:dual_d(1)   -- D1 = -d0^T: the dual derivative on dual 1-cochains
local s1, s2 = K:star(1), K:star(2)
local curlcurl = K:codiff(2) * d1                     -- delta2 d1 = *1^-1 d1^T *2 d1
local bnd = K:boundary(1)
local function clamp(a) for i = 1, #a do if bnd[i] == 1 then a[i] = 0 end end return a end

-- time step below the stability limit 2 / sqrt(lambda_max) (power iteration)
local v = K:cochain(1, function(x, y) return math.sin(7 * x + 1), math.cos(5 * y) end)
local lam = 0
for _ = 1, 60 do
  local w = clamp(curlcurl * clamp(v))
  lam = math.sqrt((s1 * w):vec():dot(w:vec()) / (s1 * v):vec():dot(v:vec()))
  v = w / w:norm()
end
local dt = 0.5 * 2 / math.sqrt(lam)
local steps = math.floor(6 / dt)
print(string.format("lambda_max %.1f, dt = %.5f (half the stability limit), %d steps to t = 6", lam, dt, steps))

-- initial state: at rest (E = 0) in a localised magnetic field, A^0 = A^1 =
-- the de Rham map of the potential bump(x, y) (-y, x - 0.3)
local prev = clamp(K:cochain(1, function(x, y)
  local b = math.exp(-((x - 0.3) ^ 2 + y * y) / 0.03)
  return -y * b, (x - 0.3) * b
end))
local cur = prev:copy()
local function energy(a0, a1)
  local e = (a1 - a0) / dt
  local b0, b1 = d1 * a0, d1 * a1
  return 0.5 * (s1 * e):vec():dot(e:vec()) + 0.5 * (s2 * b0):vec():dot(b1:vec())
end
local gauss0 = D1 * (s1 * ((cur - prev) / dt))        -- charge density on the dual cells
local E_first = energy(prev, cur)
local ts, drift, plain = {}, {}, {}
local gmax, vb = 0, K:boundary(0)     -- Gauss's law at the interior vertices
for m = 1, steps do
  local nxt = clamp(cur * 2 - prev - curlcurl * cur * dt ^ 2)
  prev, cur = cur, nxt
  local en = energy(prev, cur)
  ts[#ts + 1], drift[#drift + 1] = (m + 0.5) * dt, en / E_first - 1
  local e = (cur - prev) / dt
  plain[#plain + 1] = (0.5 * (s1 * e):vec():dot(e:vec()) + 0.5 * (s2 * (d1 * cur)):vec():dot((d1 * cur):vec())) / E_first - 1
  local gl = D1 * (s1 * e) - gauss0
  for i = 1, #gl do if vb[i] == 0 then gmax = math.max(gmax, math.abs(gl[i])) end end
end
local dmax, pmax = 0, 0
for i = 1, #drift do dmax, pmax = math.max(dmax, math.abs(drift[i])), math.max(pmax, math.abs(plain[i])) end
print(string.format("discrete energy: max relative change %.1e over %d steps; plain energy oscillates by %.1e",
                    dmax, steps, pmax))
print(string.format("Gauss's law D *1 E at the interior vertices: max change %.1e", gmax))
assert(dmax < 1e-10 and gmax < 1e-10)

dm.plot{
  {ts, plain, with = "lines lw 1", title = "1/2|E|^2 + 1/2|B|^2 at one time level"},
  {ts, drift, with = "lines lw 2.5", title = "discrete energy 1/2|E|^2 + 1/2<dA^m, dA^m+1>"},
  xlabel = "t", ylabel = "energy / initial energy - 1", grid = true, key = "top right",
  yrange = {-0.05, 0.12},
  title = string.format("Maxwell on a prism complex, %d leapfrog steps: no drift", steps),
  output = "maxwell_prism_energy.png"}
dm.plot_mesh{K, values = d1 * cur, arrows = (cur - prev) / dt, every = 3,
  title = string.format("t = %.2f: magnetic field B = dA (colour, density) and E (arrows)", (steps + 0.5) * dt),
  cblabel = "B", output = "maxwell_prism_field.png"}
print("wrote maxwell_prism_energy.png, maxwell_prism_field.png")
