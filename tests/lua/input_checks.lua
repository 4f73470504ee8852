-- input_checks.lua -- bad input that used to be accepted, ignored or
-- reported confusingly: exact error texts.
local T = require "dmech.test"
local dm = require "dmech"

local function err(f, ...)
  local ok, msg = pcall(f, ...)
  return not ok and tostring(msg) or "(no error)"
end
local function L1(q, v, p) return 0.5 * v.x^2 - 0.5 * p.k * q.x^2 end

-- parameters must be finite where they are given
T.like(err(dm.system, {coords = {"x"}, params = {k = 0/0}, L = L1}),
       "dm.system: parameter 'k' must be a finite number, got nan", "NaN in dm.system{params}")
T.like(err(dm.system, {coords = {"x"}, params = {{"k", math.huge}}, L = L1}),
       "dm.system: parameter 'k' must be a finite number, got inf", "inf in a params list")
local osc = dm.system{coords = {"x"}, params = {k = 2.385}, L = L1}
T.like(err(osc.set, osc, {k = 0/0}), "set: parameter 'k' must be a finite number, got nan",
       "sys:set{k = nan}")
T.like(err(function() osc.params.k = -math.huge end),
       "params: parameter 'k' must be a finite number, got %-inf", "sys.params.k = -inf")
T.is(osc.params.k, 2.385, "the refused values changed nothing")

-- unknown fields of dm.system are errors, not ignored
T.like(err(dm.system, {coords = {"x"}, Lagrangian = L1, L = L1}),
       "dm.system: unknown field 'Lagrangian' %(fields: name, coords, params, L, force, " ..
       "constraints, native%)", "misspelt field")
T.like(err(dm.system, {coords = {"x"}, L = L1, [1] = 2.385}), "dm.system: unknown field %[1%]",
       "positional entry")

-- too many constraints
T.like(err(dm.system, {coords = {"x", "y"}, L = function(q, v) return 0.5 * (v.x^2 + v.y^2) end,
                       constraints = function(q) return {q.x - 1, q.y - 2, q.x + q.y - 3} end}),
       "dm.system: 3 constraints on 2 coordinates leave no motion %(at most 1 independent " ..
       "constraint%)", "three constraints on two coordinates")

-- integrator options
local kep = dm.systems.kepler()
T.like(err(dm.integrator, kep, {method = "gauss", h = 0.1, stages = 0}),
       "dm.integrator: option 'stages' = 0 out of range %(integer 1..%d+%)", "stages = 0 refused")
T.like(err(dm.integrator, kep, {method = "gauss", h = 0.1, stages = 1.5}),
       "dm.integrator: option 'stages' must be an integer, got 1.5", "stages = 1.5")
T.like(err(dm.integrator, kep, {method = "gauss", h = -(0/0)}),
       "dm.integrator: option 'h' must be a number, got nan$", "h = -nan: 'nan', never '-nan'")
local g = dm.integrator(kep, {method = "gauss", h = 0.1})
T.like(err(g.run, g, {q = {1, 0}, v = {0, 1}}, {steps = 1.5}),
       "bad argument #3 to 'integrator:run' %(field 'steps': integer expected, got 1.5%)",
       "steps = 1.5 through pcall: the method's name and the value")

-- Routh reduction
local rot = dm.system{name = "planar orbit", coords = {"r", "th"}, params = {mu = 2.385},
  L = function(q, v, p) return 0.5 * (v.r^2 + q.r^2 * v.th^2) + p.mu / q.r end}
T.like(err(dm.routh, rot, {cyclic = {"th", "th"}, mu = 1.1}),
       "dm.routh: cyclic coordinate 'th' is listed twice %(cyclic%[1%] and cyclic%[2%]%)",
       "a cyclic coordinate listed twice")
