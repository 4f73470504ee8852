-- dmech.help -- help() and apropos() over the documentation registry that
-- every binding module fills (dm.docs()).
local M = {}
local dm = require "dmech.core"

local function out(...) io.stdout:write(...) end

local function show(rec)
  out(rec.sig, "\n  ", rec.doc, "\n")
end

local function sorted_names(docs, pred)
  local names = {}
  for name, rec in pairs(docs) do
    if pred(name, rec) then names[#names + 1] = name end
  end
  table.sort(names)
  return names
end

-- The entries of a class ("vec") or a module prefix ("dm.").
local function show_group(docs, prefix)
  local names = sorted_names(docs, function(name) return name:sub(1, #prefix) == prefix end)
  for _, name in ipairs(names) do
    out(string.format("  %-44s %s\n", docs[name].sig, docs[name].doc))
  end
  return #names
end

local function overview(docs)
  out("dmech -- computational geometric mechanics at a Lua prompt.\n",
      "help(f) or help \"name\" describes a function or method, help \"vec\" a class,\n",
      "apropos \"word\" searches every description.  Modules and classes:\n")
  local groups = {}
  for name in pairs(docs) do
    local g = name:match("^(.-)[:.][^:.]*$") or name
    groups[g] = (groups[g] or 0) + 1
  end
  local gs = {}
  for g, n in pairs(groups) do gs[#gs + 1] = string.format("  %-16s %d entries", g, n) end
  table.sort(gs)
  out(table.concat(gs, "\n"), "\n")
end

local function classname(x)
  local mt = getmetatable(x)
  if type(mt) == "table" then
    local name = rawget(mt, "__name")
    if type(name) == "string" then return name end
  end
end

function M.help(x)
  local docs, byval = dm.docs()
  if x == nil then return overview(docs) end
  if type(x) ~= "string" then
    local rec = byval[x]
    if rec then
      show(rec)
      if type(x) == "table" then show_group(docs, rec.name .. ".") end  -- a module: its members
      return
    end
    local cls = classname(x)
    if cls and show_group(docs, cls .. ":") > 0 then return end
    out("no help for this ", type(x), " value\n")
    return
  end
  local name = x
  local rec = docs[name] or docs["dm." .. name]
  if rec then
    show(rec)
    show_group(docs, rec.name .. ".")      -- a module (dm.test): its members
  end
  if show_group(docs, name .. ":") > 0 or rec then return end
  if show_group(docs, name .. ".") > 0 then return end
  -- a bare method or function name: every entry ending in it
  local hits = sorted_names(docs, function(n) return n:match("[:.]" .. name:gsub("%p", "%%%0") .. "$") end)
  if #hits > 0 then
    for _, n in ipairs(hits) do show(docs[n]) end
    return
  end
  out("no help for '", name, "'; try apropos \"", name, "\"\n")
end

function M.apropos(word)
  if type(word) ~= "string" then
    error("bad argument #1 to 'apropos' (string expected, got " .. type(word) .. ")", 2)
  end
  local docs = dm.docs()
  local w = word:lower()
  local names = sorted_names(docs, function(name, rec)
    return name:lower():find(w, 1, true) or rec.doc:lower():find(w, 1, true)
  end)
  if #names == 0 then
    out("nothing about '", word, "'\n")
    return
  end
  for _, name in ipairs(names) do
    out(string.format("%-44s %s\n", docs[name].sig, docs[name].doc))
  end
end

return M
