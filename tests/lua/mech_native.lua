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

-- no compiler on PATH (and no $CC), an empty cache: auto and wait keep the
-- tape and compute what it computes; wait says why on stderr, auto in
-- sys.native_error once the failed job is reaped
local function shq(x) return "'" .. x:gsub("'", "'\\''") .. "'" end
local cache = os.tmpname()
os.remove(cache)
local script = [[
local function chain(native)
  return dm.system{name = "chain", coords = {"a", "b"}, native = native,
    L = function(q, v) return 0.5 * (v.a^2 + v.b^2) - dm.cos(q.a) * q.b^2 - 0.1 * q.a^4 end}
end
local function run(s)
  local r = dm.integrator(s, {method = "gauss", stages = 2, h = 0.01}):run(
    {q = {0.3, -0.2}, v = {0.2, 0.1}}, {steps = 2000, every = 2000})
  return ("%.17g %.17g %.17g %.17g"):format(r.q.a[2], r.q.b[2], r.p.a[2], r.p.b[2])
end
local tape, auto = chain("never"), chain("auto")
local ra = run(auto)
local t0 = os.time()
while auto.compiling and os.time() - t0 < 30 do run(auto) end
local w = chain("wait")
print("same", run(tape) == ra, ra == run(w), run(tape) == run(auto))
print("auto", auto.native, auto.compiling, auto.native_error)
print("wait", w.native, w.compiling, w.native_error)
]]
local cmd = ("env -u CC PATH=/nonexistent XDG_CACHE_HOME=%s %s -e %s 2>&1"):format(
  shq(cache), shq(os.getenv("DMECH")), shq(script))
local pipe = io.popen(cmd)
local out = pipe:read("a")
pipe:close()
os.execute("rm -rf " .. shq(cache))
T.like(out, "\nsame\ttrue\ttrue\ttrue\n",
       "no compiler on PATH: auto and wait run on the tape, the same numbers as never")
T.like(out, "\nauto\tfalse\tfalse\tnative: cannot run C compiler 'cc'",
       "auto: nothing compiling any more, native_error says why")
T.like(out, "\nwait\tfalse\tfalse\tnative: cannot run C compiler 'cc'", "wait: the same")
T.like(out, "^warning: dm%.system: 'chain' runs on the tape %(native: cannot run C compiler 'cc'",
       "wait warns on stderr, once; auto does not")
local _, nwarn = out:gsub("warning:", "")
T.is(nwarn, 1, "one warning")
if not out:find("same\ttrue") then T.diag(out) end
T.done()
