-- dmech.init -- the Lua side of `require "dmech"`.
--
-- luaopen_dmech (C) builds the table of C functions and registers it as
-- package.loaded["dmech.core"]; this file adds what is natural in Lua (help,
-- apropos, configuration) and returns the finished module table.
local dm = require "dmech.core"

dm._VERSION = "dmech 0.1.0"
dm.config = dm.config or {}

local help = require "dmech.help"
dm.help = help.help
dm.apropos = help.apropos
dm.doc("dm.help", "help([x | \"name\"])",
       "Show the signature and description of a function, method, class or name; help() lists the modules.",
       dm.help)
dm.doc("dm.apropos", "apropos(\"word\")",
       "List every documented name whose name or description contains the word.", dm.apropos)

local print_ = require "dmech.print"
dm.pretty = print_.pretty
dm.show = print_.show
dm.doc("dm.pretty", "dm.pretty(x[, depth | {depth=, digits=, items=}]) -> string",
       "The REPL's rendering of a value: tables to depth 3 with truncation, vecs and mats head ... "
       .. "tail with dm.config.digits (6) significant digits, other objects by __tostring.",
       dm.pretty)
dm.doc("dm.show", "dm.show(x[, {depth=, digits=, items=}])",
       "Print a value in full: every digit (shortest round trip) and every element of a vec or mat.",
       dm.show)

dm.test = require "dmech.test"

-- pictures of meshes and cochains (lua/dmech/meshplot.lua), loaded on first use
function dm.plot_mesh(spec) return require("dmech.meshplot").plot(spec) end
dm.doc("dm.plot_mesh", "dm.plot_mesh{M, values = c, arrows = a | mat, output = \"f.png\", ...}",
       "Draw a triangle mesh with a 0-cochain as coloured triangles (pm3d) and 1-cochains or vectors as arrows.",
       dm.plot_mesh)

return dm
