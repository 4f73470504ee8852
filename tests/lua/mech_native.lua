-- mech_native.lua -- native = "auto" | "wait" | "always" | "never" from
-- Lua: with auto a system runs at once on the tape while its native code
-- compiles in the background, a run started meanwhile computes what the
-- tape alone computes, and the code takes over (sys.compiling,
-- sys.native); wait compiles before dm.system returns.
local T = require "dmech.test"
local dm = require "dmech"

-- tag: a constant in L (the systems compared share theirs), from the clock
-- so that the code is compiled, not found in the cache of an earlier run
-- (a compilation takes far longer than what these tests do meanwhile)
local function chain(native, tag)
  return dm.system{name = "chain", coords = {"a", "b", "c"}, params = {k = 1.3},
    native = native,
    L = function(q, v, p)
      local T0 = 0.5 * (v.a^2 + v.b^2 + v.c^2) + 0.1 * v.a * dm.cos(q.b)
      local d1, d2, d3, d4 = q.a, q.b - q.a, q.c - q.b, -q.c
      return T0 - p.k * (d1^4 + d2^4 + d3^4 + d4^4) - (1 + 1e-9 * tag) * (d1^2 + d2^2)
    end}
end

local seed = os.time() % 1000003
local ok_cc = pcall(chain, "always", seed)
if not ok_cc then T.skip_all("no C compiler") end

local tape, auto = chain("never", seed + 1), chain("auto", seed + 1)
T.ok(auto.compiling and not auto.native, "auto: compiling in the background, the tape runs")
T.like(tostring(auto), "traced, compiling", "tostring says so")
T.ok(not tape.compiling and not tape.native and tape.native_error == nil,
     "never: the tape, nothing compiling")

local state = {q = {0.3, -0.2, 0.1}, v = {0.2, 0.1, -0.3}}
local opts = {steps = 40000, every = 20000}
local rt = dm.integrator(tape, {method = "gauss", stages = 2, h = 0.01}):run(state, opts)
local ra = dm.integrator(auto, {method = "gauss", stages = 2, h = 0.01}):run(state, opts)
T.agree(ra, rt, {"a", "b", "c", "p_a", "p_b", "p_c"}, 1e-13,
        "a run started while compiling = the tape alone")

local t0 = os.time()
while auto.compiling and os.time() - t0 < 60 do
  dm.integrator(auto, {method = "gauss", h = 0.01}):run(state, {steps = 100})
end
T.ok(auto.native and not auto.compiling and auto.native_error == nil,
     "the native code took over")
local rb = dm.integrator(auto, {method = "gauss", stages = 2, h = 0.01}):run(state, opts)
T.agree(rb, rt, {"a", "b", "c", "p_a", "p_b", "p_c"}, 1e-13, "native = tape")

local w = chain("wait", seed + 2)
T.ok(w.native and not w.compiling, "wait: native when dm.system returns")
T.error_like(function() chain("sometimes", seed) end, "native must be \"auto\", \"wait\"",
             "an unknown mode")
T.done()
