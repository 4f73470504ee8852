-- dec_ops.lua -- mesh files, wedge, flat/sharp, contraction, homotopy,
-- moved meshes, refinement and multigrid through the Lua surface.
local T = require "dmech.test"
local dm = require "dmech"
local data = (os.getenv("DMECH_SRCDIR") or ".") .. "/tests/data/dec/"
local tmp = T.tmpdir("dec_ops")

-- files shipped with the tests
local sq2, sq4 = dm.mesh.load(data .. "square_v2.msh"), dm.mesh.load(data .. "square_v4.msh")
T.ok(sq2:count(2) == 26 and sq4:count(2) == 26 and select(2, sq2:dim()) == 2, "Gmsh 2.2 and 4.1 squares: 26 triangles, planar")
T.near(sq4:volumes(2):sum(), 1, 1e-14, "the square has area 1")
local tet = dm.mesh.load(data .. "tet.off")
local b0, b1, b2 = tet:betti()
T.ok(b0 == 1 and b1 == 0 and b2 == 1 and tet:check(), "OFF tetrahedron surface is a sphere")
T.is(dm.mesh.load(data .. "quad.obj"):count(2), 2, "OBJ with normals and relative indices")
local function loaderr(f) local ok, err = pcall(dm.mesh.load, data .. f); return not ok and err:gsub("^.*/", "") or "no error" end
T.is(loaderr("bad_vertex.off"), "bad_vertex.off:6: vertex 7 does not exist (vertices are numbered from 0)", "missing vertex")
T.is(loaderr("bad_nan.obj"), "bad_nan.obj:2: coordinate y is not a finite number", "NaN coordinate")
T.is(loaderr("bad_orient2.obj"), "bad_orient2.obj:6: inconsistent orientation: shares edge (1,3) with the simplex on line 5 in the same direction", "inconsistent orientation")
T.is(loaderr("bad_nonmanifold.off"), "bad_nonmanifold.off:9: non-manifold edge (1,2): more than two simplices share it (also line 8)", "non-manifold edge")
T.is(loaderr("bad_quad.off"), "bad_quad.off:7: face with 3 vertices expected (only triangles are supported)", "quadrilateral")
T.is(loaderr("bad_node.msh"), "bad_node.msh:12: node 9 does not exist", "missing node")
-- Gmsh itself, when installed: a disc in both formats
if os.execute("command -v gmsh > /dev/null 2>&1") then
  local geo = tmp .. "/disc.geo"
  local f = assert(io.open(geo, "w"))
  f:write("SetFactory(\"OpenCASCADE\");\nDisk(1) = {0, 0, 0, 1};\nMeshSize{:} = 0.2;\n")
  f:close()
  for _, fmt in ipairs{"msh22", "msh41"} do
    local out = tmp .. "/disc_" .. fmt .. ".msh"
    os.execute("gmsh -2 -format " .. fmt .. " " .. geo .. " -o " .. out .. " > /dev/null 2>&1")
    local G = dm.mesh.load(out)
    T.ok(G:betti() == 1 and math.abs(G:volumes(2):sum() - math.pi) < 0.05, "gmsh " .. fmt .. " disc: area " .. G:volumes(2):sum())
  end
else
  T.skip("gmsh not installed")
  T.skip("gmsh not installed")
end
-- save and load back
local S = dm.mesh.sphere{level = 1}
for _, ext in ipairs{"off", "obj", "msh"} do
  local p = tmp .. "/s." .. ext
  S:save(p)
  local S2 = dm.mesh.load(p)
  T.ok(S2:count(2) == 80 and math.abs(S2:volumes(2):sum() - S:volumes(2):sum()) < 1e-15, "save/load ." .. ext)
end
T.error_like(function() S:save(tmp .. "/s.stl") end, "unknown mesh format '%.stl'", "unknown format on save")

-- wedge: Leibniz rule for the barycentric weights on a box
local B = dm.mesh.box{n = 2}
local a = B:cochain(1, function(x, y, z) return y * z, x + z * z, x * y end)
local b = B:cochain(1, function(x, y, z) return 1 + z, x * x, y end)
local lhs = B:d(2) * B:wedge(a, b)
local rhs = B:wedge(B:d(1) * a, b) - B:wedge(a, B:d(1) * b)
T.ok((lhs - rhs):norm(math.huge) < 1e-14, "d(a ^ b) = da ^ b - a ^ db (barycentric)")
T.ok((B:wedge(a, b) + B:wedge(b, a)):norm(math.huge) < 1e-15, "a ^ b = -b ^ a")
T.error_like(function() return B:wedge(a, b, {weights = "mean"}) end, "weights must be \"barycentric\" or \"circumcentric\"", "unknown weights")
T.error_like(function() return B:wedge(B:wedge(a, b), B:wedge(a, b)) end, "degrees 2 %+ 2 exceed the dimension 3", "degree overflow")

