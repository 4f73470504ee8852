-- hodge_torus.lua -- Hodge decomposition of a 1-form on a torus:
--   omega = d alpha + delta beta + h,
-- alpha a 0-form (Laplacian(0) alpha = delta omega), beta a 2-form
-- (Laplacian(2) beta = d omega), h harmonic (d h = 0, delta h = 0).  The
-- harmonic 1-forms of the torus make a plane (b1 = 2): h is checked against
-- the two zero-eigenvalue eigencochains of Laplacian(1).  The pieces are
-- drawn as arrows (sharp) over their pointwise length.
-- Writes hodge_torus_omega.png, hodge_torus_exact.png,
-- hodge_torus_coexact.png, hodge_torus_harmonic.png.
--
--   src/dmech examples/hodge_torus.lua
local dm = require "dmech"

local T = dm.mesh.torus{R = 2, r = 0.8, n = 48, m = 24}
print(T, "Betti numbers", T:betti())
-- a 1-form from a vector field of R^3 (integrated along every edge)
local omega = T:cochain(1, function(x, y, z)
  return -y + 0.5 * x * z, x + 0.3 * z * z, math.sin(x) + y
end)

local alpha = T:laplacian(0, {pin = 1}):solve(T:codiff(1) * omega)
local beta = T:laplacian(2, {pin = 1}):solve(T:d(1) * omega)
local exact = T:d(0) * alpha
local coexact = T:codiff(2) * beta
local h = omega - exact - coexact

local s1 = T:star(1)
local function dot(a, b) return (s1 * a):vec():dot(b:vec()) end
local function norm(a) return math.sqrt(dot(a, a)) end
local n = norm(omega)
print(string.format("|omega| = %.6f   |d alpha| = %.6f   |delta beta| = %.6f   |h| = %.6f",
                    n, norm(exact), norm(coexact), norm(h)))
print(string.format("orthogonality: <d alpha, delta beta> = %.2e, <d alpha, h> = %.2e, <delta beta, h> = %.2e",
                    dot(exact, coexact) / n ^ 2, dot(exact, h) / n ^ 2, dot(coexact, h) / n ^ 2))
print(string.format("h harmonic:    |d h| = %.2e, |delta h| = %.2e (relative)",
                    (T:d(1) * h):norm() / n, (T:codiff(1) * h):norm() / n))
-- the harmonic space: the kernel of Laplacian(1)
local vals, vecs = T:eigen(1, 3)
print(string.format("Laplacian(1): eigenvalues %.2e %.2e %.6f (two zero: b1 = 2)", vals[1], vals[2], vals[3]))
local proj = h - h   -- zero cochain of the same type
for i = 1, 2 do proj = proj + vecs[i] * dot(h, vecs[i]) end
print(string.format("h minus its projection on ker Laplacian(1): %.2e (relative)", norm(h - proj) / norm(h)))
assert(norm(h - proj) / norm(h) < 1e-8 and math.abs(dot(exact, coexact)) / n ^ 2 < 1e-10)

local function length(a)
  local V = T:sharp(a)
  local c = T:cochain(0, 0)
  for i = 1, #c do c[i] = math.sqrt(V[i][1] ^ 2 + V[i][2] ^ 2 + V[i][3] ^ 2) end
  return c
end
for _, p in ipairs{{"omega", omega, "omega"}, {"exact", exact, "exact part d alpha"},
                   {"coexact", coexact, "coexact part delta beta"}, {"harmonic", h, "harmonic part h"}} do
  dm.plot_mesh{T, values = length(p[2]), arrows = p[2], every = 2, view = {55, 25},
    title = "Hodge decomposition on the torus: " .. p[3],
    cblabel = "|sharp|", output = "hodge_torus_" .. p[1] .. ".png"}
end
print("wrote hodge_torus_{omega,exact,coexact,harmonic}.png")
