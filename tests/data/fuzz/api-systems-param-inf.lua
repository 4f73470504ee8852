-- fuzz case: dm.systems.kepler_polar{mu = -inf}: an error located in lua/dmech/systems.lua
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.systems.kepler_polar"]({mu = H["minf"]})
end
