-- mech_kepler.lua -- the Kepler reference problem (doc/integrators.md
-- §12.5) through the Lua API on the TRACED Kepler
-- problem, e = 0.6 (q0 = (0.4, 0), p0 = (0, 2), H = -1/2, angular momentum
-- 0.8, period 2 pi): the maximum energy error of Stormer-Verlet h = 0.01
-- over 1000 periods is the 10-period value 3.707e-4 (no drift: the linear
-- fit of the per-period maxima is flat), the angular momentum stays within
-- 5e-13; the 10-period maxima of the Gauss methods match the reference values.
local T = require "dmech.test"
local dm = require "dmech"

local kep = dm.systems.kepler()
local k0 = {q = {0.4, 0}, p = {0, 2}}
T.near(kep:energy{q = k0.q, p = k0.p}, -0.5, 1e-15, "H0 = -1/2")

-- per-period maxima of |H - H0| and the largest angular-momentum error
local function analyse(tr, periods)
  local t, E = tr:column("t"), tr:energy()
  local x, y, px, py = tr:column("x"), tr:column("y"), tr:column("p_x"), tr:column("p_y")
  local maxima, dLz = {}, 0
  for k = 1, #t do
    local i = math.floor(t[k] / (2 * math.pi)) + 1
    if i <= periods then
      maxima[i] = math.max(maxima[i] or 0, math.abs(E[k] + 0.5))
    end
    dLz = math.max(dLz, math.abs(x[k] * py[k] - y[k] * px[k] - 0.8))
  end
  local top = 0
  for i = 1, periods do top = math.max(top, maxima[i]) end
  return maxima, top, dLz
end

-- least-squares slope of the maxima against the period index
local function slope(m)
  local n, sx, sy, sxx, sxy = #m, 0, 0, 0, 0
  for i = 1, n do sx = sx + i; sy = sy + m[i]; sxx = sxx + i * i; sxy = sxy + i * m[i] end
  return (n * sxy - sx * sy) / (n * sxx - sx * sx)
end

local sv = dm.integrator(kep, {method = "trapezoid", h = 0.01})
T.ok(sv.explicit, "Stormer-Verlet runs the explicit path on the traced (separable) Kepler system")
local tr = sv:run(k0, {t = 2000 * math.pi})
T.is(#tr, 628320, "1000 periods = 628319 steps, every step sampled")
local maxima, top, dLz = analyse(tr, 1000)
T.ok(math.abs(top / 3.707e-4 - 1) < 1e-3, ("Kepler SV h=0.01, 1000 periods: max |H - H0| = %.4g (reference 3.707e-4)"):format(top))
T.ok(math.abs(maxima[1] / 3.707e-4 - 1) < 2e-3 and math.abs(maxima[1000] / 3.707e-4 - 1) < 2e-3,
     ("the first and the last period reach the same maximum (%.5g, %.5g)"):format(maxima[1], maxima[1000]))
local drift = slope(maxima) * 1000
T.ok(math.abs(drift) < 1e-3 * top, ("no drift: linear fit of the per-period maxima changes by %.2g over 1000 periods"):format(drift))
T.ok(dLz <= 5e-13, ("angular momentum error over 1000 periods %.2g <= 5e-13"):format(dLz))

-- 10 periods of the implicit methods (reference values, doc/integrators.md §12.5)
for _, c in ipairs{{"gauss", 1, 0.01, 4.22e-4}, {"gauss", 2, 0.05, 3.89e-6}, {"gauss", 2, 0.025, 2.50e-7},
                   {"gauss", 3, 0.1, 1.21e-6}, {"gauss", 3, 0.05, 1.76e-8}, {"trapezoid", nil, 0.005, 9.263e-5}} do
  local I = dm.integrator(kep, {method = c[1], stages = c[2], h = c[3]})
  local _, m, dl = analyse(I:run(k0, {t = 20 * math.pi}), 10)
  T.ok(math.abs(m / c[4] - 1) < 0.01 and dl < 1e-13,
       ("Kepler %s s=%s h=%g, 10 periods: max |H - H0| = %.4g (reference %.4g), angular momentum %.2g"):format(
       c[1], c[2] or "-", c[3], m, c[4], dl))
end
T.done()
