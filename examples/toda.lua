-- toda.lua -- a periodic Toda lattice integrated with Gauss s = 2: the energy
-- error and the lattice's other conserved quantities, the traces of the
-- powers of its Lax matrix, stay bounded over the whole run.
--
--   src/dmech examples/toda.lua [n [steps [output.png]]]
--
-- Defaults n = 1024 particles, 20 000 steps of h = 0.05 (a few seconds
-- native); `src/dmech examples/toda.lua 4096 100000` is the large run
-- (4096 coordinates, 10^5 steps: a few minutes).  The system is the
-- catalog's dm.systems.toda (coordinates x[1..n], L = sum v_i^2/2 - sum over
-- the bonds of exp(-(x_{i+1} - x_i)), a ring), defined at once on the tape
-- while its native code compiles in the background; the run streams its
-- samples to a function, which evaluates dm.systems.toda_integrals (tr L^k,
-- k = 1..4, in Flaschka's variables: tr L^2 = H/2) and keeps only those.
-- The plot shows |E - E0| / |E0| and, for k = 3, 4, |tr L^k - initial|
-- measured against the size a sum of n k-th powers has here,
-- n (tr L^2 / n)^(k/2): the odd traces of this nearly symmetric state are
-- close to zero, and an error relative to them would say nothing.  tr L^2
-- is H/2, its curve the energy's; tr L (the total momentum) is conserved to
-- round-off.
local dm = require "dmech"

local n = tonumber(arg and arg[1]) or 1024
local steps = tonumber(arg and arg[2]) or 20000
local output = (arg and arg[3]) or "toda.png"
local h = 0.05
local samples = 200

local sys = dm.systems.toda{n = n}
print(sys)

-- a smooth wave plus a few random-looking kicks; zero total momentum
local q, p = {}, {}
for i = 1, n do
  q[i] = 0.4 * math.sin(2 * math.pi * i / n) + 0.1 * math.sin(17.3 * i)
  p[i] = 0.3 * math.cos(2 * math.pi * 3 * i / n) + 0.05 * math.cos(5.1 * i)
end
local mean = 0
for i = 1, n do mean = mean + p[i] / n end
for i = 1, n do p[i] = p[i] - mean end

local I = dm.integrator(sys, {method = "gauss", stages = 2, h = h})
local E0 = sys:energy{q = q, p = p}
local J0 = dm.systems.toda_integrals(q, p, 4)
local scale = {}                         -- n (tr L^2 / n)^(k/2)
for k = 1, 4 do scale[k] = n * (J0[2] / n)^(k / 2) end

-- the samples go to this function in blocks; only the integrals are kept
local t, dE, dJ = {}, {}, {{}, {}, {}, {}}
local function sink(tr)
  local qs, ps = tr.q.x, tr.p.x
  for k = 1, #tr do
    local qk, pk = {}, {}
    for i = 1, n do qk[i], pk[i] = qs[i][k], ps[i][k] end
    local J = dm.systems.toda_integrals(qk, pk, 4)
    t[#t + 1] = tr.t[k]
    dE[#dE + 1] = math.abs(tr:column("energy")[k] - E0) / math.abs(E0)
    for j = 1, 4 do dJ[j][#dJ[j] + 1] = math.abs(J[j] - J0[j]) / scale[j] end
  end
end

local clock = os.clock()
local last, msg = I:run({q = q, p = p}, {steps = steps, every = math.max(1, steps // samples),
                                        sink = sink, sink_every = 50})
local secs = os.clock() - clock
assert(last, msg)
local function max(x) local m = 0; for _, v in ipairs(x) do m = math.max(m, v) end; return m end
print(("%d particles, %d steps of h = %g in %.1f s (%.1f us/step; %s)"):format(n, steps, h, secs,
  secs / steps * 1e6, sys.native and "native code" or "tape"))
print(("max |E - E0|/|E0| = %.2e"):format(max(dE)))
for j = 1, 4 do
  print(("max |tr L^%d - initial| / (n (tr L^2/n)^%g) = %.2e"):format(j, j / 2, max(dJ[j])))
end
print(("Newton or fixed-point sweeps per step: %.2f"):format(I.stats.iters_total / I.stats.steps))

local floor = 1e-17                      -- log scale: zeros drawn at the floor
local function clip(x) local y = {}; for i, v in ipairs(x) do y[i] = math.max(v, floor) end; return y end
dm.plot{
  {t, clip(dE), with = "lines lw 2", legend = "energy H = 2 tr L^2"},
  {t, clip(dJ[3]), with = "lines", legend = "tr L^3"},
  {t, clip(dJ[4]), with = "lines", legend = "tr L^4"},
  title = ("periodic Toda lattice, n = %d, Gauss s = 2, h = %g: relative errors of the "
           .. "conserved quantities"):format(n, h),
  xlabel = "t", ylabel = "relative error", logscale = "y", yrange = {floor, 1e-6},
  size = {1100, 520}, output = output}
print("wrote " .. output)
