-- fuzz case: e:depends("") left the expression error pending; a later
-- dm.systems.spherical_pendulum_r3() raised it, located in lua/dmech/systems.lua
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
pcall(F["expr:depends"], P["expr"], H["s_empty"], H["s_empty"])
return F["dm.systems.spherical_pendulum_r3"]()
end
