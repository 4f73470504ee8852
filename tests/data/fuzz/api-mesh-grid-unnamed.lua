-- fuzz case: pcall(dm.mesh.grid, 'x') named the function '?'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.mesh.grid"](H["s_x"])
end
