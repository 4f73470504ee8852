-- fuzz case: dm.systems.pendulum{impl = 0/0}: got -nan
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.systems.pendulum"]({impl = H["nan"]})
end
