-- pretty.lua -- the REPL's pretty printer.
local T = require "dmech.test"
local dm = require "dmech"
local P = dm.pretty

T.is(P(2.385), "2.385", "float shortest form")
T.is(P(0.1 + 0.2), "0.30000000000000004", "all digits when needed")
T.is(P(3), "3", "integer")
T.is(P(3.0), "3.0", "float with integral value keeps .0")
T.is(P(0 / 0), "nan", "nan")
T.is(P(-math.huge), "-inf", "-inf")
T.is(P("a\"b"), '"a\\"b"', "strings quoted")
T.is(P({1, 2, x = 3, ["a b"] = 4}), '{1, 2, ["a b"] = 4, x = 3}', "table with sorted keys")
T.is(P({a = {b = {c = {d = 1}}}}), "{a = {b = {c = {...}}}}", "depth 3")
T.is(P({a = {b = {c = {d = 1}}}}, 5), "{a = {b = {c = {d = 1}}}}", "explicit depth")
local big = {}
for i = 1, 100 do big[i] = i end
T.ok(P(big):find("%.%.%. %(76 more%)"), "long tables truncated")
local cyc = {}
cyc.self = cyc
T.is(P(cyc), "{self = <cycle>}", "cycles detected")
T.is(P(dm.vec{1, 2.5}), "vec{1, 2.5}", "objects by __tostring")
local long = {}
for i = 1, 12 do long["key" .. i] = i * 1.5 end
T.ok(P(long):find("\n"), "wide tables break lines")
T.error_like(function() P(1, "x") end, "bad argument #2 to 'pretty' %(integer expected, got string%)", "depth argument")
T.done()