local red = dm.routh(rot, {cyclic = {"th"}, mu = 1.1})
local rt = dm.integrator(red, {method = "gauss", h = 0.05}):run({q = {1.3}, v = {0.1}}, {steps = 4})
T.is(#red:reconstruct(rt), 5, "its own reduced trajectory reconstructs")
local kt = dm.integrator(dm.systems.kepler(), {method = "gauss", h = 0.05})
  :run({q = {1, 0}, v = {0, 1}}, {steps = 4})
T.like(err(red.reconstruct, red, kt),
       "^red:reconstruct: the reduced trajectory must have the 1 shape coordinates, got 2$",
       "Kepler's trajectory: one 'red:reconstruct:' prefix and the counts")
local other = dm.integrator(dm.system{coords = {"x"}, L = function(q, v) return 0.5 * v.x^2 end},
  {method = "gauss", h = 0.05}):run({q = {1}, v = {0}}, {steps = 2})
T.like(err(red.reconstruct, red, other),
       "red:reconstruct: the reduced trajectory's coordinate 1 is 'x' where this reduction's " ..
       "shape coordinate is 'r' %(a trajectory of another system%?%)", "another system's coordinates")
local same_names = dm.integrator(dm.system{name = "radial", coords = {"r"},
  L = function(q, v) return 0.5 * v.r^2 - q.r^2 end}, {method = "gauss", h = 0.05})
  :run({q = {1}, v = {0}}, {steps = 2})
T.like(err(red.reconstruct, red, same_names),
       "red:reconstruct: the trajectory comes from system 'radial', not from 'planar orbit " ..
       "reduced by th'", "same coordinate names, another system")
local full = dm.integrator(dm.system{name = "planar orbit", coords = {"r"},
  L = function(q, v) return 0.5 * v.r^2 end}, {method = "gauss", h = 0.05})
  :run({q = {1}, v = {0}}, {steps = 2})
T.like(err(red.reconstruct, red, full), "%(reconstruct takes a run of the reduced system%)",
       "a trajectory of the full system's name: says which run is needed")

-- a diverging run ends early with a message, keeping what it computed
local stiff = dm.system{name = "stiff quartic", coords = {"q"},
  L = function(q, v) return 0.5 * v.q^2 - 1e12 * q.q^4 / 4 end}
local gs = dm.integrator(stiff, {method = "gauss", h = 100})
local tr, msg = gs:run({q = {1}, v = {0}}, {steps = 20, max_energy_error = 1e3})
T.ok(#tr == 2 and msg and msg:find("^run: the energy error |E %- E0| = 5e%+27 exceeds " ..
     "max_energy_error = 1000 x max%(1, |E0|%) at step 1 of 20 %(t = 100%): the run diverged"),
     "energy runaway (2.5e11 -> 5e27 in one step) stops the run: " .. tostring(msg))
T.is(tr:meta().status ~= 0 and tr:energy()[1], 2.5e11, "the samples before are kept, status set")
tr, msg = gs:run({q = {1}, v = {0}}, {steps = 200})
T.ok(msg and msg:find("the energy became non%-finite at step %d+ of 200") and #tr < 200,
     "without a threshold the same run stops when the energy overflows: " .. tostring(msg))

-- branches on symbolic values that Lua does not let dmech see
T.like(err(dm.system, {coords = {"x", "y"}, L = function(q, v)
         if q.x < q.y then return v.x^2 end return v.y^2 end}),
       "beware: 'x == 0' with a number is silently false and 'if x then' silently true",
       "the branch error warns about == with a number and if x then")
-- a damaged HDF5 file announcing numbers of 4 GB: refused before HDF5
-- fills a buffer that size (it took 8 s and 4 GB before)
local damaged = (os.getenv("DMECH_SRCDIR") or ".") .. "/tests/data/fuzz/hdf5-type-size-huge.h5"
local none, why = dm.load_trajectory(damaged)
T.ok(none == nil and tostring(why):find("dataset 'p_x' has numbers of 4076863496 bytes " ..
     "(a damaged file?)", 1, true), "HDF5 column of 4 GB numbers refused: " .. tostring(why))
T.done()
