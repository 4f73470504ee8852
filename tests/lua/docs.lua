-- docs.lua -- every function and method reachable from `dm` has a signature
-- and a sentence in the documentation registry; help and apropos find them.
local T = require "dmech.test"
local dm = require "dmech"
local byname, byval = dm.docs()

local missing = {}
local function check_table(prefix, t, seen)
  if seen[t] then return end
  seen[t] = true
  for k, v in pairs(t) do
    if type(k) == "string" and k:sub(1, 1) ~= "_" then
      if type(v) == "function" and not byval[v] and not byname[prefix .. k] then
        missing[#missing + 1] = prefix .. k
      elseif type(v) == "table" and k ~= "config" and getmetatable(v) == nil then
        check_table(prefix .. k .. ".", v, seen)
      end
    end
  end
end
check_table("dm.", dm, {})

-- methods of every class: the metatables registered by dmech
local classes = 0
for key, mt in pairs(debug.getregistry()) do
  if type(key) == "string" and key:match("^dmech%.") and type(mt) == "table" and rawget(mt, "__name") then
    classes = classes + 1
    local methods = rawget(mt, "__methods") or rawget(mt, "__index")
    if type(methods) == "table" then
      for k, v in pairs(methods) do
        if type(v) == "function" and not byval[v] then
          missing[#missing + 1] = rawget(mt, "__name") .. ":" .. k
        end
      end
    end
  end
end
table.sort(missing)
T.ok(#missing == 0, "every exposed function and method is documented" ..
  (#missing > 0 and (": missing " .. table.concat(missing, ", ")) or ""))
T.ok(classes >= 2, "classes found in the registry: " .. classes)

local bad = {}
for name, rec in pairs(byname) do
  if type(rec.sig) ~= "string" or rec.sig == "" or type(rec.doc) ~= "string"
     or not rec.doc:match("^%u") or not rec.doc:match("[%.%)]$") then
    bad[#bad + 1] = name
  end
end
table.sort(bad)
T.ok(#bad == 0, "every entry has a signature and a sentence" ..
  (#bad > 0 and (": " .. table.concat(bad, ", ")) or ""))

-- help and apropos print what the registry holds
local function capture(f, ...)
  local buf = {}
  local real = io.stdout
  local fake = setmetatable({}, {__index = {write = function(self, ...)
    for i = 1, select("#", ...) do buf[#buf + 1] = tostring((select(i, ...))) end
    return self
  end, flush = function() end}})
  io.stdout = fake
  local ok, err = pcall(f, ...)
  io.stdout = real
  assert(ok, err)
  return table.concat(buf)
end
T.ok(capture(dm.help, "vec:dot"):find("v:dot%(w%) %-> number"), "help \"vec:dot\"")
T.ok(capture(dm.help, dm.vec):find("dm.vec%(n"), "help(dm.vec) by value")
T.ok(capture(dm.help, dm.vec{1}.dot):find("Inner product"), "help(v.dot) by value")
T.ok(capture(dm.help, dm.vec{1, 2}):find("v:norm"), "help(object) lists the class methods")
T.ok(capture(dm.help, "mat"):find("m:solve%(b%)"), "help \"mat\" lists methods")
T.ok(capture(dm.help, "solve"):find("m:solve%(b%)"), "help with a bare method name")
T.ok(capture(dm.help, "nosuchthing"):find("no help for 'nosuchthing'"), "help for an unknown name")
T.ok(capture(dm.help):find("apropos"), "help() gives an overview")
T.ok(capture(dm.apropos, "EIGEN"):find("m:eig%(%)"), "apropos is case-insensitive")
T.ok(capture(dm.apropos, "zzzz"):find("nothing about"), "apropos with no hit")
T.error_like(function() dm.apropos(3) end, "bad argument #1 to 'apropos' %(string expected, got number%)", "apropos argument")
dm.doc("mylib.f", "mylib.f(x) -> y", "A user function.", print)
T.ok(capture(dm.help, print):find("mylib.f"), "dm.doc adds user entries")
T.error_like(function() dm.doc("x") end, "bad argument #2 to 'doc'", "dm.doc arguments")
T.done()
