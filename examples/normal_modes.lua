-- normal_modes.lua -- small oscillations of a chain of three masses and four
-- springs between two walls: the normal-mode frequencies are the square roots
-- of the eigenvalues of M^(-1/2) K M^(-1/2).  Exercises dm.vec, dm.mat and GSL
-- (eigen-decomposition, LU solve) and checks the result against the equations.
--
--   src/dmech examples/normal_modes.lua
local dm = require "dmech"

local m = dm.vec{1.0, 2.385, 1.5}          -- masses
local k = dm.vec{3.0, 1.2, 2.0, 4.1}       -- spring constants, wall to wall
local n = #m

local K = dm.mat(n, n)
for i = 1, n do
  K[i][i] = k[i] + k[i + 1]
  if i < n then K[i][i + 1] = -k[i + 1]; K[i + 1][i] = -k[i + 1] end
end
local Mh = dm.diag(m:map(function(x) return 1 / math.sqrt(x) end))
local A = Mh * K * Mh                      -- symmetric, positive definite

local lambda, V = A:eig()
print("stiffness matrix K =") print(K)
print(string.format("%-6s %-22s %s", "mode", "omega", "|A v - lambda v|"))
for j = 1, n do
  local v = V:col(j)
  local r = (A * v - v * lambda[j]):norm()
  print(string.format("%-6d %-22.17g %.2e", j, math.sqrt(lambda[j]), r))
  assert(r < 1e-13, "eigenpair residual too large")
end

-- Static deflection under a load: K x = f (LU through GSL), checked by residual.
local f = dm.vec{0.5, -1.25, 2.0}
local x = K:solve(f)
print("static deflection x =", x)
print(string.format("residual |K x - f| = %.2e, det K = %.17g", (K * x - f):norm(), K:det()))
