-- mech_catalog.lua -- every system of dm.systems: documented, stepped
-- briefly with its energy bounded, and checked against independent values:
-- the corrected J2 potential (doc/reduce.md §13), the same motion in two
-- coordinate systems, the locked inertia and mechanical connection of the
-- double spherical pendulum (doc/reduce.md §14), the built-in C versions.
local T = require "dmech.test"
local dm = require "dmech"

local byname = dm.docs()
local names = {}
for k in pairs(dm.systems) do names[#names + 1] = k end
table.sort(names)
local undocumented = {}
for _, k in ipairs(names) do
  local rec = byname["dm.systems." .. k]
  if not (rec and #rec.doc > 40) then undocumented[#undocumented + 1] = k end
end
T.ok(#names >= 12 and #undocumented == 0, ("%d catalog systems, each documented with its physics%s"):format(
     #names, #undocumented > 0 and (": missing " .. table.concat(undocumented, ", ")) or ""))

-- max |E - E0| over a run
local function drift(sys, o, s, steps)
  local tr = dm.integrator(sys, o):run(s, {steps = steps})
  local E, d = tr:energy(), 0
  for k = 1, #tr do d = math.max(d, math.abs(E[k] - E[1])) end
  return d, tr
end

-- harmonic oscillator: Gauss conserves the quadratic energy to round-off
local d = drift(dm.systems.harmonic{omega = 2.385}, {method = "gauss", stages = 2, h = 0.1}, {q = {0.7}, v = {0.3}}, 500)
T.ok(d < 1e-14, ("harmonic, Gauss 2: energy conserved to round-off (%.2g)"):format(d))

-- pendulum (g = l = m = 1) = the built-in pendulum
local pt = dm.integrator(dm.systems.pendulum{g = 1}, {method = "gauss", stages = 3, h = 0.1}):step{q = {1}, p = {0.5}}
T.ok(math.abs(pt.q[1] - 1.0457503205397358305) < 1e-13, "pendulum{g=1}: the one-step Gauss 3 reference value")
d = drift(dm.systems.pendulum{l = 0.8}, {method = "trapezoid", h = 0.01}, {q = {2.385}, v = {0}}, 1000)
T.ok(d < 1e-2 * 9.81 * 0.8, ("pendulum g=9.81 l=0.8, Stormer-Verlet: energy bounded (%.2g)"):format(d))

-- Kepler in 3-D and in polar coordinates
d = drift(dm.systems.kepler{dim = 3}, {method = "gauss", stages = 2, h = 0.05}, {q = {0.4, 0, 0.1}, p = {0, 2, 0.3}}, 300)
T.ok(d < 1e-4, ("Kepler 3-D, Gauss 2: energy bounded (%.2g)"):format(d))
local pol = dm.systems.kepler_polar()
T.near(pol:energy{q = {0.4, 0.3}, v = {0, 5}}, dm.systems.kepler():energy{q = {0.4 * math.cos(0.3), 0.4 * math.sin(0.3)}, v = {-2 * math.sin(0.3), 2 * math.cos(0.3)}}, 1e-15, "Kepler: polar and Cartesian energies agree")
d = drift(pol, {method = "lobatto", stages = 3, h = 0.05}, {q = {0.4, 0}, v = {0, 5}}, 300)
T.ok(d < 1e-4, ("Kepler polar, Lobatto 3: energy bounded (%.2g)"):format(d))

-- J2: the corrected potential, bound orbits, two coordinate systems
local j2, j2c = dm.systems.j2{J2 = 0.05}, dm.systems.j2_cylindrical{J2 = 0.05}
local x, y, z = 1.5, 0.4, 0.3
local R = math.sqrt(x^2 + y^2 + z^2)
local V = -1 / R + 0.05 / R^3 * (3 * z^2 / (2 * R^2) - 0.5)
T.near(j2:energy{q = {x, y, z}, v = {0, 0, 0}}, V, 1e-15, "J2: V = -1/|q| + (J2/|q|^3)(3 z^2/(2|q|^2) - 1/2) (corrected sign)")
T.near(j2c:energy{q = {math.sqrt(x^2 + y^2), 0.7, z}, v = {0, 0, 0}}, V, 1e-15, "J2 cylindrical: the same potential")
T.near(j2:energy{q = {x, y, z}, v = {0.1, 0.2, 0.3}}, dm.systems.j2{J2 = 0.05, impl = "c"}:energy{q = {x, y, z}, v = {0.1, 0.2, 0.3}}, 1e-15,
       "J2 catalog = built-in C")
local rmin, rmax = math.huge, 0
d, tr = drift(j2, {method = "gauss", stages = 2, h = 0.05}, {q = {2, 0, 0.3}, v = {0, 0.6, 0.1}}, 2000)
local X, Y, Z = tr:column("x"), tr:column("y"), tr:column("z")
for k = 1, #tr do
  local r = math.sqrt(X[k]^2 + Y[k]^2 + Z[k]^2)
  rmin, rmax = math.min(rmin, r), math.max(rmax, r)
end
T.ok(d < 1e-5 and rmin > 0.5 and rmax < 2.5, ("J2 orbit bound (r in [%.3f, %.3f]), energy error %.2g"):format(rmin, rmax, d))
local rc = dm.integrator(j2c, {method = "gauss", stages = 2, h = 0.05}):run({q = {2, 0, 0.3}, v = {0, 0.3, 0.1}}, {steps = 2000})
local dz = math.abs(rc:column("z")[#rc] - Z[#tr])
T.ok(dz < 1e-5, ("J2 in cylindrical coordinates follows the Cartesian orbit (z differs by %.2g after 100 time units)"):format(dz))
T.ok(math.abs(rc:momentum("theta")[#rc] - 4 * 0.3) < 1e-13, "J2 cylindrical: J = r^2 thetadot conserved")

-- Henon-Heiles below the escape energy 1/6
local hh = dm.systems.henon_heiles()
local s = {q = {0.1, -0.2}, v = {0.3, 0.25}}
local E0 = hh:energy{q = s.q, v = s.v}
d = drift(hh, {method = "composition", order = 6, h = 0.05}, s, 2000)
T.ok(E0 < 1 / 6 and d < 1e-6, ("Henon-Heiles (E = %.4f < 1/6): composition 6 energy error %.2g"):format(E0, d))

-- spherical pendulum: angles, R^3, the built-in
local sp, sp3 = dm.systems.spherical_pendulum{l = 1.3, m = 2}, dm.systems.spherical_pendulum_r3{l = 1.3, m = 2}
local th, ph, thd, phd = 1.2, 0.3, 0.5, 1.5
local qc = {1.3 * math.sin(th) * math.cos(ph), 1.3 * math.sin(th) * math.sin(ph), -1.3 * math.cos(th)}
local vc = {1.3 * (math.cos(th) * math.cos(ph) * thd - math.sin(th) * math.sin(ph) * phd),
            1.3 * (math.cos(th) * math.sin(ph) * thd + math.sin(th) * math.cos(ph) * phd), 1.3 * math.sin(th) * thd}
T.near(sp:energy{q = {th, ph}, v = {thd, phd}}, sp3:energy{q = qc, v = vc}, 1e-14, "spherical pendulum: angles and R^3 energies agree")
T.near(dm.systems.spherical_pendulum{l = 1.3}:energy{q = {th, ph}, v = {thd, phd}},
       dm.systems.spherical_pendulum{l = 1.3, impl = "c"}:energy{q = {th, ph}, v = {thd, phd}}, 1e-14, "spherical pendulum catalog = built-in C")
local Esp = math.abs(sp:energy{q = {th, ph}, v = {thd, phd}})
d = drift(sp, {method = "gauss", stages = 2, h = 0.02}, {q = {th, ph}, v = {thd, phd}}, 500)
T.ok(d < 1e-5 * Esp, ("spherical pendulum, Gauss 2: energy bounded (%.2g)"):format(d))
d = drift(dm.systems.spherical_pendulum_r3{l = 1.3, m = 2, form = "norm"}, {method = "trapezoid", h = 0.01}, {q = qc, v = vc}, 500)
T.ok(d < 2e-3 * Esp, ("spherical pendulum in R^3 (|q| - l form), RATTLE: energy bounded (%.2g)"):format(d))

-- double spherical pendulum: two forms, the closed forms of doc/reduce.md §14, R^3 x R^3
local P = {g = 9.81, l1 = 1.1, l2 = 0.9, m1 = 1.3, m2 = 0.7}
local cyl, shape, r33 = dm.systems.double_spherical_pendulum(P),
  dm.systems.double_spherical_pendulum{g = 9.81, l1 = 1.1, l2 = 0.9, m1 = 1.3, m2 = 0.7, form = "shape"},
  dm.systems.double_spherical_pendulum_r3(P)
local r1, t1, r2, t2 = 0.5, 0.4, 0.45, 1.3
local r1d, t1d, r2d, t2d = 0.1, 2.5, -0.2, 3.0
local phi = t2 - t1
T.is(table.concat(shape.cyclic, ","), "theta", "shape form: theta (simultaneous rotation) is cyclic")
T.near(cyl:energy{q = {r1, t1, r2, t2}, v = {r1d, t1d, r2d, t2d}}, shape:energy{q = {t1, r1, r2, phi}, v = {t1d, r1d, r2d, t2d - t1d}},
       1e-14, "cylindrical and shape forms: same energy")
local I = P.m1 * r1^2 + P.m2 * (r1^2 + r2^2 + 2 * r1 * r2 * math.cos(phi))
local qs = {t1, r1, r2, phi}
T.near(shape:momentum({q = qs, v = {1, 0, 0, 0}}, "theta"), I, 1e-14, "locked inertia I = m1 r1^2 + m2 (r1^2 + r2^2 + 2 r1 r2 cos phi)")
local A = {-r2 * math.sin(phi), r1 * math.sin(phi), r2^2 + r1 * r2 * math.cos(phi)}
local ok = true
for i = 1, 3 do
  local e = {0, 0, 0, 0}
  e[i + 1] = 1
  ok = ok and math.abs(shape:momentum({q = qs, v = e}, "theta") - P.m2 * A[i]) < 1e-14
end
T.ok(ok, "mechanical connection I A = m2 (-r2 sin phi, r1 sin phi, r2^2 + r1 r2 cos phi)")
local function bob(r, t, rd, td, l)
  local s = math.sqrt(l^2 - r^2)
  return {r * math.cos(t), r * math.sin(t), -s}, {rd * math.cos(t) - r * math.sin(t) * td,
          rd * math.sin(t) + r * math.cos(t) * td, r * rd / s}
end
local x1, w1 = bob(r1, t1, r1d, t1d, P.l1)
local x2, w2 = bob(r2, t2, r2d, t2d, P.l2)
local q6, v6 = {x1[1], x1[2], x1[3], x2[1], x2[2], x2[3]}, {w1[1], w1[2], w1[3], w2[1], w2[2], w2[3]}
T.near(r33:energy{q = q6, v = v6}, cyl:energy{q = {r1, t1, r2, t2}, v = {r1d, t1d, r2d, t2d}}, 1e-13,
       "R^3 x R^3 form: same energy at the same configuration")
d = drift(cyl, {method = "gauss", stages = 2, h = 0.01}, {q = {r1, t1, r2, t2}, v = {r1d, t1d, r2d, t2d}}, 300)
T.ok(d < 1e-7, ("double spherical pendulum (cylindrical), Gauss 2: energy bounded (%.2g)"):format(d))
local dtr
d, dtr = drift(r33, {method = "lobatto", stages = 3, h = 0.01}, {q = q6, v = v6}, 300)
local g1 = 0
local cx1, cy1, cz1 = dtr:column("x1"), dtr:column("y1"), dtr:column("z1")
local cx2, cy2, cz2 = dtr:column("x2"), dtr:column("y2"), dtr:column("z2")
for k = 1, #dtr do
  g1 = math.max(g1, math.abs(math.sqrt(cx1[k]^2 + cy1[k]^2 + cz1[k]^2) - P.l1),
                math.abs(math.sqrt(cx2[k]^2 + cy2[k]^2 + cz2[k]^2) - P.l2))
end
T.ok(d < 1e-5 and g1 < 1e-12, ("R^3 x R^3, Lobatto 3: energy bounded (%.2g), |q_i| = l_i to %.2g"):format(d, g1))

-- damped oscillator loses energy
local _, dtr2 = drift(dm.systems.damped{c = 0.2}, {method = "midpoint", h = 0.05}, {q = {1}, v = {0}}, 200)
local E = dtr2:energy()
T.ok(E[#dtr2] < E[1] * math.exp(-0.2 * 10) * 1.1, "damped oscillator loses energy at the rate c")

-- catalog errors
T.error_like(function() dm.systems.kepler{mu = 1, J2 = 3} end, "dm.systems.kepler: unknown parameter J2 %(parameters: mu, dim, impl%)",
             "unknown parameter")
T.error_like(function() dm.systems.pendulum{g = "9.81"} end, "parameter g must be a number", "non-numeric parameter")
T.error_like(function() dm.systems.harmonic(3) end, "table of parameters expected", "not a table")
T.error_like(function() dm.systems.kepler{dim = 4} end, "dim must be 2 or 3", "Kepler dim")
T.error_like(function() dm.systems.double_spherical_pendulum{form = "polar"} end, "form must be", "double pendulum form")
-- one catalogue: impl = "c" is the same system written in C (same coordinates,
-- parameters and values), also after a parameter change (the C mass follows m)
do
  local cases = {
    {"harmonic", {m = 1.7, omega = 2.385}, {0.3}, {-0.8}},
    {"damped", {m = 1.7, omega = 2.385, c = 0.3}, {0.3}, {-0.8}},
    {"pendulum", {g = 9.81, l = 1.3, m = 0.7}, {0.9}, {2.385}},
    {"kepler", {mu = 1.3}, {0.4, 0.7}, {-0.2, 1.1}},
    {"kepler", {mu = 1.3, dim = 3}, {0.4, 0.7, 0.2}, {-0.2, 1.1, 0.3}},
    {"j2", {J2 = 0.05}, {1.1, -0.4, 0.35}, {0.2, 0.9, 0.15}},
    {"spherical_pendulum", {g = 9.81, l = 1.3, m = 0.7}, {1.2, 0.3}, {0.5, 1.5}},
    {"spherical_pendulum_r3", {g = 9.81, l = 1.3, m = 0.7}, {0.3, 0.4, -1.2}, {0.5, -0.2, 0.07 / 1.2}},
  }
  for _, c in ipairs(cases) do
    local o = {}
    for k, v in pairs(c[2]) do o[k] = v end
    local tr = dm.systems[c[1]](o)
    o.impl = "c"
    local cs = dm.systems[c[1]](o)
    local same = table.concat(tr.coords, ",") == table.concat(cs.coords, ",") and tr.name == cs.name
    local names = {}
    for k in pairs(tr.params) do names[#names + 1] = k .. "=" .. tr.params[k] end
    for k in pairs(cs.params) do same = same and cs.params[k] == tr.params[k] end
    local function agree()
      local d = math.abs(tr:lagrangian{q = c[3], v = c[4]} - cs:lagrangian{q = c[3], v = c[4]})
      local pt, pc = tr:momentum{q = c[3], v = c[4]}, cs:momentum{q = c[3], v = c[4]}
      for i = 1, #pt do d = math.max(d, math.abs(pt[i] - pc[i])) end
      local st = {q = c[3], v = c[4]}
      local o2 = tr.m > 0 and {method = "lobatto", stages = 3, h = 0.05} or {method = "gauss", stages = 2, h = 0.05}
      local a = dm.integrator(tr, o2):step(st)
      local b = dm.integrator(cs, o2):step(st)
      for i = 1, #a.q do d = math.max(d, math.abs(a.q[i] - b.q[i]), math.abs(a.p[i] - b.p[i])) end
      return d
    end
    local d1 = agree()
    local pname = c[2].m and "m" or (c[2].mu and "mu" or "J2")
    tr.params[pname] = 2.385
    cs:set{[pname] = 2.385}
    local d2 = agree()
    local e = dm.integrator(tr, {method = "trapezoid", h = 0.01})
    local f = dm.integrator(cs, {method = "trapezoid", h = 0.01})
    local ta = e:run({q = c[3], v = c[4]}, {steps = 50})
    local tb = f:run({q = c[3], v = c[4]}, {steps = 50})
    local d3 = math.abs(ta:column(tr.coords[1])[51] - tb:column(tr.coords[1])[51])
    T.ok(same and d1 <= 1e-13 and d2 <= 1e-13 and d3 <= 1e-12,
         ("dm.systems.%s{impl = \"c\"} = the traced entry (%s): L, p, a Gauss (Lobatto) step %.2g; after %s = 2.385: %.2g; Stormer-Verlet run %.2g")
         :format(c[1], table.concat(names, " "), d1, pname, d2, d3))
  end
  T.error_like(function() dm.systems.henon_heiles{impl = "c"} end,
    "dm.systems.henon_heiles: no C implementation %(impl = \"c\" exists for damped, harmonic, j2, kepler, pendulum, spherical_pendulum, spherical_pendulum_r3%)",
    "an entry without C says which have one")
  T.error_like(function() dm.systems.pendulum{impl = "fortran"} end, "impl must be \"traced\" or \"c\", got fortran", "impl checked")
  T.error_like(function() dm.systems.j2{j2 = 1, impl = "c"} end, "dm.systems.j2: unknown parameter j2 %(parameters: J2, impl%)",
    "the C implementation checks parameters like the traced one")
  T.ok(dm.builtin == nil, "no second catalogue (dm.builtin)")
end
T.done()
