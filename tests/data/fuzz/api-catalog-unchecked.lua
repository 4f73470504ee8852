-- fuzz case: catalog entries and dm.plot_convergence without argument checks raised
-- Lua runtime errors located in lua/dmech/ (nbody("x"), toda(false),
-- toda_integrals(), string{n = 1e12}, plot_convergence(1))
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
  local calls = {
    {F["dm.systems.nbody"], H["s_x"]}, {F["dm.systems.toda"], H["false"]},
    {F["dm.systems.toda_integrals"]}, {F["dm.systems.string"], {n = H["size_huge"]}},
    {F["dm.plot_convergence"], H["one"]},
  }
  for _, c in ipairs(calls) do             -- an internal error of the library
    local ok, err = pcall(c[1], c[2])       -- is passed on to be judged
    if not ok and tostring(err):find("lua/dmech/", 1, true) then error(err, 0) end
  end
end
