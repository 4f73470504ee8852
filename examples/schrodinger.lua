-- schrodinger.lua -- the pseudospectral variational integrator for the
-- Schrodinger equation (doc/beyond-fixed-steps.md §6): a coherent state in a harmonic
-- trap V = w^2 (x - pi)^2/2 on the periodic [0, 2 pi), 65 Fourier modes.
--   schrodinger.png   (a) |psi|^2 over half a period: the packet moves
--                     without spreading; (b) <x>(t) against pi + a cos(w t);
--                     (c) the norm: Crank-Nicolson keeps it to round-off
--                     (a walk to 5e-13 over 2745 steps), Milne-Simpson
--                     (order 4, two-step) to its truncation error, which
--                     oscillates from one step to the next (the filled bands);
--                     (d) the energy error of both
--
--   src/dmech examples/schrodinger.lua [output-directory]
local dm = dm or require "dmech"
local outdir = arg and arg[1] or "."
local w, a, K = 16, 0.25, 32
local S = dm.schrodinger{K = K, V = function(x) return 0.5 * w^2 * (x - math.pi)^2 end}

-- the time-independent problem: the lowest levels are w (n + 1/2)
local E = S:energies()
local worst = 0
for n = 0, 5 do worst = math.max(worst, math.abs(E[n + 1] - w * (n + 0.5))) end
print(string.format("%d modes: the six lowest eigenvalues are w (n + 1/2) to %.2g; the largest "
  .. "is %.1f", S.modes, worst, E[#E]))

-- the ground state displaced by a: a coherent state, <x> = pi + a cos(w t)
local psi0 = S:wave(function(x) return (w / math.pi)^0.25 * math.exp(-0.5 * w * (x - math.pi - a)^2) end)
local period = 2 * math.pi / w
-- Milne-Simpson is stable for dt max|E| <= sqrt 3; Crank-Nicolson for any dt
local dt = 0.5 * math.sqrt(3) / E[#E]
local T = 4 * period
local ms = S:run(psi0, {method = "milne", dt = dt, t = T})
local cn = S:run(psi0, {method = "cn", dt = dt, t = T})
print(string.format("dt = %.4g (dt max E = %.3f), %d steps over 4 periods", dt, dt * E[#E], #ms - 1))

-- (a) snapshots of the density over half a period
local snaps = {}
local steps_half = math.floor(period / 2 / dt + 0.5)
for i = 0, 4 do
  local n = math.floor(i * steps_half / 4 + 0.5)
  local _, wn = S:run(psi0, {method = "milne", dt = dt, steps = n})
  local x, rho = wn:density(512)
  snaps[#snaps + 1] = {x, rho, with = "lines lw 2",
                       title = string.format("t = %.3f", n * dt)}
end

-- (b)-(d) from the trajectories
local t, xm = ms:column("t"), ms:column("x")
local exact, ts, xs = {}, {}, {}
for k = 1, #ms do
  exact[k] = math.pi + a * math.cos(w * t[k])
  if k % 25 == 1 then ts[#ts + 1], xs[#xs + 1] = t[k], xm[k] end   -- every 25th step as a point
end
local function dev(tr, col)
  local v, d = tr:column(col), {}
  for k = 1, #tr do d[k] = math.max(math.abs(v[k] - v[1]), 1e-17) end
  return d
end
local nms, ncn, ems, ecn = dev(ms, "norm"), dev(cn, "norm"), dev(ms, "energy"), dev(cn, "energy")
local function maxof(v) local m = 0 for k = 1, #v do m = math.max(m, v[k]) end return m end
print(string.format("norm change: Milne-Simpson %.2g, Crank-Nicolson %.2g; energy change: %.2g, %.2g",
  maxof(nms), maxof(ncn), maxof(ems), maxof(ecn)))

local tcn = cn:column("t")
dm.plot{
  {snaps[1], snaps[2], snaps[3], snaps[4], snaps[5],
   title = "(a) |psi|^2 over half a period (Milne-Simpson)", xlabel = "x", ylabel = "|psi|^2",
   xrange = {math.pi - 1.2, math.pi + 1.2}, key = "top right", grid = true},
  {{t, exact, with = "lines lw 2", title = string.format("pi + a cos(w t), a = %g", a)},
   {ts, xs, with = "points pt 7 ps 0.8", title = "<x>, Milne-Simpson"},
   title = "(b) the centre of the packet", xlabel = "t", ylabel = "<x>", grid = true,
   yrange = {math.pi - 0.4, math.pi + 0.45}, key = "top right"},
  {{t, nms, with = "lines lw 2", title = "Milne-Simpson"},
   {tcn, ncn, with = "lines lw 2", title = "Crank-Nicolson"},
   title = "(c) norm change |N(t) - N(0)|", xlabel = "t", ylabel = "|N - N0|", logscale = "y",
   grid = true, yrange = {1e-17, 1e-9}, key = "top left"},
  {{t, ems, with = "lines lw 2", title = "Milne-Simpson"},
   {tcn, ecn, with = "lines lw 2", title = "Crank-Nicolson"},
   title = "(d) energy change |E(t) - E(0)|", xlabel = "t", ylabel = "|E - E0|", logscale = "y",
   grid = true, yrange = {1e-15, 1e-7}, key = "top left"},
  layout = "2,2", output = outdir .. "/schrodinger.png", size = {1200, 900},
  title = string.format("Coherent state in a harmonic trap (w = %g, K = %d, dt = %.2g)", w, K, dt)}
print("wrote " .. outdir .. "/schrodinger.png")
