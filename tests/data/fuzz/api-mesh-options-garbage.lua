-- fuzz case: dm.mesh.grid{0/0, 1}: unknown option (options: -nan), a stack slot read in the wrong order
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.mesh.grid"](H["t_nan"])
end
