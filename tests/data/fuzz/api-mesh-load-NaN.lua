-- fuzz case: dm.mesh.load(0/0): '-nan' as a file name
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.mesh.load"](H["nan"])
end
