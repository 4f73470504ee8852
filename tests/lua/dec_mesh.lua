-- dec_mesh.lua -- dm.mesh: generators, typed operators and cochains, solves,
-- eigenpairs, intrinsic meshes and the error messages.
local T = require "dmech.test"
local dm = require "dmech"

-- the acceptance script of the module, as a user writes it
local Tor = dm.mesh.torus{R = 2, r = 0.7, n = 40, m = 20}
local b0, b1, b2 = Tor:betti()
T.ok(b0 == 1 and b1 == 2 and b2 == 1, "torus Betti numbers 1 2 1")
T.is((Tor:d(1) * Tor:d(0)):norm(), 0, "d1 d0 = 0 exactly (integer 0)")
local D = dm.mesh.disc{radius = 1, n = 32}
local f = D:cochain(0, function(x, y) return x^2 + y^2 end)
local lap = D:laplacian(0) * f
local bnd = D:boundary(0)
local maxerr = 0
for i = 1, #lap do
  if bnd[i] == 0 then maxerr = math.max(maxerr, math.abs(lap[i] + 4)) end
end
T.ok(maxerr < 1e-10, "Delta0 (x^2+y^2) = -4 at interior vertices (" .. maxerr .. ")")
local u = D:laplacian(0, {boundary = "dirichlet"}):solve(D:cochain(0, function(x, y) return 4 end))
local X = D:vertices()
maxerr = 0
for i = 1, #u do maxerr = math.max(maxerr, math.abs(u[i] - (1 - X[i][1]^2 - X[i][2]^2))) end
T.ok(maxerr < 1e-12, "Dirichlet Poisson: u = 1 - x^2 - y^2 at the vertices (" .. maxerr .. ")")
T.is(tostring(Tor), "mesh of dimension 2 in R^3: 800 vertices, 2400 edges, 1600 triangles", "tostring of a mesh")
T.ok(Tor:well_centered(), "the acceptance torus is well-centred")
T.is(tostring(u):match("^primal 0%-cochain%[3169%]{"), "primal 0-cochain[3169]{", "tostring of a cochain")
T.is(tostring(D:d(0)), "sparse 9312x3169, 18624 nonzeros (d0: primal 0-cochains -> primal 1-cochains)",
  "tostring of an operator")
T.is(select(2, u:degree()), "primal", "cochain side")

