-- j2_stability_map.lua -- where the orbits of a satellite about an oblate
-- planet that has a distant companion stay regular, turn chaotic, fall
-- onto the planet or escape: a MEGNO map over (semi-major axis,
-- inclination), one dm.ensemble member per pixel.
--
--   src/dmech examples/j2_stability_map.lua [options]
--   mpirun -np 2 src/dmech examples/j2_stability_map.lua [options]   (the same script)
--
-- Options: --size NAxNI (default 40x24, about 25 ms of CPU per orbit: a
--   minute for the three timed runs on 2 idle cores; the full map --size
--   200x200 takes about 8 minutes there),
--   --t T (default 1000), --h H (default 0.05), --j2 J (default 0.1),
--   --tide K (default 0.003), --obliquity DEG (default 75),
--   --a A0,A1 (default 1.2,3.2), --out FILE.png (default
--   j2_stability_map.png), --table FILE.h5 (also save the table: a, i are
--   recomputed from the member number; HDF5 or .csv), --threads N (default:
--   all cores), --no-timing.
--
-- Model.  Units: the planet's radius R = 1 and GM = 1 (time unit
-- sqrt(R^3/GM)).  The planet's potential with its zonal harmonic J2 about
-- the spin axis z (dm.systems.j2), plus the tide of a distant companion --
-- a star or moon of mass M' on a circular orbit of radius a', averaged over
-- that orbit (a ring), whose normal n is tilted by the obliquity from z:
--   V = -1/r + (J2/r^3) (3 z^2/(2 r^2) - 1/2) + (K/4) (r^2 - 3 (n.r)^2),
--   K = G M' / a'^3.
-- Inside the Laplace radius r_L = (J2/K)^(1/5) the planet's bulge rules the
-- orbit planes, outside it the companion does; between the two the
-- "Laplace surface" of the orbits' mean planes warps, and for obliquities
-- above 68.9 degrees part of it is unstable (Tremaine, Touma and Namouni,
-- Astron. J. 137 (2009) 3706).  Beyond r_L orbits inclined by more than
-- 39 degrees to the companion's plane undergo Lidov-Kozai cycles whose
-- eccentricity can bring the pericentre below the planet's surface.  The
-- Hill radius (1/(3K))^(1/3) bounds the bound orbits.  The defaults (J2 =
-- 0.1, K = 0.003: r_L = 2.02, Hill radius 4.81) are far stronger than any
-- real planet's, so that the secular dynamics plays out within t = 1000
-- (a few hundred orbits at a = 2) and the map takes a minute; the picture
-- is qualitative.  At the Earth's J2 = 1.08e-3 without a companion every
-- orbit of this map is regular.
--
-- Every orbit starts on the x axis (the line of nodes of the planet's
-- equator), circular for the orbit-averaged J2 field, v^2 = 1/a + (3 J2 /
-- (2 a^3)) (1 - 3/2 sin^2 i), in a plane inclined by i to the equator.
-- Gauss s = 2 (order 4, symplectic) with h = 0.05; the indicator is MEGNO
-- <Y> from the exact step Jacobian (doc/ensembles.md §3): <Y> -> 2 for
-- regular orbits and grows like lambda t / 2 on chaotic ones; pixels with
-- <Y> > 3 are called chaotic in the count.  At the defaults the chaotic
-- orbits are the exactly polar ones inside the Laplace radius (the top
-- row: their plane contains the companion's orbit normal), and the regular
-- region is cut by bands of inclination whose orbits reach the surface.  Orbits that come within r < 1
-- (min_distance over the samples) are marked "hits the planet", orbits
-- that end beyond the Hill radius "escapes": their <Y> describes a path
-- through the planet or out of the system.
--
-- Timing: without mpirun the map is computed with 1 and with 2 threads
-- (the tables must agree bit for bit) and -- when mpirun exists -- by 2
-- MPI ranks of 1 thread each (the script runs itself under mpirun); the
-- three wall-clock times are printed.
local dm = require "dmech"

-- {==== options ============================================================
local opt = {na = 40, ni = 24, t = 1000, h = 0.05, j2 = 0.1, tide = 0.003, obl = 75,
             a0 = 1.2, a1 = 3.2, out = "j2_stability_map.png", threads = nil, timing = true}
local i = 1
while arg and arg[i] do
  local k, v = arg[i], arg[i + 1]
  local function num()
    local x = tonumber(v)
    if not x then error(k .. ": a number expected, got " .. tostring(v), 0) end
    i = i + 1
    return x
  end
  if k == "--size" then
    local a, b = (v or ""):match("^(%d+)x(%d+)$")
    if not a or tonumber(a) < 2 or tonumber(b) < 2 then error("--size: NAxNI expected, e.g. 200x200", 0) end
    opt.na, opt.ni = tonumber(a), tonumber(b)
    i = i + 1
  elseif k == "--t" then opt.t = num()
  elseif k == "--h" then opt.h = num()
  elseif k == "--j2" then opt.j2 = num()
  elseif k == "--tide" then opt.tide = num()
  elseif k == "--obliquity" then opt.obl = num()
  elseif k == "--a" then
    local a, b = (v or ""):match("^([%d.]+),([%d.]+)$")
    if not a then error("--a: A0,A1 expected, e.g. 1.2,3.6", 0) end
    opt.a0, opt.a1 = tonumber(a), tonumber(b)
    i = i + 1
  elseif k == "--out" then opt.out = v i = i + 1
  elseif k == "--table" then opt.table = v i = i + 1
  elseif k == "--threads" then opt.threads = math.tointeger(num())
  elseif k == "--no-timing" then opt.timing = false
  elseif k == "--mpi-child" then opt.child = true       -- started by this script under mpirun
  else error("unknown option " .. k .. " (the options are listed at the head of the script)", 0) end
  i = i + 1
end
local rank, size = dm.mpi.rank(), dm.mpi.size()
local function say(...) if rank == 0 then print(...) end end
-- }==========================================================================

-- {==== the system and the members ========================================
local ob = math.rad(opt.obl)
local nx, nz = math.sin(ob), math.cos(ob)       -- the companion's orbit normal
local sys = dm.system{name = "J2 planet with a distant companion", coords = {"x", "y", "z"},
  params = {J2 = opt.j2, K = opt.tide},
  L = function(q, v, p)
    local r2 = q.x^2 + q.y^2 + q.z^2
    local r = dm.sqrt(r2)
    local nr = nx * q.x + nz * q.z
    local V = -1 / r + p.J2 / (r2 * r) * (1.5 * q.z^2 / r2 - 0.5) + p.K / 4 * (r2 - 3 * nr^2)
    return 0.5 * (v.x^2 + v.y^2 + v.z^2) - V
  end}
local I = dm.integrator(sys, {method = "gauss", stages = 2, h = opt.h})
local N = opt.na * opt.ni
local rL, rH = (opt.j2 / opt.tide)^0.2, (1 / (3 * opt.tide))^(1 / 3)

local function grid(k)              -- member k -> (a, i in degrees), a fastest
  local ia, ii = (k - 1) % opt.na, (k - 1) // opt.na
  return opt.a0 + (opt.a1 - opt.a0) * ia / (opt.na - 1), 90 * ii / (opt.ni - 1)
end

local function start(k)
  local a, inc = grid(k)
  local s, c = math.sin(math.rad(inc)), math.cos(math.rad(inc))
  local v = math.sqrt(1 / a + 1.5 * opt.j2 / a^3 * (1 - 1.5 * s * s))
  return {q = {a, 0, 0}, v = {0, v * c, v * s}}
end

-- orbits that plunge into the planet fail (Newton) once r is near 0; the
-- count below says so, so the ensemble's own warning line is turned off
dm.config.warn = false

local function run(threads)
  local w0 = dm.mpi.wtime()
  local res, msg = dm.ensemble{integrator = I, members = N, threads = threads, states = start,
    run = {t = opt.t, every = 4}, reduce = {"final", "min_distance", "megno"}}
  if size > 1 then dm.mpi.barrier() end
  return res, msg, dm.mpi.wtime() - w0
end
-- }==========================================================================

-- {==== runs and their times ===============================================
if opt.child then                    -- a timing under mpirun, for the parent
  local _, _, dt = run(1)
  say(("MPI %d ranks x 1 thread: %.2f s"):format(size, dt))
  return
end

say(("%s: J2 = %g, K = %g, obliquity %g deg (Laplace radius %.3f, Hill radius %.3f)"):format(
    sys.name, opt.j2, opt.tide, opt.obl, rL, rH))
say(("%d x %d circular orbits, a in [%g, %g], i in [0, 90] deg; t = %g, h = %g, Gauss s=2, MEGNO")
    :format(opt.na, opt.ni, opt.a0, opt.a1, opt.t, opt.h))
local res, msg, dt
if size > 1 then
  res, msg, dt = run(1)
  say(("%d MPI ranks x 1 thread: %.2f s"):format(size, dt))
elseif opt.timing then
  local res1, _, dt1 = run(1)
  res, msg, dt = run(2)
  local same = true
  for _, c in ipairs(res:names()) do
    local x, y = res:column(c), res1:column(c)
    for k = 1, #x do same = same and (x[k] == y[k] or (x[k] ~= x[k] and y[k] ~= y[k])) end
  end
  say(("1 thread: %.2f s   2 threads: %.2f s (%.2fx)   the two tables bit for bit equal: %s"):format(
      dt1, dt, dt1 / dt, tostring(same)))
  local mpirun = io.popen("command -v mpirun 2>/dev/null"):read("l")
  if mpirun and dm.mpi.info().built then
    local root = io.popen("id -u"):read("l") == "0" and " --allow-run-as-root" or ""
    local cmd = ("%s%s --oversubscribe -np 2 %s %s --mpi-child --size %dx%d --t %.17g --h %.17g "
                 .. "--j2 %.17g --tide %.17g --obliquity %.17g --a %.17g,%.17g 2>&1"):format(
                 mpirun, root, arg[-1], arg[0], opt.na, opt.ni, opt.t, opt.h, opt.j2, opt.tide,
                 opt.obl, opt.a0, opt.a1)
    local p = io.popen(cmd)
    local out = p:read("a")
    p:close()
    local t2 = out:match("MPI 2 ranks x 1 thread: ([%d.]+) s")
    say(t2 and ("2 MPI ranks x 1 thread: %s s (%.2fx)"):format(t2, dt1 / tonumber(t2))
        or ("2 MPI ranks: mpirun failed:\n" .. out))
  else
    say("2 MPI ranks: not timed (" .. (mpirun and "dmech was built without MPI" or "no mpirun") .. ")")
  end
else
  res, msg, dt = run(opt.threads)
  say(("%.2f s"):format(dt))
end
-- }==========================================================================

-- {==== the picture (rank 0) ================================================
if opt.table then res:save(opt.table) end    -- every rank calls it, rank 0 writes
if rank ~= 0 then return end
local megno, dmin = res:column("megno"), res:column("min_distance")
local X, Y, Z, status = res:column("x"), res:column("y"), res:column("z"), res:column("status")
local A, INC, C = {}, {}, {}
local n = {regular = 0, chaotic = 0, hit = 0, escape = 0, failed = 0}
for k = 1, N do
  A[k], INC[k] = grid(k)
  local rend = math.sqrt(X[k]^2 + Y[k]^2 + Z[k]^2)
  if dmin[k] < 1 then                    -- it met the surface (it may fail afterwards, inside)
    C[k] = -1.5                          -- the palette's light grey
    n.hit = n.hit + 1
  elseif rend > rH or status[k] ~= 0 then
    C[k] = -0.5                          -- dark grey
    if status[k] ~= 0 then n.failed = n.failed + 1 else n.escape = n.escape + 1 end
  else
    C[k] = math.min(megno[k], 8)
    if megno[k] > 3 then n.chaotic = n.chaotic + 1 else n.regular = n.regular + 1 end
  end
end
local da, di = (opt.a1 - opt.a0) / (opt.na - 1), 90 / (opt.ni - 1)
dm.plot{
  {A, INC, C, with = "image"},
  title = ("MEGNO <Y> at t = %g: J2 = %g, companion tide K = %g at obliquity %g deg (%dx%d orbits)")
          :format(opt.t, opt.j2, opt.tide, opt.obl, opt.na, opt.ni),
  xlabel = "semi-major axis a (planet radii)",
  ylabel = "inclination i to the planet's equator (degrees)",
  xrange = {opt.a0 - da / 2, opt.a1 + da / 2}, yrange = {-di / 2, 90 + di / 2},
  key = false, output = opt.out, size = {1100, 680},
  commands = {
    "set view map",
    "set rmargin at screen 0.80",
    "set cbrange [-2:8]",
    "set palette defined (-2 '#d9d9d9', -1.001 '#d9d9d9', -1 '#636363', -0.001 '#636363', "
      .. "0 '#08306b', 1.6 '#2171b5', 2 '#9ecae1', 2.6 '#c7e9c0', 3 '#fee08b', 5 '#f46d43', "
      .. "8 '#a50026')",
    ("set cbtics ('hits the planet' -1.5, '%s' -0.5, '0' 0, '2: regular' 2, '4' 4, '6' 6, "
      .. "'>= 8: chaotic' 8)"):format(n.failed > 0 and "escapes or fails" or "escapes"),
    "set cblabel 'MEGNO <Y>'",
    "set ytics 0, 15, 90",
    "set tics out",
    ("set arrow from %.17g, graph 0 to %.17g, graph 1 nohead dt 2 lw 2 lc rgb 'black' front")
      :format(rL, rL),
    ("set label 'Laplace radius' at %.17g, graph 1.03 center front"):format(rL),
  }}
-- members fail (Newton) once they plunge towards r = 0 inside the planet:
-- expected; a failure before the surface is worth the run's own message
if n.failed > 0 and msg then say(msg) end
say(("%d regular (<Y> <= 3), %d chaotic (<Y> > 3), %d hit the planet, %d escape, %d failed "
     .. "before reaching the planet; picture: %s"):format(n.regular, n.chaotic, n.hit, n.escape,
     n.failed, opt.out))
-- }==========================================================================
