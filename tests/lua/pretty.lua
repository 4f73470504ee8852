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
T.is(P(big), "{1, 2, 3, 4, 5, ..., 96, 97, 98, 99, 100} (100 items)", "long lists of numbers: head ... tail")
big[50] = "x"
T.ok(P(big):find("%.%.%. %(76 more%)"), "other long tables truncated")
local cyc = {}
cyc.self = cyc
T.is(P(cyc), "{self = <cycle>}", "cycles detected")
T.is(P(dm.vec{1, 2.5}), "vec{1, 2.5}", "objects by __tostring")
local long = {}
for i = 1, 12 do long["key" .. i] = i * 1.5 end
T.ok(P(long):find("\n"), "wide tables break lines")
T.error_like(function() P(1, "x") end, "bad argument #2 to 'pretty' %(integer depth or {depth=, digits=, items=} expected, got string%)", "depth argument")
T.error_like(function() P(1, {digits = 18}) end, "digits: integer 0..17 expected", "digits argument")
T.error_like(function() P(1, {digit = 3}) end, "unknown option 'digit'; options: depth, digits, items", "unknown option")

-- vecs and mats: head ... tail with 6 significant digits unless asked
local v = dm.linspace(0, 79289.95000000001, 100)
T.is(P(v), "vec{0, 800.909, 1601.82, 2402.73, 3203.63, ..., 76086.3, 76887.2, 77688.1, 78489, 79290} (100 elements)",
     "a long vec: head ... tail, %.6g")
T.is(P(dm.vec{2.385, -1.5}), "vec{2.385, -1.5}", "a short vec whole")
T.is(P(v, {digits = 0, items = 4}), "vec{0, " .. dm.format_number(v[2]) .. ", ..., " .. dm.format_number(v[99]) .. ", 79289.95000000001} (100 elements)",
     "every digit and fewer items on request")
T.is(P(dm.mat{{2.385, 1}, {1 / 3, 4}}), "mat{{   2.385,        1},\n    {0.333333,        4}}", "a mat, %.6g, aligned")
local saved = dm.config.digits
dm.config.digits = 3
T.is(P(dm.vec{1 / 3, 2.385}), "vec{0.333, 2.38}", "dm.config.digits")
dm.config.digits = saved
local shown = {}
local real = io.stdout
io.stdout = {write = function(_, ...) for i = 1, select("#", ...) do shown[#shown + 1] = select(i, ...) end end}
dm.show(dm.vec{1 / 3, 2.385})
io.stdout = real
T.is(table.concat(shown), "vec{0.3333333333333333, 2.385}\n", "dm.show: every digit")
T.done()
