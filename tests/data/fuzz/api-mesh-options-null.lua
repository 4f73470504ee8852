-- fuzz case: dm.mesh.grid{1}: unknown option (options: (null))
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.mesh.grid"]({[1] = H["one"]})
end