-- flat and sharp
local D = dm.mesh.disc{n = 6}
local fl = D:flat(function(x, y) return 2.385, -0.5 end)
local V = D:sharp(fl)
T.ok(math.abs(V[1][1] - 2.385) < 1e-13 and math.abs(V[7][2] + 0.5) < 1e-13, "sharp(flat(X)) = X")
T.ok((D:d(1) * fl):norm(math.huge) < 1e-14, "flat of a constant field is closed")

-- contraction of the area form with a constant field; Lie derivative
local mu = D:cochain(2, D:dual_volumes(0), {dual = true})
local ix = D:contract({1, 0}, mu)
T.is(select(2, ix:degree()), "dual", "contraction gives a dual cochain")
local L = D:lie({1, 0}, mu)
local inner = 0
for i = 1, #L do if D:boundary(0)[i] == 0 then inner = math.max(inner, math.abs(L[i])) end end
T.ok(inner < 1e-14, "L_X of the area form vanishes inside for constant X")

-- Poincare lemma through the homotopy operator
local H, apex = D:homotopy(1)
local f0 = D:cochain(0, function(x, y) return math.sin(3 * x) + y * y end)
local g = H * (D:d(0) * f0)
T.ok(math.abs(g[apex]) < 1e-15 and (D:d(0) * g - D:d(0) * f0):norm(math.huge) < 1e-13, "H(df) = f - f(apex), d H df = df")
T.error_like(function() return dm.mesh.annulus{}:homotopy(1) end, "no collapse to a point", "annulus is not collapsible")

-- the dual-dual wedge only behind its flag
local da = D:cochain(1, function(x, y) return y, x * x end)
local dua, dub = D:star(1) * da, D:star(1) * (D:d(0) * f0)
T.error_like(function() return D:wedge(dua, dub) end, "pass {dual_dual = true}", "dual-dual wedge needs its flag")
T.ok((D:wedge(dua, dub, {dual_dual = true}) + D:wedge(dub, dua, {dual_dual = true})):norm(math.huge) < 1e-13,
  "dual-dual wedge of 1-forms is anti-commutative")

-- discrete maps: cochains move along, d commutes, geometry changes
local M2 = D:moved(function(x, y) return 1.5 * x + 0.2 * y, 0.8 * y + 0.1 end)
local fm = M2:cochain(0, f0)
T.ok((M2:d(0) * fm):norm() == (D:d(0) * f0):norm(), "pull-back commutes with d (same values)")
local J = D:push({1, 0}, M2)
T.ok(math.abs(J[1][1] - 1.5) < 1e-14 and math.abs(J[1][2]) < 1e-14, "push-forward of e1 by the affine map")

-- nested refinement and multigrid
local F1 = D:refine()
local F = F1:refine()
local c0 = F:cochain(0, function(x, y) return (x * 7 + y * 3) // 1 end)
T.ok((F:restrict(F:d(0) * c0) - F1:d(0) * F:restrict(c0)):norm() == 0, "restriction commutes with d")
local u, cycles = F:mg_solve(F:cochain(0, 4))
local ref = F:laplacian(0, {boundary = "dirichlet"}):solve(F:cochain(0, 4))
T.ok((u - ref):norm(math.huge) < 1e-9 and cycles < 15, "multigrid = CHOLMOD in " .. cycles .. " V-cycles")
T.error_like(function() return D:mg_solve(D:cochain(0, 1)) end, "was not made by mesh:refine", "multigrid needs a refinement chain")

-- pictures: dm.plot_mesh writes a PNG (gnuplot needed)
if os.execute("command -v gnuplot > /dev/null 2>&1") then
  local png = tmp .. "/mesh.png"
  dm.plot_mesh{D, values = f0, arrows = D:d(0) * f0, output = png}
  local fh = io.open(png, "rb")
  T.ok(fh ~= nil and #fh:read("a") > 1000, "plot_mesh writes a PNG")
  if fh then fh:close() end
  dm.plot_mesh{S, values = S:cochain(0, function(x, y, z) return z end), output = tmp .. "/sphere.png"}
  T.ok(io.open(tmp .. "/sphere.png") ~= nil, "plot_mesh of a surface in R^3")
else
  T.skip("gnuplot not installed")
  T.skip("gnuplot not installed")
end
T.error_like(function() dm.plot_mesh{D, colour = 1} end, "dm.plot_mesh: unknown option 'colour'", "plot_mesh option check")
T.error_like(function() dm.plot_mesh{B, values = B:cochain(0, 1)} end, "triangle meshes in R%^2 or R%^3 only", "plot_mesh refuses tetrahedra")
T.error_like(function() dm.plot_mesh{D, values = S:cochain(0, 1)} end, "the cochain lives on another mesh", "plot_mesh: cochain of another mesh")
T.done()
