-- fuzz case: dm.systems.toda("x") and fpu{q = 1} raised "lua/dmech/systems.lua:NNN: ..."
-- (an error level fixed for one helper, entries nesting two)
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
  local ok, err = pcall(F["dm.systems.toda"], H["s_x"])
  if not ok and err:find("lua/dmech/", 1, true) then error(err, 0) end
  return F["dm.systems.fpu"]({q = H["one"]})
end
