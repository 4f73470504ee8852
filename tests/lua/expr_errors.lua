-- expr_errors.lua -- every misuse of the expression API gives a clear
-- message: bad arguments, symbolic branches (naming file:line and
-- suggesting dm.select), unknown functions, wrong arity, dm.fn misuse.
local T = require "dmech.test"
local dm = require "dmech"

local x, y = dm.syms "x y"
local function err(pattern, name, f)
  T.error_like(f, pattern, name)
end

-- bad arguments
err("bad argument #1 to 'sym' %(string expected, got table%)", "dm.sym{}", function() return dm.sym{} end)
err("bad argument #1 to 'sin' %(expression or number expected, got string%)", "dm.sin('a')",
    function() return dm.sin("a") end)
err("bad argument #2 to 'atan2' %(expression or number expected, got boolean%)", "dm.atan2(x, true)",
    function() return dm.atan2(x, true) end)
err("bad operand to '%+' %(expression or number expected, got table%)", "x + {}",
    function() return x + {} end)
err("bad operand to '%*' %(expression or number expected, got string%)", "'a' * x",
    function() return "a" * x end)
err("operators %%, // and bitwise operators are not defined for expressions", "x % 2",
    function() return x % 2 end)

-- symbolic branches name the place and suggest dm.select
local line = debug.getinfo(1, "l").currentline + 2
err("expr_errors.lua:" .. line .. ": branch on a symbolic value %('<' on an expression%).*dm%.select%(dm%.lt",
    "if x < 0 names file:line", function() if x < 0 then return 1 end end)
err("branch on a symbolic value %('<=' on an expression%).*dm%.select%(dm%.le", "x <= y",
    function() return x <= y end)
err("branch on a symbolic value %('<' on an expression%)", "0 > x (Lua turns it into x < 0)",
    function() return 0 > x end)
err("branch on a symbolic value %('==' on an expression%)", "x == y",
    function() return x == y end)
line = debug.getinfo(1, "l").currentline + 3
err("expr_errors.lua:" .. line .. ": branch on a symbolic value %('<' on an expression%) in the traced function",
    "branch inside dm.trace names the place", function()
      return dm.trace(function(q) if q[1] < 0 then return -q[1] end return q[1] end, {1})
    end)
local ok = pcall(function() return x < 0 end)
T.ok(not ok and tostring(dm.sin(x)) == "sin(x)", "the error leaves the session usable")

-- unknown functions, wrong arity
err("unknown function 'foo'", "dm.apply unknown", function() return dm.apply("foo", x) end)
err("atan2 expects 2 arguments, got 1", "dm.apply wrong arity", function() return dm.apply("atan2", x) end)
err("dm.sin expects 1 argument, got 2", "dm.sin(x, y)", function() return dm.sin(x, y) end)
err("dm.atan2 expects 2 arguments, got 1", "dm.atan2(x)", function() return dm.atan2(x) end)
err("dm.select expects 3 arguments, got 2", "dm.select(c, a)", function() return dm.select(dm.lt(x, y), x) end)

-- symbolic vectors
local q = dm.symvec("q", {"r", "theta", "z"})
err("no element 'thta' in q %(elements: r, theta, z%)", "q.thta", function() return q.thta end)
err("index 5 out of range 1..3 for q", "q[5]", function() return q[5] end)
err("a symbolic vector is read%-only", "q.r = 1", function() q.r = 1 end)
err("bad argument #2 to 'symvec' %(non%-empty list of names expected%)", "dm.symvec('q', {})",
    function() return dm.symvec("q", {}) end)
err("bad argument #3 to 'symvec' %(format with exactly one %%s expected%)", "bad fmt",
    function() return dm.symvec("q", {"a"}, "%d") end)

-- calculus and evaluation
err("symbol, parameter, name or a list of them expected, got mul", "diff by a product",
    function() return (x*y):diff(x*y) end)
err("eval: no value for symbol 'y'", "eval with an unbound symbol", function() return (x + y):eval{x = 1} end)
err("eval: the value of x is a string, number expected", "eval with a string value",
    function() return (x + y):eval{x = "1", y = 2} end)
err("subs: keys must be names or expressions, got boolean", "subs with a bad key",
    function() return x:subs{[true] = 1} end)
err("trace: argument 1: names, a count, a symbolic vector or a symbol expected, got boolean",
    "dm.trace with a bad spec", function() return dm.trace(function(a) return a end, {true}) end)
err("trace: result 2 is a boolean", "dm.trace with a bad result",
    function() return dm.trace(function(a) return {a[1], false} end, {1}) end)

-- dm.fn
err("dm.fn: field 'outputs' missing", "dm.fn without outputs", function() return dm.fn{inputs = {x}} end)
err("dm.fn: field 'inputs' missing", "dm.fn without inputs", function() return dm.fn{outputs = x} end)
err("dm.fn: tape: symbol 'y' is neither an input nor a parameter", "dm.fn with an unbound symbol",
    function() return dm.fn{inputs = {x}, outputs = x*y} end)
err("dm.fn: tape: 'x' is listed twice", "dm.fn with a duplicate input",
    function() return dm.fn{inputs = {x, "x"}, outputs = x} end)
err("dm.fn: input 1 is a add, symbol or name expected", "dm.fn with an expression as input",
    function() return dm.fn{inputs = {x + 1}, outputs = x} end)
err("dm.fn: params must map names to numbers", "dm.fn with bad params",
    function() return dm.fn{inputs = {x}, outputs = x, params = {k = "big"}} end)
err("dm.fn: native must be \"auto\", \"wait\", \"always\" or \"never\" %(got \"sometimes\"%)", "bad native option",
    function() return dm.fn{inputs = {x}, outputs = x, native = "sometimes"} end)
dm.config.native = "sometimes"
err("dm.config.native must be \"auto\", \"wait\", \"always\" or \"never\" %(got sometimes%)", "bad dm.config.native",
    function() return dm.fn{inputs = {x}, outputs = x} end)
dm.config.native = "never"
local f = dm.fn{inputs = {x, y}, outputs = x*y, params = {}}
err("compiled function: 2 inputs expected, got 3", "too many inputs", function() return f(1, 2, 3) end)
err("compiled function: 2 inputs expected, got a vector of 1", "short vector", function() return f{1} end)
err("compiled function: input 2 is a string, number expected", "string input", function() return f(1, "a") end)
err("no parameter 'k' in this function", "set_param unknown", function() f:set_param("k", 1) end)
err("batch: points need 2 columns, got 3", "batch with wrong width", function() return f:batch{{1, 2, 3}} end)

T.done()
