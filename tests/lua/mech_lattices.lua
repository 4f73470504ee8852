-- mech_lattices.lua -- the large-system catalog entries (dm.systems.fpu,
-- toda, toda_integrals, nbody, string): their physics checked on small
-- instances -- conserved momenta to round-off, the Toda integrals tr L^k
-- (tr L^2 = H b/(2a) exactly, all four bounded over a Gauss run, also for
-- other a, b, m), N-body momentum and angular momentum conserved by Gauss
-- to round-off, the string's lowest frequency against the discrete wave
-- equation; and their option errors.
local T = require "dmech.test"
local dm = require "dmech"
dm.config.native = "never"        -- the physics here, not the compiler

-- FPU-beta, periodic: total momentum conserved (translations), energy bounded
local n = 12
local fpu = dm.systems.fpu{n = n, beta = 1.5, alpha = 0.25, ends = "periodic"}
local q, v = {}, {}
for i = 1, n do q[i] = 0.3 * math.sin(2 * math.pi * i / n); v[i] = 0.1 * math.cos(i) end
local tr = dm.integrator(fpu, {method = "trapezoid", h = 0.02}):run({q = q, v = v}, {steps = 3000, every = 30})
local P0, P1 = 0, 0
for i = 1, n do P0 = P0 + tr.p.x[i][1]; P1 = P1 + tr.p.x[i][#tr] end
T.near(P1, P0, 1e-13, "FPU periodic, Stormer-Verlet: total momentum conserved")
T.conserved(tr, "energy", 2e-3, "FPU: energy bounded")
local fixed = dm.systems.fpu{n = 4, beta = 1}
T.near(fixed:energy{q = {0.1, 0.2, 0.3, 0.4}, v = {0, 0, 0, 0}},
       0.5 * (0.01 + 0.01 * 3 + 0.16) + 0.25 * (1e-4 + 3e-4 + 0.0256), 1e-15,
       "FPU fixed ends: the potential of the stretches x1, x2-x1, ..., -x4")

-- Toda: 2 tr L^2 = H/a, and the integrals bounded over a Gauss run
local function toda_run(o, steps)
  local sys = dm.systems.toda{n = o.n, a = o.a, b = o.b, m = o.m}
  local qq, vv = {}, {}
  for i = 1, o.n do qq[i] = 0.2 * math.sin(1.3 * i); vv[i] = 0.4 * math.cos(2.385 * i) end
  return sys, dm.integrator(sys, {method = "gauss", stages = 2, h = 0.02}):run({q = qq, v = vv},
    {steps = steps, every = steps // 10})
end
local function integrals(tr, k, o)
  local qq, pp = {}, {}
  for i = 1, #tr.q.x do qq[i] = tr.q.x[i][k]; pp[i] = tr.p.x[i][k] end
  return dm.systems.toda_integrals(qq, pp, 4, o)
end
for _, o in ipairs{{n = 10, a = 1, b = 1, m = 1}, {n = 9, a = 2, b = 0.5, m = 1.5}} do
  local sys, trt = toda_run(o, 1000)
  local E = trt:energy()
  local I0, I1 = integrals(trt, 1, o), integrals(trt, #trt, o)
  T.near(2 * I0[2], E[1] * o.b / o.a, 1e-13, ("Toda a=%g b=%g m=%g: 2 tr L^2 = H b/a"):format(o.a, o.b, o.m))
  local worst = 0
  for k = 1, 4 do worst = math.max(worst, math.abs(I1[k] - I0[k]) / math.max(1, math.abs(I0[k]))) end
  T.ok(worst < 1e-6, ("Toda a=%g b=%g m=%g: tr L, tr L^2, tr L^3, tr L^4 conserved over 1000 "
    .. "Gauss steps (rel. change %.2g)"):format(o.a, o.b, o.m, worst))
end

-- N-body: Gauss keeps linear and angular momentum (quadratic invariants)
for _, dim in ipairs{2, 3} do
  local nb = dm.systems.nbody{n = 4, dim = dim, masses = {1, 0.5, 2, 1.5}, soft = 0.1}
  local st = {q = {}, v = {}}
  local axes = dim == 2 and {"x", "y"} or {"x", "y", "z"}
  for _, a in ipairs(axes) do
    st.q[a], st.v[a] = {}, {}
    for i = 1, 4 do
      st.q[a][i] = math.cos(1.7 * i + #a) * (1 + 0.3 * i)
      st.v[a][i] = 0.3 * math.sin(2.385 * i - #a)
    end
  end
  local trn = dm.integrator(nb, {method = "gauss", stages = 2, h = 0.01}):run(st, {steps = 500, every = 50})
  local function moments(k)
    local P, Lz = {0, 0, 0}, 0
    for i = 1, 4 do
      for c, a in ipairs(axes) do P[c] = P[c] + trn.p[a][i][k] end
      Lz = Lz + trn.q.x[i][k] * trn.p.y[i][k] - trn.q.y[i][k] * trn.p.x[i][k]
    end
    return P, Lz
  end
  local P0b, L0 = moments(1)
  local P1b, L1 = moments(#trn)
  T.ok(math.abs(P1b[1] - P0b[1]) < 1e-13 and math.abs(P1b[2] - P0b[2]) < 1e-13 and
       math.abs(L1 - L0) < 1e-13, ("%d-body %d-D, Gauss 2: momentum and angular momentum "
       .. "conserved (dLz %.2g)"):format(4, dim, L1 - L0))
end

-- string: the lowest mode's period against the discrete wave equation
local ns, Ls, tension, density = 15, 2, 3, 0.75
local str = dm.systems.string{n = ns, length = Ls, tension = tension, density = density}
local dx, c = Ls / (ns + 1), math.sqrt(tension / density)
local omega = 2 * c / dx * math.sin(math.pi * dx / (2 * Ls))    -- discrete mode 1
local amp, u0, rest = 1e-4, {}, {}
for i = 1, ns do
  u0[i] = amp * math.sin(math.pi * i * dx / Ls)
  rest[i] = 0
end
local h = 2 * math.pi / omega / 400
local trs = dm.integrator(str, {method = "gauss", stages = 2, h = h}):run({q = {u = u0}, v = {u = rest}},
  {steps = 400, every = 400})
local mid = trs.q.u[(ns + 1) // 2]
T.near(mid[#trs] / mid[1], 1, 1e-5, ("string: after one period of the discrete lowest mode "
  .. "(omega %.6g) the midpoint is back (small amplitude)"):format(omega))

-- options
T.error_like(function() dm.systems.fpu{n = 1} end, "n must be an integer >= 2", "fpu: n")
T.error_like(function() dm.systems.toda{ends = "open"} end, "ends must be", "toda: ends")
T.error_like(function() dm.systems.nbody{n = 3, dim = 4} end, "dim must be 2 or 3", "nbody: dim")
T.error_like(function() dm.systems.nbody{n = 3, masses = {1, 2}} end, "masses must be a list of 3",
             "nbody: masses")
T.error_like(function() dm.systems.string{n = 0} end, "n must be an integer >= 1", "string: n")
T.error_like(function() dm.systems.string{tension = "taut"} end, "must be a number", "string: a parameter")
T.done()
