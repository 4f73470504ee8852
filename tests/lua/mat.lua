-- mat.lua -- dm.mat: construction, row views, products (BLAS), LU, eigen, errors.
local T = require "dmech.test"
local dm = require "dmech"

local A = dm.mat{{4.2, -1.2, 0.5}, {-1.2, 3.2, -2}, {0.5, -2, 6.1}}
T.is(#A, 3, "#m is the number of rows")
T.ok(A:rows() == 3 and A:cols() == 3, "rows and cols")
T.is(A[2][3], -2, "m[i][j] reads")
A[1][2] = -1.25
T.is(A:get(1, 2), -1.25, "m[i][j] = x writes through the row view")
A:set(1, 2, -1.2)
T.is(A[1][2], -1.2, "m:set")
local row = A[3]
A = nil
collectgarbage(); collectgarbage()
T.is(row[3], 6.1, "a row view keeps its matrix alive")
A = dm.mat{{4.2, -1.2, 0.5}, {-1.2, 3.2, -2}, {0.5, -2, 6.1}}

local Z = dm.mat(2, 3)
T.ok(Z:rows() == 2 and Z:cols() == 3 and Z[2][3] == 0, "dm.mat(r, c) is zero")
T.ok(dm.eye(3) == dm.mat{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, "eye")
T.ok(dm.diag{2, 3} == dm.mat{{2, 0}, {0, 3}}, "diag")
T.ok(dm.mat(A) == A, "copy equals")
T.ok(A:t() == A, "symmetric matrix equals its transpose")
local B = dm.mat{{1.5, 2}, {-0.5, 3}, {2.385, 1}}
T.ok(B:t():rows() == 2 and B:t()[2][3] == 1, "transpose of a 3x2")
T.near(A:trace(), 4.2 + 3.2 + 6.1, 1e-15, "trace")
T.near(dm.mat{{3, 4}, {0, 0}}:norm(), 5, 1e-15, "Frobenius norm")

-- products through BLAS against explicit sums
local C = A * B
local s = 0
for k = 1, 3 do s = s + A[2][k] * B[k][1] end
T.near(C[2][1], s, 1e-15, "mat * mat element")
local x = dm.vec{1.5, -0.75, 2.385}
local y = A * x
T.near(y[3], 0.5 * 1.5 + (-2) * (-0.75) + 6.1 * 2.385, 1e-14, "mat * vec")
local z = x * B
T.near(z[2], 1.5 * 2 + (-0.75) * 3 + 2.385 * 1, 1e-15, "vec * mat is the row product")
T.ok((A + A) == A * 2 and (2 * A) == A * 2, "mat + mat and scaling")
T.ok((A - A) == dm.mat(3, 3), "mat - mat")
T.ok((-A) == A * -1 and (A / 2) == A * 0.5, "unary minus and division")

-- LU: det, inverse, solve
local det = 4.2 * (3.2 * 6.1 - 4) + 1.2 * (-1.2 * 6.1 + 1) + 0.5 * (2.4 - 1.6)
T.near(A:det(), det, 1e-13, "determinant")
local I = A * A:inv()
local err = 0
for i = 1, 3 do for j = 1, 3 do err = math.max(err, math.abs(I[i][j] - (i == j and 1 or 0))) end end
T.ok(err < 1e-15, string.format("A * A:inv() = I (max error %.1e)", err))
local b = dm.vec{0.5, -1.25, 2}
local sol = A:solve(b)
T.ok((A * sol - b):norm() < 1e-15, "solve residual")
T.ok((A:solve{0.5, -1.25, 2} - sol):norm() == 0, "solve accepts a table")

-- symmetric eigenproblem
local vals, vecs = A:eig()
T.ok(vals[1] <= vals[2] and vals[2] <= vals[3], "eigenvalues ascending")
local worst = 0
for j = 1, 3 do
  local v = vecs:col(j)
  worst = math.max(worst, (A * v - v * vals[j]):norm())
end
T.ok(worst < 1e-14, string.format("eigenpairs (residual %.1e)", worst))
local VtV = vecs:t() * vecs
T.near(VtV[1][2], 0, 1e-15, "eigenvectors orthonormal")
T.near(vals[1] + vals[2] + vals[3], A:trace(), 1e-14, "sum of eigenvalues = trace")

T.is(tostring(dm.mat{{1, -2.5}, {30, 4}}), "mat{{   1, -2.5},\n    {  30,    4}}", "aligned tostring")
local tt = B:totable()
T.ok(#tt == 3 and tt[3][1] == 2.385, "totable")

-- errors
T.error_like(function() return dm.mat() end, "bad argument #1 to 'mat' %(size, table of rows or mat expected, got no value%)", "no arguments")
T.error_like(function() return dm.mat(0, 2) end, "bad argument #1 to 'mat' %(positive number of rows expected%)", "zero rows")
T.error_like(function() return dm.mat{{1, 2}, {3}} end, "rows of equal length expected, row 2 has 1, row 1 has 2", "ragged rows")
T.error_like(function() return dm.mat{{1, 2}, "x"} end, "table of rows expected, got string at row 2", "bad row")
T.error_like(function() return dm.mat{1, 2} end, "bad argument #1 to 'mat'", "flat table")
T.error_like(function() return A * dm.mat(2, 2) end, "inner dimensions differ %(3x3 times 2x2%)", "product shapes")
T.error_like(function() return A * dm.vec(2) end, "3x3 matrix times vector of length 2", "mat * vec length")
T.error_like(function() return dm.vec(2) * A end, "vector of length 2 times 3x3 matrix", "vec * mat length")
T.error_like(function() return A + B end, "shapes differ %(3x3 and 3x2%)", "sum shapes")
T.error_like(function() return A[4] end, "mat row 4 out of range 1%.%.3", "row out of range")
T.error_like(function() return A:get(1, 4) end, "mat index %(1, 4%) out of range %(3x3%)", "get out of range")
T.error_like(function() A[1] = 2 end, "assign elements with m%[i%]%[j%]", "row assignment")
T.error_like(function() return B:det() end, "det: square matrix expected, got 3x2", "det of non-square")
T.error_like(function() return dm.mat{{1, 2}, {2, 4}}:inv() end, "inv: matrix is singular", "singular inverse")
T.error_like(function() return dm.mat{{1, 2}, {2, 4}}:solve{1, 1} end, "solve: matrix is singular", "singular solve")
T.is(dm.mat{{1, 2}, {2, 4}}:det(), 0, "singular determinant is 0")
T.error_like(function() return dm.mat{{1, 2}, {3, 4}}:eig() end, "eig: symmetric matrix expected", "non-symmetric eig")
T.error_like(function() return A:solve{1, 2} end, "bad argument #1 to 'solve' %(vector of length 3 expected, got length 2%)", "solve length")
T.error_like(function() return A:col(0) end, "mat column 0 out of range", "col out of range")
T.error_like(function() return A / A end, "only division by a number", "mat / mat")
T.done()