-- generators
local G = dm.mesh.grid{n = 4}
T.ok(G:count(0) == 25 and G:count(1) == 56 and G:count(2) == 32, "grid 4 x 4 counts")
local S = dm.mesh.sphere{level = 1}
T.ok(S:count(0) == 42 and S:count(2) == 80 and select(3, S:betti()) == 1, "icosphere level 1")
local A = dm.mesh.annulus{r0 = 1, r1 = 2, n = 3, m = 18}
T.ok(select(2, A:betti()) == 1 and A:count(0) == 72, "annulus: b1 = 1")
local B = dm.mesh.box{n = 2}
local c = {B:betti()}
T.ok(#c == 4 and c[1] == 1 and c[2] == 0 and c[3] == 0 and c[4] == 0 and B:count(3) == 48, "box: 48 tets, b = 1 0 0 0")
local P = dm.mesh.path{x = {0, 1, 3}}
T.ok(P:count(1) == 2 and P:volumes(1)[2] == 2, "path with given points")
T.is(P:dim(), 1, "dimension of a path")

-- typed operators
local ok, err = pcall(function() return D:d(1) * f end)
T.ok(not ok and err:find("d1 %* cochain: the operator takes primal 1%-cochains, got a primal 0%-cochain"),
  "d(1) * 0-cochain names both degrees: " .. tostring(err))
T.error_like(function() return D:d(0) * D:d(0) end,
  "d0 %* d0: the left operator takes primal 0%-cochains, the right one gives primal 1%-cochains",
  "operator product with mismatched types")
T.error_like(function() return f + D:cochain(1, 0) end, "cochain %+ cochain: primal 0%-cochain and primal 1%-cochain",
  "cochain sum of mixed degrees")
T.error_like(function() return f + Tor:cochain(0, 0) end, "different meshes", "cochains of two meshes")
T.error_like(function() return f * f end, "wedge", "cochain * cochain points to the wedge product")
T.error_like(function() return D:laplacian(0):solve(f) end,
  "laplacian0:solve: matrix .* without a boundary condition the kernel holds the harmonic forms",
  "singular Laplacian explained")
T.error_like(function() return D:d(2) end, "bad argument #1 to 'd' %(degree in 0%.%.1 expected, got 2", "degree range")
T.error_like(function() return D:laplacian(0, {boundry = "dirichlet"}) end,
  "mesh:laplacian: unknown option 'boundry'", "misspelt option")
T.error_like(function() return D:laplacian(0, {boundary = "neumann"}) end,
  "boundary must be \"dirichlet\" or \"none\", got \"neumann\"", "unknown boundary condition")
T.error_like(function() return Tor:laplacian(0, {boundary = "dirichlet"}) end, "mesh without boundary",
  "Dirichlet on a closed surface")
T.error_like(function() return D:cochain(0, {1, 2}) end, "3169 values expected %(one per vertex%), got 2",
  "cochain of the wrong length")
T.error_like(function() return D:cochain(0, function() return "x" end) end, "function must return 1 number",
  "function returning a string")
T.error_like(function() return D:cochain(0, function() error("boom") end) end, "boom", "error in the user function")
T.error_like(function() return dm.mesh.torus{n = 10, m = 7} end, "an even m >= 4 around the tube", "odd tube count")
T.error_like(function() return dm.mesh.disc{rings = 3} end, "unknown option 'rings'", "generator option check")
T.error_like(function() return f[0] end, "cochain index 0 out of range 1%.%.3169", "cochain index")

-- stars and the dual derivative
local n = 2
for k = 0, 2 do
  local I = Tor:star(n - k, {dual = true}) * Tor:star(k)
  local sgn = (k * (n - k)) % 2 == 0 and 1 or -1
  local r, cc, v = I:triplets()
  local bad = 0
  for i = 1, #v do if r[i] == cc[i] then bad = math.max(bad, math.abs(v[i] - sgn)) else bad = math.max(bad, math.abs(v[i])) end end
  T.ok(bad < 1e-12 and #v == Tor:count(k), "** = " .. sgn .. " on " .. k .. "-cochains")
end
T.error_like(function() return Tor:star(1) * Tor:star(1) end, "the left operator takes primal 1%-cochains, the right one gives dual 1%-cochains",
  "star * star of the wrong sides")
do
  local r1, c1, v1 = Tor:dual_d(0):triplets()
  local r2, c2, v2 = Tor:d(1):t():triplets()
  local same = #v1 == #v2
  for i = 1, #v1 do same = same and r1[i] == r2[i] and c1[i] == c2[i] and v1[i] == v2[i] end
  T.ok(same, "dual d0 = d1^T in 2-D")
  T.error_like(function() return Tor:dual_d(0) - Tor:d(1):t() end,
    "operators of different types %(taking dual 0%-cochains and primal 2%-cochains%)", "typed difference refused")
end
-- d R(x dy) = triangle areas
local w = D:cochain(1, function(x, y) return 0, x end)
local dw, area = D:d(1) * w, D:volumes(2)
maxerr = 0
for i = 1, #dw do maxerr = math.max(maxerr, math.abs(dw[i] - area[i]) / area[i]) end
T.ok(maxerr < 1e-12, "d R(x dy) = area of every triangle (" .. maxerr .. ")")
local rho = D:cochain(2, function(x, y) return 1 end)
T.near(rho:sum(), D:volumes(2):sum(), 1e-14, "R(dx dy) sums to the area")

-- Dirichlet with boundary values: linear + |x|^2/2 (Delta0 exact on it) is reproduced
local g = function(x, y) return 2.385 * x - y + 0.5 * (x * x + y * y) end
local h = D:laplacian(0, {boundary = "dirichlet", value = g}):solve(D:cochain(0, -2))
local gc = D:cochain(0, g)
T.ok((h - gc):norm(math.huge) < 1e-12, "Dirichlet solve with boundary values reproduces a quadratic")

-- eigenpairs of the sphere
local vals, vecs = dm.mesh.sphere{level = 2}:eigen(0, 9)
T.ok(math.abs(vals[1]) < 1e-10 and math.abs(vals[2] - 1.9999905) < 1e-5 and math.abs(vals[9] - 5.865269) < 1e-5,
  "icosphere eigenvalues 0, 2, 6")
T.ok(#vecs == 9 and #vecs[2] == 162, "eigencochains")

-- the 4-cycle with unit edge lengths is a valid local metric (not embeddable with global distances)
local C4 = dm.mesh.new{simplices = {{1, 2}, {2, 3}, {3, 4}, {4, 1}}, lengths = {{1, 2, 1}, {2, 3, 1}, {3, 4, 1}, {4, 1, 1}}}
local c0, c1 = C4:betti()
T.ok(c0 == 1 and c1 == 1 and C4:volumes(1):sum() == 4, "intrinsic 4-cycle: b = 1 1, length 4")
T.is(tostring(C4), "mesh of dimension 1 (intrinsic): 4 vertices, 4 edges", "tostring of an intrinsic mesh")
T.error_like(function() return C4:vertices() end, "an intrinsic mesh has no coordinates", "intrinsic: no coordinates")
-- explicit meshes and their errors
local Tri = dm.mesh.new{vertices = {{0, 0}, {1, 0}, {0, 1}}, simplices = {{1, 2, 3}}}
T.is(Tri:star(0):get(1, 1), 0.25, "a triangle from tables")
T.near(Tri:dual_volumes(0)[1], 0.25, 1e-15, "right triangle: dual area at the right angle")
T.error_like(function() return dm.mesh.new{vertices = {{0, 0}, {1, 0}}, simplices = {{1, 2, 3}}} end,
  "dm.mesh.new: simplex 1: vertex 3 outside 1..2", "vertex out of range")
T.error_like(function() return dm.mesh.new{vertices = {{0, 0}, {1, 0}, {0, 0/0}}, simplices = {{1, 2, 3}}} end,
  "vertex 3, coordinate 2 is not finite", "NaN coordinate")
T.error_like(function() return dm.mesh.new{vertices = {{0, 0}, {1, 0}, {2, 0}}, simplices = {{1, 2, 3}}} end,
  "degenerate 2%-simplex %(1,2,3%)", "degenerate triangle")
T.error_like(function() return dm.mesh.new{vertices = {{0, 0}, {1, 0}, {0, 1}, {1, 1}}, simplices = {{1, 2, 3}, {1, 2, 4}, {2, 3, 4}}}:check() end,
  "inconsistent orientation", "check finds an orientation defect")
T.ok(dm.mesh.new{vertices = {{0, 0}, {1, 0}, {0, 1}, {1, 1}}, simplices = {{1, 2, 3}, {2, 4, 3}}}:check(), "consistent pair passes check")

-- plain sparse matrices
local M = dm.sparse(3, 3, {{1, 1, 4}, {2, 2, 5}, {3, 3, 6}, {1, 3, 1}, {3, 1, 1}, {1, 1, 0.5}})
T.is(M:get(1, 1), 4.5, "duplicates summed")
local x = M:solve{1, 2, 3}
local Mx = M * x
T.ok(math.abs(Mx[1] - 1) < 1e-14 and math.abs(Mx[3] - 3) < 1e-14, "UMFPACK solve of a plain matrix")
T.is(tostring(M), "sparse 3x3, 5 nonzeros", "tostring of a plain matrix")
T.error_like(function() return dm.sparse(2, 2, {{3, 1, 1}}) end, "entry 1: index %(3, 1%) outside 2 x 2", "triplet out of range")
T.error_like(function() return M * {1, 2} end, "vector of length 3 expected, got length 2", "matrix times short vector")

-- a warning on stderr, once per mesh and degree, for non-positive duals
local exe = os.getenv("DMECH")
if exe then
  local cmd = exe .. [[ -e 'local M = dm.mesh.new{vertices = {{0,0},{2,0},{1,0.4},{1,-0.4}}, simplices = {{1,2,3},{2,1,4}}}; M:laplacian(0); M:laplacian(0); M:star(1)' 2>&1]]
  local p = io.popen(cmd)
  local out = p:read("a")
  p:close()
  local _, count = out:gsub("dmech: warning:", "")
  T.ok(out:find("dmech: warning: 2 vertices of this mesh have non%-positive dual volume %(not Delaunay there%): %*0 is indefinite")
       and out:find("1 edge of this mesh has non%-positive dual volume") and count == 2,
       "non-Delaunay mesh: one warning per degree on stderr")
else
  T.skip("DMECH not set")
end
T.done()
